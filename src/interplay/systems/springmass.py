"""Spring-mass networks: nets, cords, cloth (SPEC 2.1).

Point masses joined by linear springs, with Rayleigh damping (mass-proportional -alpha m v and
stiffness-proportional along each spring, kd = beta k) plus any spring's own viscosity (a
group of springs damped beyond beta: a foam's, not its stiff cover's), optional tension-only
cords, points fixed in place (constraint filter) and points tied to world positions by anchor
springs.
Three integrators: ``explicit`` (symplectic Euler, the reference), ``implicit`` (backward
Euler, one Newton step, preconditioned CG; Baraff & Witkin 1998) and ``localglobal`` (Liu et
al. 2013: a prefactored constant matrix and per-spring projections; ``kernels/localglobal.py``).
"""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError, SceneError, require_nonnegative, require_positive
from ..kernels import global_matrix as GM
from ..kernels import localglobal as LG
from ..kernels import multigrid as MG
from ..kernels import parallel as PAR
from ..kernels import springs as K
from ..kernels.contact import THICKNESS, colliders as no_colliders
from ..kernels.part_contact import Parts
from ..kernels.subcycle import advance_with_colliders, advance_with_parts
from .base import GRAVITY, System, substeps
from .explicit_stability import ExplicitStability
from .shape import Shape, split_color
from .spring_set import Springs  # noqa: F401 (networks are built from it: springmass.Springs)
from .views import PointsView

INTEGRATORS = ("explicit", "implicit", "localglobal")
SCHEMES = ("bdf2", "theta")
LG_SOLVERS = ("auto", "direct", "multigrid")
# "auto" picks multigrid from this many free points (measured: at 64^2 = 4094 one V-cycle costs
# 0.16 ms against 0.37 ms for the factored solve, at 32^2 they are even, and the factor's cost
# grows as n^1.25)
MULTIGRID_MIN_POINTS = 4000


