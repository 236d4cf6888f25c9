"""A competition trampoline: the woven bed as a spring-mass grid, hung from a rigid frame by
coil springs around its edge (SPEC 2.1, 4), and the frame as a drawn set piece.

Dimensions follow the competition apparatus (FIG; olympic.org "Trampoline equipment": frame
5.05 x 2.91 m, 1.155 m high; a bed of about 4.3 x 2.1 m on about 110-120 springs). The bed is
a grid of points joined by springs along every triangle edge of a criss-cross triangulation
(the webbing: stiff in stretch, weak in shear and bending); each edge point hangs on one frame
spring, a tension-only spring to a fixed point on the frame rail, pre-stretched so the bed is
taut at rest. The vertical load-deflection of such a bed is not that of a spring: the frame
springs are horizontal at rest, so the bed's first resistance is the pre-tension turned by
the bed's slope, and it stiffens as the springs stretch (Kraft 2001; docs/trampoline.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..params import param
from . import shapes


@dataclass(frozen=True)
class BedParams:
    """The trampoline. length, width (m): the bed along x and y; height (m): the bed's rest
    plane above the floor; nu, nv: grid points along x and y (the edge points, 2 (nu + nv) - 4,
    are where the springs hook on); mass (kg): bed and springs together (the paper's 20 kg),
    of which spring_mass (kg) per spring, half at its bed end (the other half rests on the
    frame); gap (m): a frame spring's installed length, bed edge to rail; spring_stiffness
    (N/m) per spring and spring_tension (N) its pull at that length (a coil spring wound with
    initial tension: the pre-tension that keeps the bed taut); stretch (N): the straps'
    stress/strain ratio (k = stretch / rest length), shear and bend (N) the weave's shear and
    bending springs;
    mass_damping (1/s), stiffness_damping (s): Rayleigh; dt (s): the bed's step (explicit:
    below the stability bound the builder reports); thickness (m): half the bed's thickness,
    its contact skin; fine_x, fine_y (m): half extents of a central zone whose cells are
    halved along x and along y (0: none), so the bed resolves a foot where she lands
    (docs/trampoline.md: a foot narrower than a facet chatters); the webbing's stiffness per
    width, mass per area and the frame springs' per length of edge stay those of the coarse
    grid, so its load-deflection does too."""
    length: float = param(4.28, "m", gt=0.0, le=50.0)
    width: float = param(2.14, "m", gt=0.0, le=50.0)
    height: float = param(1.155, "m", gt=0.0, le=20.0, doc="the bed's rest plane")
    nu: int = param(37, "points", ge=3, le=400, cost="points")
    nv: int = param(19, "points", ge=3, le=400, cost="points")
    mass: float = param(20.0, "kg", gt=0.0, le=1000.0, doc="bed and springs")
    spring_mass: float = param(0.12, "kg", ge=0.0, le=10.0, doc="per frame spring")
    gap: float = param(0.30, "m", gt=0.0, le=5.0, doc="a frame spring's installed length")
    spring_stiffness: float = param(250.0, "N/m", gt=0.0, le=1e7, doc="per frame spring")
    spring_tension: float = param(120.0, "N", gt=0.0, le=1e6, doc="per spring, installed")
    stretch: float = param(1.0e4, "N", gt=0.0, le=1e8, doc="straps' stress/strain")
    shear: float = param(500.0, "N", gt=0.0, le=1e8)
    bend: float = param(30.0, "N", gt=0.0, le=1e8)
    mass_damping: float = param(0.0, "1/s", ge=0.0, le=1e3)
    stiffness_damping: float = param(1e-4, "s", ge=0.0, le=1.0)
    dt: float = param(1.25e-4, "s", gt=0.0, le=0.01)
    thickness: float = param(0.004, "m", gt=0.0, le=0.2, doc="contact skin")
    fine_x: float = param(0.0, "m", ge=0.0, le=25.0, doc="central zone refined along x")
    fine_y: float = param(0.0, "m", ge=0.0, le=25.0, doc="central zone refined along y")

    def validated(self) -> "BedParams":
        for name, unit in (("length", "m"), ("width", "m"), ("height", "m"), ("mass", "kg"),
                           ("gap", "m"), ("spring_tension", "N"), ("spring_stiffness", "N/m"),
                           ("stretch", "N"), ("shear", "N"), ("bend", "N"), ("dt", "s"),
                           ("thickness", "m")):
            require_positive("trampoline", name, getattr(self, name), unit)
        springs = 2 * (self.nu + self.nv) - 4
        if not 0.0 <= self.spring_mass * springs < self.mass:
            raise ParameterError(f"trampoline: {springs} springs of spring_mass "
                                 f"{self.spring_mass} kg leave no mass for the bed "
                                 f"(mass {self.mass} kg); lower spring_mass")
        return self


@dataclass(frozen=True)
class Bed:
    """The built trampoline: positions (n,3) m of the bed's grid points then the frame points;
    masses (n,) kg; triangles (t,3) of the bed; springs as (i, j, rest m, k N/m,
    tension_only) arrays: the webbing's then the frame springs; frame (e,) indices of the
    frame points (fixed); edge (e,) the bed points they hold; bed_points: how many grid
    points; kind (s,) 0 structural, 1 shear, 2 bending, 3 frame spring."""
    x: np.ndarray
    masses: np.ndarray
    triangles: np.ndarray
    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    tension_only: np.ndarray
    kind: np.ndarray
    frame: np.ndarray
    edge: np.ndarray
    bed_points: int

    @property
    def frame_springs(self) -> np.ndarray:
        """(e,2) point pairs of the frame springs (bed edge, frame)."""
        return np.stack([self.edge, self.frame], axis=1)


def edge_points(nu: int, nv: int):
    """Indices of the grid's boundary points and the outward unit directions (e,3) their
    springs pull along: perpendicular to the side, diagonal at the corners."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv))
    i, j = i.ravel(), j.ravel()
    out = np.stack([(i == nu - 1).astype(float) - (i == 0), (j == nv - 1).astype(float)
                    - (j == 0), np.zeros(len(i))], axis=1)
    edge = np.flatnonzero(np.abs(out).sum(axis=1) > 0)
    d = out[edge]
    return edge, d / np.linalg.norm(d, axis=1)[:, None]


