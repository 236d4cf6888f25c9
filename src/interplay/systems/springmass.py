"""Spring-mass networks: nets, cords, cloth (SPEC 2.1).

Point masses joined by linear springs, with Rayleigh damping (mass-proportional -alpha m v and
stiffness-proportional along each spring, kd = beta k), optional tension-only cords, points
fixed in place (constraint filter) and points tied to world positions by anchor springs.
Three integrators: ``explicit`` (symplectic Euler, the reference), ``implicit`` (backward
Euler, one Newton step, preconditioned CG; Baraff & Witkin 1998) and ``localglobal`` (Liu et
al. 2013: a prefactored constant matrix and per-spring projections; ``kernels/localglobal.py``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, StabilityError, require_nonnegative, require_positive
from ..kernels import localglobal as LG
from ..kernels import multigrid as MG
from ..kernels import parallel as PAR
from ..kernels import springs as K
from ..kernels.subcycle import substep_with_spheres
from .base import GRAVITY, System

INTEGRATORS = ("explicit", "implicit", "localglobal")
SCHEMES = ("bdf2", "theta")
LG_SOLVERS = ("auto", "direct", "multigrid")
# "auto" picks multigrid from this many free points (measured: at 64^2 = 4094 one V-cycle costs
# 0.16 ms against 0.37 ms for the factored solve, at 32^2 they are even, and the factor's cost
# grows as n^1.25)
MULTIGRID_MIN_POINTS = 4000


@dataclass(frozen=True)
class Springs:
    """A set of springs between points i and j.

    rest: rest length (m); stiffness: N/m; tension_only: cords that go slack when compressed.
    """
    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    stiffness: np.ndarray
    tension_only: np.ndarray

    @staticmethod
    def from_ratio(x, pairs, stress_strain: float, tension_only: bool = False) -> "Springs":
        """Springs on index pairs at their current lengths, k = (stress/strain ratio) / l0.

        stress_strain: force per unit strain (N), e.g. E*A for a cord; independent of resolution.
        """
        pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        rest = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
        with np.errstate(divide="ignore"):  # zero lengths are reported by SpringNetwork
            k = stress_strain / rest
        return Springs(pairs[:, 0].copy(), pairs[:, 1].copy(), rest, k,
                       np.full(len(pairs), bool(tension_only)))

    @staticmethod
    def concat(*parts: "Springs") -> "Springs":
        return Springs(*(np.concatenate([getattr(p, f) for p in parts])
                         for f in ("i", "j", "rest", "stiffness", "tension_only")))


class SpringNetwork(System):
    """A heterogeneous network of point masses and springs.

    positions: (n,3) m; masses: (n,) kg; springs: a ``Springs`` set;
    mass_damping: alpha (1/s), force -alpha m_i v_i; stiffness_damping: beta (s), kd = beta k;
    anchors: (indices, world positions (a,3) m, stiffness N/m, damping N s/m) zero-length springs;
    fixed: indices of points that never move; strain_limit: a strain above which the state is
    reported unstable; scheme: the implicit integrator, "bdf2" (second order, little numerical
    damping of resolved motion) or "theta" (theta-method: theta = 1 backward Euler, 1/2
    trapezoidal). integrator="localglobal" minimizes backward Euler's objective each step
    (``kernels/localglobal.py``) by L-BFGS with lg_memory pairs (Liu et al. 2017; 0: plain
    local/global iterations, Liu et al. 2013), at most lg_iterations iterations, stopping when
    an iteration moves no point by more than lg_tolerance times the first one did. More
    iterations converge towards backward Euler; fewer are cheaper and softer. lg_solver: the
    constant matrix's inverse as a sparse factor ("direct": exact, cost superlinear in points)
    or one multigrid V-cycle ("multigrid": linear cost, approximate); "auto": multigrid from
    MULTIGRID_MIN_POINTS free points. parallel:
    explicit spring forces on all threads (per spring, then a per-point gather: equal to the
    serial kernel to round-off); opt-in: on 2 cores it measured slower (``kernels/parallel.py``).
    """

    kind = "springmass"

    def __init__(self, name, positions, masses, springs: Springs, dt=1e-3, integrator="implicit",
                 mass_damping=0.0, stiffness_damping=0.0, anchors=None, fixed=(),
                 gravity=GRAVITY, strain_limit=1.0, cg_tolerance=1e-8, cg_max_iter=400,
                 scheme="theta", theta=1.0, lg_iterations=10, lg_memory=3,
                 lg_tolerance=1e-4, lg_solver="auto", parallel=False):
        super().__init__(name, dt)
        x = np.array(positions, dtype=float)
        if x.ndim != 2 or x.shape[1] != 3 or len(x) == 0:
            raise ParameterError(f"{name}: positions must be an (n,3) array, got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            bad = int(np.argwhere(~np.isfinite(x))[0, 0])
            raise ParameterError(f"{name}: position of point {bad} is not finite: {x[bad]}")
        m = np.broadcast_to(np.asarray(masses, dtype=float), (len(x),)).copy()
        if not np.all(m > 0):
            bad = int(np.argmin(m > 0))
            raise ParameterError(f"{name}: mass of point {bad} must be positive, got {m[bad]} kg")
        if integrator not in INTEGRATORS:
            raise ParameterError(f"{name}: unknown integrator {integrator!r}; "
                                 f"choose one of {', '.join(INTEGRATORS)}")
        self._check_springs(springs, len(x))
        self.integrator = integrator
        self.x, self.v, self.m = x, np.zeros_like(x), m
        self.si = springs.i.astype(np.int64)
        self.sj = springs.j.astype(np.int64)
        self.l0 = springs.rest.astype(float)
        self.k = springs.stiffness.astype(float)
        self.tension_only = springs.tension_only.astype(np.bool_)
        self.alpha = require_nonnegative(name, "mass_damping", mass_damping, "1/s")
        self.beta = require_nonnegative(name, "stiffness_damping", stiffness_damping, "s")
        self.kd = self.beta * self.k
        if anchors is None:
            anchors = (np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0), np.zeros(0))
        idx, pos, ak, ac = anchors
        self.a_idx = np.asarray(idx, dtype=np.int64)
        self.a_pos = np.asarray(pos, dtype=float).reshape(-1, 3)
        self.a_k = np.broadcast_to(np.asarray(ak, dtype=float), self.a_idx.shape).copy()
        self.a_c = np.broadcast_to(np.asarray(ac, dtype=float), self.a_idx.shape).copy()
        self.fixed = np.zeros(len(x), dtype=np.bool_)
        self.fixed[np.asarray(fixed, dtype=np.int64)] = True
        self.gravity = np.array(gravity, dtype=float)
        self.strain_limit = require_positive(name, "strain_limit", strain_limit)
        self.cg_tolerance, self.cg_max_iter = cg_tolerance, cg_max_iter
        if scheme not in SCHEMES:
            raise ParameterError(f"{name}: unknown implicit scheme {scheme!r}; choose one of "
                                 f"{', '.join(SCHEMES)}")
        self.scheme = scheme
        self.xp, self.vp = np.zeros_like(x), np.zeros_like(x)
        self.has_prev = False  # BDF2 needs the previous step's state
        if not 0.5 <= theta <= 1.0:
            raise ParameterError(f"{name}: theta must be in [0.5, 1] (1 = backward Euler), "
                                 f"got {theta}")
        self.theta = float(theta)
        self.fext = np.zeros_like(x)
        self.kext = np.zeros((len(x), 3, 3))
        self.dext = np.zeros((len(x), 3, 3))
        self.kvref = np.zeros_like(x)
        self._f = np.zeros_like(x)
        self._jac = False
        self._spheres: list = []
        self._seg = None
        self.impulses = np.zeros((0, 7))
        self.cg_iterations = 0
        self.lg_iterations = int(require_positive(name, "lg_iterations", lg_iterations))
        self.lg_memory = int(require_nonnegative(name, "lg_memory", lg_memory))
        self.lg_tolerance = require_nonnegative(name, "lg_tolerance", lg_tolerance)
        if lg_solver not in LG_SOLVERS:
            raise ParameterError(f"{name}: unknown lg_solver {lg_solver!r}; choose one of "
                                 f"{', '.join(LG_SOLVERS)}")
        self.lg_solver = lg_solver
        self.lg_taken = 0  # iterations taken in the last advance
        self.lg_objective = np.zeros(2)  # the last step's objective at its first guess and end
        self._lg = None  # the factored local/global matrix and what it was built from
        self.lg_factorizations = 0
        # point -> spring adjacency (CSR) for the parallel explicit kernel
        self._adj = (PAR.adjacency(len(x), self.si, self.sj, self.a_idx) if parallel else None)
        self.check_step(self.dt)

    @classmethod
    def from_mesh(cls, name, vertices, triangles, total_mass, stretch, shear=None, bend=None,
                  masses="area", stiffen=None, **kw) -> "SpringNetwork":
        """A network from a triangle mesh (``geometry.mesh``): structural springs on edges,
        shear and bending springs across interior edges, k = ratio / rest length.

        vertices (n,3) m, triangles (m,3); total_mass kg spread by incident area or uniformly
        (masses="area" | "uniform"); stretch, shear, bend: stress/strain ratios (N) of each
        kind (shear defaults to stretch, bend to stretch / 100); stiffen: (vertex indices,
        factor) multiplies the stiffness of structural springs joining two of those vertices
        (a leaf's vein). Other keywords go to ``SpringNetwork``. The result carries
        ``triangles`` so renderers draw it as a surface.
        """
        from ..geometry import mesh as M
        ms = M.mesh_springs(vertices, triangles, total_mass, masses, name)
        x, t = M.validate(vertices, triangles, name)
        shear = stretch if shear is None else shear
        bend = stretch / 100.0 if bend is None else bend
        k = M.spring_stiffness(x, ms.pairs, ms.kind, stretch, shear, bend)
        if stiffen is not None:
            idx, factor = stiffen
            on = np.zeros(len(x), dtype=bool)
            on[np.asarray(idx, dtype=np.int64)] = True
            sel = (ms.kind == 0) & on[ms.pairs[:, 0]] & on[ms.pairs[:, 1]]
            k[sel] *= require_positive(name, "stiffen factor", factor)
        rest = np.linalg.norm(x[ms.pairs[:, 0]] - x[ms.pairs[:, 1]], axis=1)
        springs = Springs(ms.pairs[:, 0].copy(), ms.pairs[:, 1].copy(), rest, k,
                          np.zeros(len(rest), dtype=bool))
        net = cls(name, x, ms.masses, springs, **kw)
        net.triangles = t
        net.spring_kind = ms.kind
        return net

    @staticmethod
    def _check_springs(s: Springs, n: int):
        if len(s.i) and (s.i.min() < 0 or s.j.min() < 0 or max(s.i.max(), s.j.max()) >= n):
            raise ParameterError(f"springs reference a point outside 0..{n - 1}")
        bad = np.flatnonzero(~(s.rest > 0))
        if len(bad):
            raise ParameterError(f"spring {bad[0]} ({s.i[bad[0]]}-{s.j[bad[0]]}) has zero rest "
                                 "length: remove the duplicate point or edge")
        bad = np.flatnonzero(~(s.stiffness > 0))
        if len(bad):
            raise ParameterError(f"spring {bad[0]} has non-positive stiffness {s.stiffness[bad[0]]}"
                                 " N/m: stiffness must be > 0")

    # --- stability -------------------------------------------------------------------------
    def stable_step(self) -> float:
        """Explicit (symplectic Euler) bound, dt < min_i sqrt(2 m_i / sum_j k_ij)  (s)."""
        ksum = np.zeros(len(self.x))
        np.add.at(ksum, self.si, self.k)
        np.add.at(ksum, self.sj, self.k)
        np.add.at(ksum, self.a_idx, self.a_k)
        free = (ksum > 0) & ~self.fixed
        if not np.any(free):
            return np.inf
        return float(np.min(np.sqrt(2.0 * self.m[free] / ksum[free])))

    def check_step(self, dt: float):
        """Refuse an explicit step above the stability bound, naming the bound and the cure."""
        if self.integrator == "explicit":
            bound = self.stable_step()
            if dt >= bound:
                raise StabilityError(
                    f"{self.name}: dt={dt:.3g} s is above the explicit stability bound "
                    f"{bound:.3g} s; use dt < {bound:.3g} or --integrator implicit")

    # --- forces ----------------------------------------------------------------------------
    @property
    def mass(self) -> float:
        return float(self.m.sum())

    def clear_forces(self):
        self._spheres.clear()
        self.fext[:] = 0.0
        if self._jac:
            self.kext[:] = 0.0
            self.dext[:] = 0.0
            self.kvref[:] = 0.0
            self._jac = False

    def add_point_forces(self, indices, forces, dfdx=None, dfdv=None, vref=None):
        """Add forces (N) on points. dfdx, dfdv (len,3,3) are their Jacobians (N/m, N s/m) and
        vref (len,3) the velocity (m/s) of whatever the force is relative to (a contact's other
        body); the implicit integrator uses them to keep stiff external couplings stable."""
        idx = np.asarray(indices, dtype=np.int64)
        f = np.asarray(forces, dtype=float).reshape(-1, 3)
        if dfdx is None:
            K.scatter_forces(idx, f, self.kext, self.dext, f, self.fext, self.kext, self.dext,
                             self.kvref, False)
        else:
            vr = np.zeros_like(f) if vref is None else vref
            K.scatter_forces(idx, f, dfdx, dfdv, vr, self.fext, self.kext, self.dext,
                             self.kvref, True)
            self._jac = True

    def add_moving_sphere(self, segments, centre, velocity, spin, accel, radius, mass,
                          contact) -> int:
        """Collide a sphere with these segments at every substep of the next ``advance``
        (segments None: with the points; explicit and localglobal only, ~3x cheaper for cloth).

        The sphere moves along c0 + v t + a t^2/2 over the step (m, m/s, m/s^2; spin rad/s);
        contact = (thickness m, c_s N/m, c_d N s/m, mu, eps m/s, constraint 0/1). After the
        advance, ``impulses[slot]`` holds the impulse (N s) and angular impulse (N m s) the
        cords exerted on the sphere over the step, and the peak force (N) of any substep.
        Returns the slot.
        """
        if segments is None and self.integrator == "implicit":
            raise ParameterError(f"{self.name}: point contacts (segments=None) need the explicit "
                                 "or localglobal integrator; pass the segments for implicit")
        self._seg = segments
        self._spheres.append((centre, velocity, spin, accel, radius, mass, contact))
        return len(self._spheres) - 1

    def _sphere_arrays(self):
        sp = self._spheres
        arr = [np.array([s[i] for s in sp], dtype=float).reshape(len(sp), *shape)
               for i, shape in enumerate(((3,), (3,), (3,), (3,), (), (), (6,)))]
        self.impulses = np.zeros((len(sp), 7))
        return arr

    def _advance_with_spheres(self, h, n):
        arr = self._sphere_arrays()
        substep_with_spheres(
            self.x, self.v, self.m, self.fixed, self.si, self.sj, self.l0, self.k, self.kd,
            self.tension_only, self.a_idx, self.a_pos, self.a_k, self.a_c, self.alpha,
            self.gravity, self.fext, self.kext, self.dext, self.kvref, self._f, h, n,
            self.integrator == "implicit", self.theta, self.scheme == "bdf2", self.has_prev,
            self.xp, self.vp, self.cg_tolerance, self.cg_max_iter,
            self._seg, arr[0], arr[1], arr[2], arr[4], arr[5], arr[3], arr[6], self.impulses)
        self.has_prev = self.scheme == "bdf2"
        self.time += h

    def internal_forces(self) -> np.ndarray:
        """Total force (N) on each point from springs, anchors, damping, gravity and externals."""
        K.network_forces(self.x, self.v, self.m, self.si, self.sj, self.l0, self.k, self.kd,
                         self.tension_only, self.a_idx, self.a_pos, self.a_k, self.a_c,
                         self.alpha, self.gravity, self.fext, self._f)
        return self._f

    def _factors(self, h):
        """The local/global preconditioner for step h (the factor, or a multigrid hierarchy and
        its workspace) and the L-BFGS history, rebuilt only when the step, the masses, the
        damping, the springs, the anchors, the fixed set, the solver or the memory changed."""
        arrays = (self.m, self.fixed, self.si, self.sj, self.k, self.a_idx, self.a_k, self.a_c)
        lg = self._lg
        key = (h, self.alpha, self.beta, self.lg_solver, self.lg_memory)
        if (lg is None or lg[0] != key
                or not all(np.array_equal(a, b) for a, b in zip(arrays, lg[1]))):
            fid, A = LG.system_matrix(self.m, self.fixed, self.si, self.sj, self.k, self.a_idx,
                                      self.a_k, self.a_c, self.alpha, self.beta, h)
            if self._multigrid(A.shape[0]):
                hier = MG.hierarchy(A)
                pre = (LG.NO_DIRECT, (*hier, *MG.workspace(hier)))
            else:
                pre = (LG.factor(A), LG.NO_MULTIGRID)
            # L-BFGS pairs (kept across steps while the matrix is unchanged) and their count
            nf, slots = A.shape[0], self.lg_memory + 1
            history = (np.zeros((slots, nf, 3)), np.zeros((slots, nf, 3)), np.zeros(slots),
                       np.zeros(1, np.int64))
            self._lg = lg = (key, tuple(a.copy() for a in arrays), (fid, *pre, *history))
            self.lg_factorizations += 1
        return lg[2]

    def _multigrid(self, unknowns):
        return self.lg_solver == "multigrid" or (
            self.lg_solver == "auto" and unknowns >= MULTIGRID_MIN_POINTS)

    def _localglobal(self, h, n):
        """n local/global steps of h/n with the held forces and any moving spheres."""
        arr = self._sphere_arrays()
        fid, direct, mg, *history = self._factors(h / n)
        self.lg_taken = LG.localglobal_steps(
            self.x, self.v, self.m, fid, self.si, self.sj, self.l0, self.k, self.tension_only,
            self.a_idx, self.a_pos, self.a_k, self.a_c, self.alpha, self.beta, self.gravity,
            self.fext, h / n, n, self.lg_iterations, self.lg_tolerance, direct, mg, *history, arr[0], arr[1], arr[3], arr[4], arr[6],
            self.impulses, self.lg_objective)

    def _explicit(self, h, n):
        """n symplectic-Euler steps of h s with the held forces, serial or parallel."""
        if self._adj is None:
            K.explicit_step(self.x, self.v, self.m, self.fixed, self.si, self.sj, self.l0, self.k,
                            self.kd, self.tension_only, self.a_idx, self.a_pos, self.a_k, self.a_c,
                            self.alpha, self.gravity, self.fext, self._f, h, n)
        else:
            PAR.explicit_step(self.x, self.v, self.m, self.fixed, self.si, self.sj, self.l0,
                              self.k, self.kd, self.tension_only, self.a_pos, self.a_k, self.a_c,
                              self.alpha, self.gravity, self.fext, self._f, h, n, self._adj)

    def step(self, h):
        if self.integrator == "localglobal":
            self._localglobal(h, 1)
        elif self.integrator == "explicit":
            self._explicit(h, 1)
        else:
            self.cg_iterations = K.implicit_step(
                self.x, self.v, self.m, self.fixed, self.si, self.sj, self.l0, self.k, self.kd,
                self.tension_only, self.a_idx, self.a_pos, self.a_k, self.a_c, self.alpha,
                self.gravity, self.fext, self.kext, self.dext, self.kvref, self._f, h, self.theta,
                self.scheme == "bdf2", self.has_prev, self.xp, self.vp, self.cg_tolerance,
                self.cg_max_iter)
            self.has_prev = self.scheme == "bdf2"

    def advance(self, h):
        # Explicit substeps with held forces run inside one kernel call (no Python per substep).
        n = max(1, int(np.ceil(h / self.dt - 1e-9)))
        if self.integrator == "localglobal":
            self._localglobal(h, n)
            self.time += h
        elif self._spheres and self._seg is None:
            arr = self._sphere_arrays()
            K.explicit_step_point_spheres(
                self.x, self.v, self.m, self.fixed, self.si, self.sj, self.l0, self.k, self.kd,
                self.tension_only, self.a_idx, self.a_pos, self.a_k, self.a_c, self.alpha,
                self.gravity, self.fext, self._f, h, n, *arr[:4], arr[4], arr[5], arr[6],
                self.impulses)
            self.time += h
        elif self._spheres:
            self._advance_with_spheres(h, n)
        elif self.integrator == "explicit" and n > 1:
            self._explicit(h / n, n)
            self.time += h
        else:
            super().advance(h)

    def settle(self, seconds=1.0, h=2e-3, damping=30.0):
        """Let the network sag to rest under gravity alone (implicit, heavily damped), v = 0 after."""
        alpha = self.alpha
        self.alpha = damping
        saved = self.fext.copy()
        self.fext[:] = 0.0
        try:
            for _ in range(int(round(seconds / h))):
                K.implicit_step(self.x, self.v, self.m, self.fixed, self.si, self.sj, self.l0,
                                self.k, self.kd, self.tension_only, self.a_idx, self.a_pos,
                                self.a_k, self.a_c, self.alpha, self.gravity, self.fext, self.kext,
                                self.dext, self.kvref, self._f, h, 1.0, False, False,
                                self.xp, self.vp, 1e-10, 1000)
        finally:
            self.alpha = alpha
            self.fext[:] = saved
        self.v[:] = 0.0
        self.has_prev = False

    # --- measures --------------------------------------------------------------------------
    def strain(self) -> float:
        """Largest spring strain (l - l0) / l0 (dimensionless)."""
        return float(K.max_strain(self.x, self.si, self.sj, self.l0)) if len(self.si) else 0.0

    def lowest_z(self) -> float:
        """Lowest point height (m)."""
        return float(self.x[:, 2].min())

    def kinetic_energy(self):
        return 0.5 * float(np.sum(self.m[:, None] * self.v * self.v))

    def momentum(self):
        return (self.m[:, None] * self.v).sum(axis=0)

    def health(self):
        warnings = super().health()
        if not warnings:
            e = self.strain()
            if e > self.strain_limit:
                warnings.append(f"{self.name}: strain {e:.2f} exceeds {self.strain_limit:.2f} at "
                                f"t={self.time:.4f} s (dt={self.dt:.3g} s, {self.integrator}): "
                                "unstable or torn")
        return warnings

    # --- state -----------------------------------------------------------------------------
    def generalized_state(self):
        return self.x.reshape(-1), self.v.reshape(-1)

    def set_generalized_state(self, x, xdot):
        self.x[:] = np.reshape(x, self.x.shape)
        self.v[:] = np.reshape(xdot, self.v.shape)
        self.has_prev = False  # a jump in state: BDF2 restarts with a backward-Euler step

    def frame(self):
        return {"points": self.x.copy()}

    def segments(self) -> np.ndarray:
        """(s,2) point index pairs of the springs: what lines render and contacts test."""
        return np.stack([self.si, self.sj], axis=1)