class SpringNetwork(ExplicitStability, System):
    """A heterogeneous network of point masses and springs.

    positions: (n,3) m; masses: (n,) kg; springs: a ``Springs`` set;
    mass_damping: alpha (1/s), force -alpha m_i v_i; stiffness_damping: beta (s), kd = beta k;
    spring_damping: (s,) N s/m, each spring's own along-spring damping added to beta k (a group
    of springs viscous beyond what beta allows the stiffest; explicit or implicit only);
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
    triangles (m,3): its faces, when it is a surface (cloth), for contacts, aerodynamics and
    drawing; cord_radius (m): the cords' radius as drawn and as a contact skin (None: drawn
    at 8% of the median spring length); color: linear RGB (0..1) as drawn (None: the
    outputs' default); cords (c,2): point pairs drawn as cords beside a surface (a
    trampoline's frame springs), a shape of their own named "<name>-cords".
    stability_share: with the explicit integrator, the share of damped symplectic Euler's
    limit (h^2 w^2 + 2 h c < 4) the network may use, the rest left to what acts on it (a
    sub-cycled contact); None: the undamped and damping bounds only (``explicit_bounds``);
    dt_key, step_cure: how a refused step's message names the step and the other cures.
    """

    def __init__(self, name, positions, masses, springs: Springs, dt=1e-3, integrator="implicit",
                 mass_damping=0.0, stiffness_damping=0.0, spring_damping=None, anchors=None,
                 fixed=(),
                 gravity=GRAVITY, strain_limit=1.0, cg_tolerance=1e-8, cg_max_iter=400,
                 scheme="theta", theta=1.0, lg_iterations=10, lg_memory=3,
                 lg_tolerance=1e-4, lg_solver="auto", parallel=False, triangles=None,
                 cord_radius=None, color=None, cords=None, stability_share=None,
                 dt_key="dt", step_cure="less stiffness or damping"):
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
        self.kd = self.beta * self.k + self._own_damping(spring_damping, integrator)
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
        self._cols = None  # the colliders sub-cycled in the next advance, and their elements
        self._free_dt = None  # (s, s): free_step and the dt it was found at
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
        # the energy guard's extra iteration rounds and velocity scalings so far
        self.lg_guard = np.zeros(2, dtype=np.int64)
        self._lg = None  # the factored local/global matrix and what it was built from
        self._lg_pending = None  # a restored L-BFGS history waiting for its matrix
        self.lg_factorizations = 0
        # point -> spring adjacency (CSR) for the parallel explicit kernel
        self._adj = (PAR.adjacency(len(x), self.si, self.sj, self.a_idx) if parallel else None)
        self.triangles = None if triangles is None else np.asarray(triangles, np.int64)
        self.cord_radius = None if cord_radius is None else require_positive(
            name, "cord_radius", cord_radius, "m")
        self.color = color
        self.cords = None if cords is None else np.asarray(cords, np.int64).reshape(-1, 2)
        self._pts = K.Points(self.x, self.v, self.m, self.fixed)
        self._load = K.Load(self.fext, self.kext, self.dext, self.kvref)
        self._view = None
        self.stability_share = (None if stability_share is None else
                                require_positive(name, "stability_share", stability_share))
        self.dt_key, self.step_cure = dt_key, step_cure
        self.check_step(self.dt)

    def bundle(self, alpha=None) -> K.Network:
        """The kernels' bundle of this network (with mass damping alpha, default its own)."""
        return K.Network(self._pts,
                         K.SpringSet(self.si, self.sj, self.l0, self.k, self.kd,
                                     self.tension_only),
                         K.Anchors(self.a_idx, self.a_pos, self.a_k, self.a_c),
                         self.alpha if alpha is None else alpha, self.gravity)

    def _scheme(self) -> K.Scheme:
        return K.Scheme(self.integrator == "implicit", self.theta, self.scheme == "bdf2",
                        self.cg_tolerance, self.cg_max_iter, self.xp, self.vp)

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
        net = cls(name, x, ms.masses, springs, triangles=t, **kw)
        net.spring_kind = ms.kind
        return net

    @staticmethod
    def _check_springs(s: Springs, n: int):
        if len(s.i) and (s.i.min() < 0 or s.j.min() < 0 or max(s.i.max(), s.j.max()) >= n):
            raise ParameterError(f"springs reference a point outside 0..{n - 1}")
        bad = np.flatnonzero(~((s.rest > 0) | ((s.rest < 0) & ~s.tension_only)))
        if len(bad):
            b = bad[0]
            if s.rest[b] < 0:
                raise ParameterError(f"spring {b} ({s.i[b]}-{s.j[b]}) is a tension-only cord "
                                     f"with negative rest length {s.rest[b]} m; only preloaded "
                                     "springs (never slack) may have one")
            raise ParameterError(f"spring {b} ({s.i[b]}-{s.j[b]}) has zero rest "
                                 "length: remove the duplicate point or edge")
        bad = np.flatnonzero(~(s.stiffness > 0))
        if len(bad):
            raise ParameterError(f"spring {bad[0]} has non-positive stiffness {s.stiffness[bad[0]]}"
                                 " N/m: stiffness must be > 0")

    def _own_damping(self, kd, integrator) -> np.ndarray:
        """The springs' own damping (N s/m), checked: one finite value >= 0 per spring; the
        local/global step damps with beta alone (its constant matrix), so it refuses them."""
        if kd is None:
            return np.zeros(len(self.k))
        kd = np.broadcast_to(np.asarray(kd, dtype=float), self.k.shape).copy()
        if not np.all(np.isfinite(kd) & (kd >= 0.0)):
            bad = int(np.argmin(np.isfinite(kd) & (kd >= 0.0)))
            raise ParameterError(f"{self.name}: spring {bad}'s own damping must be finite and "
                                 f">= 0 N s/m, got {kd[bad]}")
        if integrator == "localglobal" and np.any(kd > 0.0):
            raise ParameterError(f"{self.name}: springs with their own damping need the "
                                 "explicit or implicit integrator (local/global damps with "
                                 "stiffness_damping alone)")
        return kd

    # --- forces ----------------------------------------------------------------------------
    @property
    def mass(self) -> float:
        return float(self.m.sum())

    def clear_forces(self):
        self._cols = None
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
        zero = np.zeros((0, 3, 3))
        if dfdx is None:
            pf = K.PointForces(idx, f, zero, zero, f)
            K.scatter_forces(pf, len(idx), self._load, False)
        else:
            vr = np.zeros_like(f) if vref is None else vref
            K.scatter_forces(K.PointForces(idx, f, dfdx, dfdv, vr), len(idx), self._load, True)
            self._jac = True

    def substeps(self, h) -> int:
        """Substeps of the next advance of h (s) at this network's own step."""
        return substeps(h, self.dt)

    def subcycle(self, colliders, elements) -> bool:
        """The sub-cycling hook (PointsView.subcycle): collide kernels.contact.Colliders with
        ``elements`` ((s,2) point pairs; (p, p) for points) at every substep of the next
        ``advance`` (local/global: after every step, points only). One batch per advance; a
        second with the same elements is merged."""
        elems = np.ascontiguousarray(elements, dtype=np.int64)
        if isinstance(colliders, Parts):  # rigid parts: one batch, explicit or implicit
            if self.integrator == "localglobal":
                return False
            if self._cols is not None:
                raise SceneError(f"{self.name}: a second sub-cycled contact in one coupling "
                                 "step with rigid parts; exchange one of them in lock step")
            self._cols = (colliders, elems, [colliders])
            return True
        if self._cols is None:
            self._cols = (colliders, elems, [colliders])
            return True
        cols, old, parts = self._cols
        if isinstance(cols, Parts):
            raise SceneError(f"{self.name}: a sub-cycled contact with rigid parts already "
                             "acts in this coupling step; exchange one of them in lock step")
        if old.shape != elems.shape or not np.array_equal(old, elems):
            raise SceneError(f"{self.name}: two sub-cycled contacts with different elements in "
                             "one coupling step; give them the same elements or exchange one "
                             "of them in lock step")
        parts.append(colliders)
        merged = type(cols)(*(np.concatenate([getattr(c, f) for c in parts])
                              for f in cols._fields))
        self._cols = (merged, old, parts)
        return True

    def _within_reach(self, cols, h) -> bool:
        """Whether any collider's path over the next h (s) can come within its reach (radius
        plus the law's thickness) of the network's bounding box grown by the fastest point's
        travel: a sphere stays within |v| h + |a| h^2 / 2 of where it starts."""
        if not len(cols.radii):
            return False
        grow = float(np.sqrt((self.v * self.v).sum(axis=1).max())) * h
        lo, hi = self.x.min(axis=0) - grow, self.x.max(axis=0) + grow
        travel = (np.linalg.norm(cols.velocities, axis=1) * h
                  + 0.5 * np.linalg.norm(cols.accels, axis=1) * h * h)
        reach = (cols.radii + cols.law[:, THICKNESS] + travel)[:, None]
        return bool(np.any(np.all((cols.centres + reach >= lo) & (cols.centres - reach <= hi),
                                  axis=1)))

    def _return_impulses(self):
        """Hand each sub-cycled batch its own rows of the merged impulses."""
        cols, _, parts = self._cols
        if len(parts) > 1:
            k = 0
            for c in parts:
                n = len(c.impulses)
                c.impulses[:] = cols.impulses[k:k + n]
                k += n

    def internal_forces(self) -> np.ndarray:
        """Total force (N) on each point from springs, anchors, damping, gravity and externals."""
        K.network_forces(self.bundle(), self.fext, self._f)
        return self._f

    def accelerations(self) -> np.ndarray:
        """(n,3) accelerations (m/s^2) from every force now acting on the points."""
        return self.internal_forces() / self.m[:, None]

    def contact_view(self) -> PointsView:
        if self._view is None:
            self._view = PointsView(self, self._pts, self.triangles, self.segments(),
                                    self.cord_radius or 0.0, self.integrator == "implicit")
        return self._view

    def shapes(self):
        """A surface (cloth, flags, leaves: double-sided) or cords (a net, a bungee cord) at
        their drawn width. ``color`` may be one colour or one per point ((n,3): autumn leaves
        each their own)."""
        anchors = self.a_pos.copy() if len(self.a_pos) else None
        color, per_point = split_color(self.color)
        if self.triangles is not None:
            out = [Shape(self.name, "surface", color=color, triangles=self.triangles,
                         anchors=anchors, palette="cloth", point_colors=per_point,
                         material="cloth", double_sided=True)]
            if self.cords is not None:
                # the springs a surface hangs from (a trampoline's frame springs): steel coils
                out.append(Shape(f"{self.name}-cords", "cords", segments=self.cords,
                                 width=self._cord_width(self.cords), palette="static",
                                 source=(self.name, "points"), material="metal"))
            return out
        seg = self.segments()
        return [Shape(self.name, "cords", color=color, segments=seg,
                      width=self._cord_width(seg), anchors=anchors, palette="cloth",
                      material="cloth")]

    def _cord_width(self, seg) -> float:
        """A drawn cord's diameter (m): twice cord_radius, else 8% of the median length."""
        if self.cord_radius is not None:
            return 2.0 * self.cord_radius
        if len(seg):
            lengths = np.linalg.norm(self.x[seg[:, 0]] - self.x[seg[:, 1]], axis=1)
            return float(np.clip(0.08 * np.median(lengths), 0.002, 0.02))
        return 0.005

    def _factors(self, h):
        """The local/global preconditioner for step h (kernels.localglobal.Factors) and the
        L-BFGS History, rebuilt only when the step, the masses, the damping, the springs, the
        anchors, the fixed set, the solver or the memory changed."""
        arrays = (self.m, self.fixed, self.si, self.sj, self.k, self.a_idx, self.a_k, self.a_c)
        lg = self._lg
        key = (h, self.alpha, self.beta, self.lg_solver, self.lg_memory)
        if (lg is None or lg[0] != key
                or not all(np.array_equal(a, b) for a, b in zip(arrays, lg[1]))):
            fid, A = GM.system_matrix(self.bundle(), self.beta, h)
            if self._multigrid(A.shape[0]):
                hier = MG.hierarchy(A)
                pre = GM.Factors(fid, GM.NO_DIRECT, hier, MG.workspace(hier))
            else:
                pre = GM.Factors(fid, GM.factor(A), GM.NO_MULTIGRID, GM.NO_WORKSPACE)
            # L-BFGS pairs (kept across steps while the matrix is unchanged) and their count
            nf, slots = A.shape[0], self.lg_memory + 1
            history = LG.History(np.zeros((slots, nf, 3)), np.zeros((slots, nf, 3)),
                                 np.zeros(slots), np.zeros(1, np.int64))
            pending = self._lg_pending
            if pending is not None and pending[0] == key:
                for mine, saved in zip(history, pending[1]):
                    mine[...] = saved
            self._lg_pending = None
            self._lg = lg = (key, tuple(a.copy() for a in arrays), pre, history)
            self.lg_factorizations += 1
        return lg[2], lg[3]

    def _multigrid(self, unknowns):
        return self.lg_solver == "multigrid" or (
            self.lg_solver == "auto" and unknowns >= MULTIGRID_MIN_POINTS)

    def _localglobal(self, h, n):
        """n local/global steps of h/n with the held forces and any sub-cycled colliders."""
        pre, history = self._factors(h / n)
        cols = self._cols[0] if self._cols is not None else no_colliders(0)
        self.lg_taken = LG.localglobal_steps(
            self.bundle(), self.fext, pre, history,
            LG.Settings(self.beta, self.lg_iterations, self.lg_tolerance), h / n, n, cols,
            self.lg_objective, self.lg_guard)

    def _explicit(self, h, n):
        """n symplectic-Euler steps of h s with the held forces, serial or parallel."""
        if self._adj is None:
            K.explicit_step(self.bundle(), self.fext, self._f, h, n)
        else:
            PAR.explicit_step(self.bundle(), self.fext, self._f, h, n, self._adj)

    def step(self, h):
        if self.integrator == "localglobal":
            self._localglobal(h, 1)
        elif self.integrator == "explicit":
            self._explicit(h, 1)
        else:
            self.cg_iterations = K.implicit_step(self.bundle(), self._load, self._f, h,
                                                 self._scheme(), self.has_prev)
            self.has_prev = self.scheme == "bdf2"

    def advance(self, h, dt=None):
        # Explicit substeps with held forces run inside one kernel call (no Python per substep).
        n = substeps(h, self.dt if dt is None else dt)
        if self.integrator == "localglobal":
            self._localglobal(h, n)
        elif self._cols is not None:
            cols, elems, _ = self._cols
            if isinstance(cols, Parts):
                advance_with_parts(self.bundle(), self._load, self._f, h, n, self._scheme(),
                                   self.has_prev, cols)
            elif self.integrator == "explicit" and not self._within_reach(cols, h):
                # nothing can touch the network this step: its own stable step, not the
                # contact's (the basketball's net before the ball arrives and after it left)
                cols.impulses[:] = 0.0
                step = self.dt if dt is None else dt
                if self._free_dt is None:
                    self._free_dt = (self.free_step(), self.dt)
                # a step the health check cut (dt / 10 on a rerun) cuts the free one alike
                free, at = self._free_dt
                m = substeps(h, max(step, free * self.dt / at))
                self._explicit(h / m, m)
            else:
                advance_with_colliders(self.bundle(), self._load, self._f, h, n,
                                       self._scheme(), self.has_prev, cols, elems)
            self.has_prev = self.scheme == "bdf2" and self.integrator == "implicit"
        elif self.integrator == "explicit" and n > 1:
            self._explicit(h / n, n)
        else:
            super().advance(h, dt)
            return
        if self._cols is not None:
            self._return_impulses()
        self.time += h

    def settle(self, relaxed: float | None = None):
        """Let the network sag to rest under gravity alone (``relaxation.settle``: the minimum
        of its potential energy, or ``relaxed`` s of damped relaxation; remembered per network
        for the process), v = 0 after."""
        from .relaxation import settle
        settle(self, relaxed)

    # --- measures --------------------------------------------------------------------------
    def strain(self) -> float:
        """Largest spring strain (l - l0) / l0 (dimensionless)."""
        return float(K.max_strain(self.x, K.SpringSet(self.si, self.sj, self.l0, self.k, self.kd,
                                                     self.tension_only))) if len(self.si) else 0.0

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

    def capture(self):
        """Points, time and all solver memory: BDF2's previous state and the L-BFGS pairs
        (with the matrix key they belong to), so a restore and a rerun repeat bit for bit."""
        snap = {"x": self.x.copy(), "v": self.v.copy(), "time": np.array(self.time),
                "has_prev": np.array(self.has_prev), "xp": self.xp.copy(),
                "vp": self.vp.copy(), "lg_guard": self.lg_guard.copy()}
        if self._lg is not None:
            snap["lg_key"] = np.array(self._lg[0][:3], dtype=float)
            snap["lg_solver"] = np.array(self._lg[0][3])
            snap["lg_memory"] = np.array(self._lg[0][4])
            for f, a in zip(LG.History._fields, self._lg[3]):
                snap[f"lg_{f}"] = a.copy()
        return snap

    def restore(self, snap):
        self.x[:], self.v[:] = snap["x"], snap["v"]
        self.time = float(snap["time"])
        self.has_prev = bool(snap["has_prev"])
        self.xp[:], self.vp[:] = snap["xp"], snap["vp"]
        self.lg_guard[:] = snap["lg_guard"]
        self._lg_pending = None
        if "lg_key" in snap:
            h, alpha, beta = (float(v) for v in snap["lg_key"])
            key = (h, alpha, beta, str(snap["lg_solver"]), int(snap["lg_memory"]))
            saved = tuple(snap[f"lg_{f}"] for f in LG.History._fields)
            if self._lg is not None and self._lg[0] == key:
                for mine, s in zip(self._lg[3], saved):
                    mine[...] = s
            else:
                self._lg_pending = (key, saved)
        elif self._lg is not None:  # captured before any local/global step: start afresh
            for a in self._lg[3]:
                a[...] = 0

    def extra_diagnostics(self) -> dict:
        """Local/global: how often the energy guard acted (kernels/localglobal.py)."""
        if self.integrator != "localglobal":
            return {}
        return {"energy_guard": {"extra_rounds": int(self.lg_guard[0]),
                                 "scaled_steps": int(self.lg_guard[1])}}

    def frame(self):
        return {"points": self.x.copy()}

    def segments(self) -> np.ndarray:
        """(s,2) point index pairs of the springs: what lines render and contacts test."""
        return np.stack([self.si, self.sj], axis=1)