def weave(nu: int, nv: int):
    """Spring index pairs (s,2) of a woven grid of nu x nv points (point (i, j) is j nu + i)
    and their kinds: 0 the straps (neighbours along x and along y), 1 shear (both diagonals
    of every cell), 2 bending (across two cells along x and y). Unlike a cloth, a woven bed
    has its stretch stiffness in the straps only: the weave shears freely, which is what lets
    a bed of inextensible straps take the funnel shape of a depression."""
    idx = np.arange(nu * nv).reshape(nv, nu)
    pairs = [(idx[:, :-1], idx[:, 1:], 0), (idx[:-1, :], idx[1:, :], 0),
             (idx[:-1, :-1], idx[1:, 1:], 1), (idx[:-1, 1:], idx[1:, :-1], 1),
             (idx[:, :-2], idx[:, 2:], 2), (idx[:-2, :], idx[2:, :], 2)]
    ij = np.concatenate([np.stack([a.ravel(), b.ravel()], axis=1) for a, b, _ in pairs])
    kind = np.concatenate([np.full(a.size, k) for a, _, k in pairs])
    return ij, kind


def graded(length: float, n: int, fine: float) -> np.ndarray:
    """Coordinates (m) of n points evenly spanning length centred on 0, with the midpoint
    added in every cell that lies within |x| <= fine (m)."""
    c = np.linspace(-length / 2, length / 2, n)
    tol = 1e-9 * length
    mid = [(a + b) / 2 for a, b in zip(c[:-1], c[1:]) if max(abs(a), abs(b)) <= fine + tol]
    return np.sort(np.concatenate([c, mid]))


def _widths(c: np.ndarray) -> np.ndarray:
    """The width (m) of the strip each grid line carries: half of each neighbouring cell."""
    d = np.diff(c)
    return np.concatenate([[d[0] / 2], (d[:-1] + d[1:]) / 2, [d[-1] / 2]])


def _refined_shares(p: BedParams, xs, ys, pairs, edge):
    """For a graded grid: each spring's strip width over the coarse spacing (a diagonal: its
    cell's size over the coarse cell's), each point's area (m^2), and each frame spring's
    length of edge over the coarse spacing."""
    nu = len(xs)
    s = np.array([p.length / (p.nu - 1), p.width / (p.nv - 1)])
    wx, wy = _widths(xs), _widths(ys)
    area = np.outer(wy, wx).ravel()
    wx[[0, -1]], wy[[0, -1]] = 2 * wx[[0, -1]], 2 * wy[[0, -1]]  # border lines: whole strips
    iu, jv = pairs % nu, pairs // nu
    cell = np.sqrt(np.abs(np.diff(xs[iu], axis=1)[:, 0] * np.diff(ys[jv], axis=1)[:, 0])
                   / (s[0] * s[1]))
    strip = np.where(jv[:, 0] == jv[:, 1], wy[jv[:, 0]] / s[1],
                     np.where(iu[:, 0] == iu[:, 1], wx[iu[:, 0]] / s[0], cell))
    ei, ej = edge % nu, edge // nu
    ends = (ei == 0) | (ei == nu - 1)
    side = np.where(ends, wy[ej] / s[1], wx[ei] / s[0])
    side[ends & ((ej == 0) | (ej == len(ys) - 1))] = 1.0
    return strip, area, side


