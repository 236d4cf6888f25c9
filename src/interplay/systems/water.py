"""Water (SPEC 2.4, O'Brien & Hodgins 1995): height-field columns joined by virtual pipes, the
surface they define, and spray particles. Objects act on it through external pressure.

Volume: columns of water over a bed; pressure differences drive flow through 8-neighbour pipes
(kernels/water.py has the equations). Surface: the height field bed + V/l^2 plus the external
pressure head (what a renderer shows). Spray: where the surface rises faster than a threshold,
particles leave it, fly ballistically with light air drag and fall back; each carries its
volume from one column to another, so columns plus airborne particles conserve volume to
round-off.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, StabilityError, require_nonnegative, require_positive
from ..kernels import lids as L
from ..params import param, zero_or_at_least
from ..kernels import water as K
from .base import System
from .shape import Shape

#: the wave-speed stability limit: dt < STABLE_CFL * l / sqrt(g d) (the pipe update is stable
#: up to 1.0 for the fastest 8-pipe mode; 0.7 leaves room for depth growing within a step)
STABLE_CFL = 0.7

# linear RGB as drawn: clear water over a muddy sand bed; spray as white foam droplets
WATER_COLOR = (0.06, 0.25, 0.30)
SPRAY_COLOR = (0.92, 0.96, 1.0)
BED_COLOR = (0.45, 0.37, 0.25)
BANK_COLOR = (0.30, 0.42, 0.20)  # the grass the bed rises into above the water
BED_STRIDE = 2  # columns per drawn bed cell


@dataclass(frozen=True)
class SprayParams:
    """threshold: surface rise speed (m/s) above which spray leaves it; fraction: share (-) of
    the excess upward flux, l^2 (rate - threshold), that detaches; radius: particle radius (m);
    capacity: most particles airborne at once (output frames are padded to it); drag: drag
    coefficient (-) of a droplet in air of density air_density (kg/m^3)."""
    enabled: bool = True
    threshold: float = param(0.6, "m/s", ge=1e-6, le=100.0)
    fraction: float = param(0.3, "-", ge=0.0, le=1.0)
    radius: float = param(0.004, "m", ge=1e-5, le=0.1)
    capacity: int = param(4096, "particles", ge=1, le=10_000_000, cost="particles")
    drag: float = param(0.47, "-", ge=0.0, le=10.0)
    air_density: float = param(1.2, "kg/m^3", ge=0.0, le=100.0)


@dataclass(frozen=True)
class WaterParams:
    """density (kg/m^3), gravity (m/s^2), damping: linear pipe friction (1/s); cfl: substep as
    a fraction of l / sqrt(g d_max), rechecked every coupling step (<= 0.7); dt: largest step
    (s), 0 picks cfl * l / sqrt(g d_max) of the initial water.
    body_stiffness kappa (-): pressure head per metre of water rising into a body. A floating
    body rests deeper than Archimedes by about 1/(1 + kappa) of its submerged depth; while a
    body touches the water the substeps shrink by sqrt(1 + kappa). body_samples: sample points
    per column side where a body cuts the columns. body_damping (1/s): extra pipe friction
    under a body (its wetted surface), which damps waves trapped under it."""
    density: float = param(1000.0, "kg/m^3", ge=1.0, le=1e5)
    gravity: float = param(9.81, "m/s^2", ge=0.01, le=100.0)
    damping: float = param(0.5, "1/s", ge=0.0, le=1e4)
    cfl: float = param(0.5, "-", ge=0.01, le=0.7)
    dt: float = param(0.0, "s", ge=0.0, le=0.1, check=zero_or_at_least(1e-9),
                      doc="0: automatic")
    # the substeps shrink by sqrt(1 + kappa) under a body: 1e4 is 100x the steps
    body_stiffness: float = param(30.0, "-", ge=1e-6, le=1e4)
    body_samples: int = param(4, "-", ge=1, le=16)
    body_damping: float = param(200.0, "1/s", ge=0.0, le=1e5)
    spray: SprayParams = SprayParams()


class Water(System):
    """A rectilinear grid of fluid columns with spray.

    bed: (nx, ny) bed heights (m); fluid: (nx, ny) mask, False is wall; depth: (nx, ny) initial
    water depth (m, >= 0); spacing: column width l (m); origin: centre (m) of column (0, 0).
    Bodies register where they cut the columns (``add_solids``) at every coupling step;
    the water's external pressure follows from that and from its own state in every substep
    (kernels/water.py ``heads``); ``clear_forces`` forgets them.
    """

    integrator = "virtual pipes (O'Brien & Hodgins 1995), staggered flow update"

    def __init__(self, name, bed, fluid, depth, spacing, origin=(0.0, 0.0),
                 params: WaterParams = WaterParams()):
        self.spacing = l = require_positive(name, "spacing", spacing, "m")
        bed = np.ascontiguousarray(bed, dtype=float)
        fluid = np.ascontiguousarray(fluid, dtype=bool)
        depth = np.ascontiguousarray(depth, dtype=float)
        if bed.ndim != 2 or bed.shape != fluid.shape or bed.shape != depth.shape \
                or min(bed.shape) < 2:
            raise ParameterError(f"{name}: bed, fluid mask and depth must be equal 2-D grids of "
                                 f"at least 2x2 columns, got {bed.shape}, {fluid.shape}, "
                                 f"{depth.shape}")
        if not (np.all(np.isfinite(bed)) and np.all(np.isfinite(depth))):
            raise ParameterError(f"{name}: bed and depth must be finite numbers")
        if np.any(depth < 0.0):
            i, j = np.unravel_index(int(np.argmin(depth)), depth.shape)
            raise ParameterError(f"{name}: negative water depth {depth[i, j]:.4g} m at column "
                                 f"({i}, {j}); depths must be >= 0 (use 0 for a dry column)")
        p = params
        self.rho = require_positive(name, "density", p.density, "kg/m^3")
        self.g = require_positive(name, "gravity", p.gravity, "m/s^2")
        require_nonnegative(name, "damping", p.damping, "1/s")
        self.kappa = require_positive(name, "body_stiffness", p.body_stiffness)
        require_nonnegative(name, "body_damping", p.body_damping, "1/s")
        self.samples = int(p.body_samples)
        if self.samples < 1:
            raise ParameterError(f"{name}: body_samples must be >= 1, got {p.body_samples}")
        if not 0.0 < p.cfl <= STABLE_CFL:
            raise ParameterError(f"{name}: cfl must be in (0, {STABLE_CFL}], got {p.cfl}; the "
                                 f"pipe update is unstable past {STABLE_CFL} l / sqrt(g d)")
        d = np.where(fluid, depth, 0.0)
        if not np.any(d > 0.0):
            raise ParameterError(
                f"{name}: the basin holds no water ({int(fluid.sum())} fluid columns, all dry); "
                "raise the water depth above the bed or widen the fluid mask")
        dmax = float(d.max())
        limit = STABLE_CFL * l / math.sqrt(self.g * dmax)
        if p.dt:
            dt = require_positive(name, "dt", p.dt, "s")
            if dt > limit:
                raise StabilityError(
                    f"{name}: dt {dt:.4g} s is above the wave-speed limit "
                    f"{STABLE_CFL} l / sqrt(g d) = {limit:.4g} s (columns {l:.4g} m, deepest "
                    f"{dmax:.4g} m); use dt <= {p.cfl * l / math.sqrt(self.g * dmax):.4g} s "
                    "or leave dt at 0 (automatic)")
        else:
            dt = p.cfl * l / math.sqrt(self.g * dmax)
        super().__init__(name, dt)
        self.params = p
        self.shape = bed.shape
        self.origin = (float(origin[0]), float(origin[1]))
        self.area = l * l
        self.pipe_width = l / (1.0 + math.sqrt(2.0))  # m: wave speed exactly sqrt(g d)
        self.bed, self.fluid = bed, fluid
        self.V = d * self.area
        self.Q = np.zeros((4,) + bed.shape)
        self.ext = np.zeros(bed.shape)       # external pressure head p/(rho g) (m)
        self._grow_lids(64)
        self.rate = np.zeros(bed.shape)      # surface vertical speed (m/s)
        self.pipe = _pipes(fluid)
        self.nearest = _nearest_fluid(fluid)
        s = p.spray
        self.spray_on = bool(s.enabled)
        if self.spray_on:
            require_positive(name, "spray threshold", s.threshold, "m/s")
            require_nonnegative(name, "spray fraction", s.fraction)
            require_positive(name, "spray radius", s.radius, "m")
            require_nonnegative(name, "spray drag", s.drag)
            require_nonnegative(name, "air density", s.air_density, "kg/m^3")
            if int(s.capacity) < 1:
                raise ParameterError(f"{name}: spray capacity must be >= 1, got {s.capacity}")
        self.particle_volume = 4.0 / 3.0 * math.pi * s.radius ** 3  # m^3
        # quadratic drag per unit mass: 0.5 rho_air C_d pi r^2 / (rho_w 4/3 pi r^3) (1/m)
        self.air_drag = 3.0 * s.air_density * s.drag / (8.0 * self.rho * s.radius)
        cap = max(1, int(s.capacity)) if self.spray_on else 1
        self.px = np.zeros((cap, 3))
        self.pv = np.zeros((cap, 3))
        self.count = 0
        self._steps = 0
        self._track = np.zeros(K.TRACKED)  # what the run has seen: kernels/water.py
        self._track[K.MIN_DEPTH] = float(d[fluid].min())
        self._track[K.HIGHEST] = -np.inf
        self.volume0 = self.total_volume()
        self._drift = 0.0
        self._em = np.zeros(4)
        self._grid = K.Grid(self.bed, self.fluid, self.pipe, self.nearest, self.area,
                            self.origin[0], self.origin[1], self.spacing, self.pipe_width)
        self._state = K.State(self.V, self.Q, self.ext, self.rate, self.px, self.pv, self._track)
        self._settings = K.Settings(self.g, self.kappa, float(p.damping), float(p.body_damping),
                                    float(p.cfl), self.spray_on, float(s.threshold),
                                    float(s.fraction), self.particle_volume, float(s.radius),
                                    self.air_drag)
        self._scratch = K.Scratch(np.zeros(bed.shape), np.zeros(bed.shape), np.zeros(bed.shape))
        # linear RGB as drawn: the water (None: WATER_COLOR), its bed below the still water and
        # the bed where it rises above it (the banks)
        self.color, self.bed_color, self.bank_color = None, BED_COLOR, BANK_COLOR

    # --- the System protocol -----------------------------------------------------------------
    @property
    def mass(self) -> float:
        return self.rho * self.total_volume()

    def clear_forces(self):
        self.n_lid = 0
        self.n_solid = 0
        self.ext[:] = 0.0

    def _grow_lids(self, cap):
        s2 = self.samples * self.samples
        old = getattr(self, "n_lid", 0)
        arrays = (np.zeros(cap, np.int64), np.zeros(cap, np.int64), np.zeros((cap, s2)),
                  np.zeros((cap, s2)), np.zeros(cap), np.zeros(cap))
        if old:
            for new, cur in zip(arrays, self._lids):
                new[:old] = cur[:old]
        self._lids = L.Lids(*arrays)
        self.n_lid = old
        self.n_solid = getattr(self, "n_solid", 0)

    def _run(self, h, dt_max):
        self.count, _ = K.advance(self._grid, self._state, self._lids, self.n_lid,
                                  self._settings, self._scratch, self.count,
                                  self._steps & 0xFFFFFFFF, h, dt_max)
        self._steps += 1

    def step(self, h):
        """One step of h seconds (split further only if h breaks the wave-speed limit)."""
        self._run(h, h)

    def advance(self, h, dt=None):
        """A coupling step of h seconds in equal substeps no longer than dt (s, default the
        water's own) inside one kernel call."""
        self._run(h, self.dt if dt is None else dt)
        self.time += h

    def total_volume(self) -> float:
        """Water in the columns plus airborne spray (m^3)."""
        return float(self.V.sum()) + self.count * self.particle_volume

    def heights(self) -> np.ndarray:
        """(nx, ny) surface heights (m): bed + depth + external pressure head (the water
        pushed up around a body)."""
        sc = self._scratch
        K.heads(self._grid, self.V, self._lids, self.n_lid, self.kappa, self.ext, sc.eta, sc.H)
        return sc.H.copy()

    def column_centres(self):
        """(nx, ny) x and y (m) of the column centres."""
        nx, ny = self.shape
        x = self.origin[0] + np.arange(nx) * self.spacing
        y = self.origin[1] + np.arange(ny) * self.spacing
        return np.meshgrid(x, y, indexing="ij")

    def surface(self):
        """The surface as a triangle mesh: vertices (nx*ny, 3) m, triangles (m, 3) over the
        squares whose four columns are all fluid."""
        X, Y = self.column_centres()
        verts = np.stack([X.ravel(), Y.ravel(), self.heights().ravel()], axis=1)
        nx, ny = self.shape
        idx = np.arange(nx * ny).reshape(nx, ny)
        f = self.fluid
        ok = (f[:-1, :-1] & f[1:, :-1] & f[:-1, 1:] & f[1:, 1:]).ravel()
        a, b = idx[:-1, :-1].ravel()[ok], idx[1:, :-1].ravel()[ok]
        c, d = idx[1:, 1:].ravel()[ok], idx[:-1, 1:].ravel()[ok]
        tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
        return verts, tris

    def shapes(self):
        """The surface (a height field over the columns: translucent water, its bed heights
        tell wet columns from dry), its spray (bright droplets) and the bed under it (the
        basin's floor and walls, a static mesh over every column)."""
        _, tris = self.surface()
        X, Y = self.column_centres()
        xy = np.stack([X.ravel(), Y.ravel()], axis=1)
        out = [Shape(self.name, "surface", color=self.color or WATER_COLOR,
                     triangles=np.asarray(tris, np.int64), grid_xy=xy,
                     base=self.bed.ravel().copy(), material="water")]
        if self.spray_on:
            out.append(Shape(f"{self.name}-spray", "particles", color=SPRAY_COLOR,
                             width=2.0 * self.params.spray.radius, source=(self.name, "particles"),
                             material="spray"))
        # the bed at every BED_STRIDE-th column (the outer ones kept): a static mesh 4x
        # lighter to draw, within millimetres of the bed on the shore's linear slope
        X, Y = self.column_centres()
        ix = np.unique(np.r_[np.arange(0, self.shape[0], BED_STRIDE), self.shape[0] - 1])
        iy = np.unique(np.r_[np.arange(0, self.shape[1], BED_STRIDE), self.shape[1] - 1])
        bed = self.bed[np.ix_(ix, iy)]
        nx, ny = bed.shape
        idx = np.arange(nx * ny).reshape(nx, ny)
        a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
        c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
        # sand below the highest still water, turning to the banks' colour up to the rim
        wet = self.fluid & (self.V > 0.0)
        # (a basin with no water in it, as a pass that never reads it may leave it: its floor)
        level = (float(np.max(np.where(wet, self.bed + self.V / self.area, -np.inf)))
                 if wet.any() else float(self.bed.min()))
        up = np.clip((bed.ravel() - level) / max(float(self.bed.max()) - level, 1e-3), 0.0,
                     1.0)[:, None]
        colors = (1 - up) * np.asarray(self.bed_color) + up * np.asarray(self.bank_color)
        verts = np.stack([X[np.ix_(ix, iy)].ravel(), Y[np.ix_(ix, iy)].ravel(), bed.ravel()], 1)
        out.append(Shape(f"{self.name}-bed", "static", color=self.bed_color, verts=verts,
                         tris=np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]),
                         palette="static", material="ground", point_colors=colors))
        return out

    def frame(self):
        """heights (nx, ny) m and surface_vz (nx, ny) m/s; particles (capacity, 3) m and
        particle_radius (capacity,) m, NaN past particle_count, so frames stack."""
        cap = self.px.shape[0]
        pts = np.full((cap, 3), np.nan)
        pts[:self.count] = self.px[:self.count]
        rad = np.full(cap, np.nan)
        rad[:self.count] = self.params.spray.radius
        return {"heights": self.heights(), "surface_vz": self.rate.copy(), "particles": pts,
                "particle_radius": rad, "particle_count": np.array(self.count)}

    def kinetic_energy(self):
        self._energy()
        return float(self._em[0])

    def momentum(self):
        self._energy()
        return self._em[1:].copy()

    def _energy(self):
        K.energy_momentum(self._grid, self._state, self.rho, self.count, self.particle_volume,
                          self._em)

    def health(self):
        n = self.count
        total = self.V.sum() + self.Q.sum() + self.px[:n].sum() + self.pv[:n].sum()
        if not math.isfinite(total):
            return [f"{self.name}: state became non-finite at t={self.time:.4f} s"]
        vmin = float(self.V.min())
        if vmin < 0.0:
            return [f"{self.name}: a column went negative ({vmin / self.area:.3g} m) at "
                    f"t={self.time:.4f} s"]
        self._drift = max(self._drift, abs(self.total_volume() / self.volume0 - 1.0))
        return []

    def extra_diagnostics(self) -> dict:
        """volume_drift_rel: largest relative change of the total volume (columns plus
        airborne spray) seen in the run; peak_particles; min_depth_m: shallowest fluid column
        seen (0 where the water left a column dry); spray_emitted_m3: the volume that left
        the surface as spray in all; spray_top_m: the highest a drop flew (m, None if none)."""
        drift = max(self._drift, abs(self.total_volume() / self.volume0 - 1.0))
        t = self._track
        return {"volume_drift_rel": drift, "peak_particles": int(t[K.PEAK]),
                "min_depth_m": float(t[K.MIN_DEPTH]),
                "spray_emitted_m3": float(t[K.EMITTED]) * self.particle_volume,
                "spray_top_m": float(t[K.HIGHEST]) if t[K.EMITTED] else None}

    # --- state ---------------------------------------------------------------------------------
    def generalized_state(self):
        """x: column volumes (m^3), xdot: their rates (m^3/s), flat views. The flows and
        spray are not in it: ``capture`` holds the full state."""
        return self.V.reshape(-1), (self.rate * self.area).reshape(-1)

    def set_generalized_state(self, x, xdot):
        self.V[:] = np.asarray(x, dtype=float).reshape(self.shape)
        self.rate[:] = np.asarray(xdot, dtype=float).reshape(self.shape) / self.area

    def capture(self):
        n = self.count
        return {"V": self.V.copy(), "Q": self.Q.copy(), "ext": self.ext.copy(),
                "rate": self.rate.copy(),
                "px": self.px[:n].copy(), "pv": self.pv[:n].copy(), "count": np.array(n),
                "steps": np.array(self._steps), "track": self._track.copy(),
                "drift": np.array(self._drift), "time": np.array(self.time)}

    def restore(self, snap):
        for key in ("V", "Q", "ext", "rate"):
            getattr(self, key)[:] = snap[key]
        self.n_lid = self.n_solid = 0  # bodies register again at the next coupling step
        n = int(snap["count"])
        self.px[:n] = snap["px"]
        self.pv[:n] = snap["pv"]
        self.count = n
        self._steps = int(snap["steps"])
        self._track[:] = snap["track"]
        self._drift = float(snap["drift"])
        self.time = float(snap["time"])

    # --- bodies --------------------------------------------------------------------------------
    def add_solids(self, solids: L.Solids):
        """Register solids (kernels/lids.py ``Solids``: world ellipsoids, capsules, boxes with
        their volumes and vertical speeds) for this coupling step: where they cut the
        columns, water rising into them meets external pressure. Returns the (first, stop)
        range of the numbers they are known by in ``solid_loads``."""
        first = self.n_solid
        while True:
            n = L.add_solids(solids, self._grid, self.samples, self._lids, self.n_lid, first)
            if n >= 0:
                break
            self._grow_lids(2 * self._lids.cell.shape[0])
        L.group_lids(self._lids, n)
        self.n_lid = n
        self.n_solid = first + len(solids.kind)
        return first, self.n_solid

    def solid_loads(self, solids, out):
        """The water's push on registered solids (the range ``add_solids`` returned): out
        (k, 7) receives per solid the displaced volume (m^3; rho g times it is the buoyancy),
        the centre of buoyancy (m) and the water's velocity there (m/s). Solids registered
        together share the columns they cut exactly; one registered later is seen by them
        from the next coupling step."""
        K.solid_loads(self._grid, self._state, self._lids, self.n_lid, solids[0], solids[1],
                      self.kappa, out)
        return out


def _pipes(fluid):
    """(4, nx, ny) True where a pipe joins two fluid columns (directions as kernels/water)."""
    nx, ny = fluid.shape
    pipe = np.zeros((4, nx, ny), dtype=bool)
    pipe[0, :-1, :] = fluid[:-1, :] & fluid[1:, :]
    pipe[1, :, :-1] = fluid[:, :-1] & fluid[:, 1:]
    pipe[2, :-1, :-1] = fluid[:-1, :-1] & fluid[1:, 1:]
    pipe[3, :-1, 1:] = fluid[:-1, 1:] & fluid[1:, :-1]
    return pipe


def _nearest_fluid(fluid):
    """(nx, ny) flat index of the nearest fluid column: where spray landing on a wall goes."""
    from scipy.ndimage import distance_transform_edt
    ii, jj = distance_transform_edt(~fluid, return_distances=False, return_indices=True)
    return np.ascontiguousarray(ii * fluid.shape[1] + jj, dtype=np.int64)