def build_bed(p: BedParams) -> Bed:
    """The bed grid centred on the origin at z = height, its frame springs and masses."""
    p = p.validated()
    xs, ys = graded(p.length, p.nu, p.fine_x), graded(p.width, p.nv, p.fine_y)
    nu, nv = len(xs), len(ys)
    gx, gy = np.meshgrid(xs, ys)
    x = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, p.height)], axis=1)
    _, tris = shapes.grid(p.length, p.width, nu, nv)
    edge, out = edge_points(nu, nv)
    n, e = len(x), len(edge)
    pairs, kind = weave(nu, nv)
    rest = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    # a spring stands for the strip of webbing across it: k = modulus x strip width / rest,
    # the coarse grid's modulus being stretch (shear, bend) / its spacing; on the even grid
    # the strip is the spacing (its border lines' too, as always): k = stretch / rest. The
    # webbing's mass by the area each point carries (a quarter of each cell at its corners:
    # uniform inside, unlike a criss-cross triangulation's thirds); half of each spring's at
    # its hook. A frame spring stands for the length of edge its point carries (its
    # stiffness, tension and mass scale with it; the corners' diagonal ones are whole)
    strip, side = np.ones(len(pairs)), np.ones(e)
    area = np.outer(np.r_[0.5, np.ones(nv - 2), 0.5], np.r_[0.5, np.ones(nu - 2), 0.5]).ravel()
    if p.fine_x > 0.0 or p.fine_y > 0.0:
        strip, area, side = _refined_shares(p, xs, ys, pairs, edge)
    k = np.array([p.stretch, p.shear, p.bend])[kind] * strip / rest
    springs = 2 * (p.nu + p.nv) - 4
    masses = np.concatenate([area * (p.mass - p.spring_mass * springs) / area.sum(),
                             side * p.spring_mass / 2.0])
    masses[edge] += side * p.spring_mass / 2.0
    frame = np.arange(n, n + e)
    # k (l - rest) = spring_tension at l = gap; rest < 0 when the preload exceeds k gap (a
    # preloaded spring, never slack), else the spring goes slack below its rest length
    spring_rest = p.gap - p.spring_tension / p.spring_stiffness
    return Bed(np.vstack([x, x[edge] + p.gap * out]), masses, tris,
               np.concatenate([pairs[:, 0], edge]), np.concatenate([pairs[:, 1], frame]),
               np.concatenate([rest, np.full(e, spring_rest)]),
               np.concatenate([k, side * p.spring_stiffness]),
               np.concatenate([np.zeros(len(rest), bool), np.full(e, spring_rest > 0)]),
               np.concatenate([kind, np.full(e, 3)]), frame, edge, n)


def _box(lo, hi):
    """Vertices (8,3) and outward triangles (12,3) of the axis-aligned box lo..hi (m)."""
    from ..systems.colliders import box_surface
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v, t = box_surface((hi - lo) / 2.0)
    return v + (lo + hi) / 2.0, t


def frame_mesh(p: BedParams, rail: float = 0.05, leg: float = 0.05):
    """The steel frame as one triangle mesh (vertices m, triangles): four rails of square
    section ``rail`` (m) whose inner faces carry the springs' hooks, and four legs of section
    ``leg`` (m) at the corners down to the floor (z = 0)."""
    hx, hy = p.length / 2 + p.gap, p.width / 2 + p.gap  # the rails' inner faces
    z = p.height
    boxes = [((-hx - rail, -hy - rail, z - rail), (hx + rail, -hy, z)),
             ((-hx - rail, hy, z - rail), (hx + rail, hy + rail, z)),
             ((-hx - rail, -hy, z - rail), (-hx, hy, z)),
             ((hx, -hy, z - rail), (hx + rail, hy, z))]
    for sx in (-1, 1):
        for sy in (-1, 1):
            cx, cy = sx * (hx + rail / 2), sy * (hy + rail / 2)
            boxes.append(((cx - leg / 2, cy - leg / 2, 0.0), (cx + leg / 2, cy + leg / 2,
                                                              z - rail)))
    verts, tris, base = [], [], 0
    for lo, hi in boxes:
        v, t = _box(lo, hi)
        verts.append(v)
        tris.append(t + base)
        base += len(v)
    return np.concatenate(verts), np.concatenate(tris)
