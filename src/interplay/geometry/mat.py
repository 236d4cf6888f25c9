"""A gymnastics landing mat: a foam block as a layered spring-mass lattice (SPEC 2.1, 4).

The block (a competition landing mat is about 2-3 m x 1.5-2 m x 0.2 m) is a regular lattice
of ``nx x ny x nz`` points, ``nz`` layers through its thickness. Every cubic cell carries
springs along its 12 edges (the foam's compression and stretch), across its 12 face diagonals
(shear) and its 4 body diagonals (volume: a cell squashed flat must shorten them, so the
block resists being crushed in any direction, not only along its edges). Edge springs get
k = E a / n, with E the foam's compressive modulus (Pa), a the area a spring carries (the cell's
face shared among the four edges around it) and n its rest length, so the block's
stiffness does not depend on the resolution; the braces are a share ``brace`` of that.
The foam is viscoelastic (Kelvin-Voigt: each foam spring's force k (l - l0) + tau k dl/dt,
tau the foam's retardation time): landing mats absorb most of an impact rather than return it
(Mills, Pain & Yeadon 2006). Only the foam's share of a spring is damped so: the stiff top
cover (vinyl, firm foam) would set the explicit step's damping bound at a hundredth of the
foam's (docs/mat.md), so it keeps the network's small stiffness-proportional beta alone.

Calibration (docs/mat.md): Pain, Mills & Yeadon (2005, Med. Sci. Sports Exerc. 37) dropped a
24 kg impactor on a competition landing mat and measured 0.088-0.118 m of deformation; the
modulus below puts this lattice's deformation under that impactor in the band by a 3 m drop
(scenes/mat_impact.drop_test), and its measured load-deflection under a rigid sole and its
impactor drops are what the hybrid stand-in is fitted to (scenes/mat.fit).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..params import param

MAT_COLOR = (0.05, 0.18, 0.55)  # the blue vinyl cover of a landing mat (linear RGB)
FEET_HALF = 0.15  # m: two feet side by side load a 0.3 m square (the stand-in's fit)


@dataclass(frozen=True)
class MatParams:
    """The mat. enabled: false removes it (a rigid floor where its top would be, for
    comparison); length, width, thickness (m) along x, y, z; nx, ny, nz: lattice points along
    each (nz layers); mass (kg): foam and cover; modulus (Pa): the foam's compressive modulus
    E (edge springs k = E a / l); brace (-): the diagonals' stiffness as a share of an
    edge's; foam_damping, brace_damping (s): the foam's retardation time tau on its edges
    (its compression) and on its braces (shear, volume): kd = tau k of the foam's share of a
    spring; stiffness_damping (s): beta of every spring's Rayleigh damping, the cover's too;
    mass_damping (1/s); dt (s): the lattice's explicit step; thickness of the
    contact skin on its top (m) is the contact's; x0 (m): the mat's near edge along x (the
    direction of the vault)."""
    enabled: bool = param(True, doc="false: a rigid floor at the mat's top instead")
    length: float = param(3.0, "m", gt=0.0, le=20.0)
    width: float = param(1.6, "m", gt=0.0, le=20.0)
    thickness: float = param(0.2, "m", gt=0.0, le=2.0)
    nx: int = param(31, "points", ge=2, le=200, cost="points")
    ny: int = param(17, "points", ge=2, le=200, cost="points")
    nz: int = param(4, "points", ge=2, le=20, cost="points")
    mass: float = param(37.5, "kg", gt=0.0, le=1000.0)
    modulus: float = param(6.0e4, "Pa", gt=0.0, le=1e9, doc="foam's compressive modulus")
    brace: float = param(1.5, "-", ge=0.0, le=10.0, doc="diagonals' share of an edge's k")
    cover: float = param(2.0e4, "N", ge=0.0, le=1e8, doc="the top cover's stress/strain")
    top_ratio: float = param(1.0, "-", gt=0.0, le=1e3, doc="top layer's modulus / the foam's")
    foam_damping: float = param(5.5e-3, "s", ge=0.0, le=1.0, doc="foam edges' tau (viscosity)")
    brace_damping: float = param(0.0, "s", ge=0.0, le=1.0, doc="foam braces' tau")
    stiffness_damping: float = param(0.0, "s", ge=0.0, le=1.0)
    mass_damping: float = param(20.0, "1/s", ge=0.0, le=1e3)
    dt: float = param(1e-4, "s", gt=0.0, le=0.01)
    x0: float = param(1.5, "m", ge=-100.0, le=100.0, doc="near edge along x")

    def validated(self) -> "MatParams":
        for name, unit in (("length", "m"), ("width", "m"), ("thickness", "m"),
                           ("mass", "kg"), ("modulus", "Pa"), ("dt", "s")):
            require_positive("mat", name, getattr(self, name), unit)
        if min(self.nx, self.ny, self.nz) < 2:
            raise ParameterError(f"mat: nx, ny, nz must each be at least 2, got {self.nx}, "
                                 f"{self.ny}, {self.nz}")
        return self

    @property
    def spacing(self) -> tuple:
        """(dx, dy, dz) m: the lattice's cell sizes."""
        return (self.length / (self.nx - 1), self.width / (self.ny - 1),
                self.thickness / (self.nz - 1))

    def footprint(self) -> tuple:
        """(x0, x1, y0, y1) m: the mat's top face (centred on y = 0)."""
        return (self.x0, self.x0 + self.length, -0.5 * self.width, 0.5 * self.width)


@dataclass(frozen=True)
class Lattice:
    """The built mat: positions (n,3) m, masses (n,) kg, springs (i, j, rest m, k N/m, kd
    N s/m: the foam's own damping);
    kind (s,) 0 edge, 1 face diagonal, 2 body diagonal; bottom, top: indices of the bottom
    and top layers; triangles (t,3): the block's outer surface (drawn); top_edges (e,2): the
    top face's edges and both diagonals of each of its cells (what a foot collides with:
    mirror-symmetric, as the mat is); shape (nx, ny, nz)."""
    x: np.ndarray
    masses: np.ndarray
    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    kd: np.ndarray
    kind: np.ndarray
    bottom: np.ndarray
    top: np.ndarray
    triangles: np.ndarray
    top_edges: np.ndarray
    shape: tuple


def _grid_faces(index, flip=False):
    """Two triangles per cell of a 2-D index grid (a, b), wound one way or the other."""
    a, b = index.shape
    tris = []
    for s in range(a - 1):
        for t in range(b - 1):
            p, q, r, u = index[s, t], index[s + 1, t], index[s + 1, t + 1], index[s, t + 1]
            tris += [(p, q, r), (p, r, u)] if not flip else [(p, r, q), (p, u, r)]
    return np.array(tris, np.int64)


def build_mat(p: MatParams) -> Lattice:
    """The lattice of the mat resting on the floor (z = 0 at its bottom), its near edge at x0,
    centred on y = 0."""
    p = p.validated()
    nx, ny, nz = p.nx, p.ny, p.nz
    dx, dy, dz = p.spacing
    idx = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    X, Y, Z = np.meshgrid(p.x0 + dx * np.arange(nx), -0.5 * p.width + dy * np.arange(ny),
                          dz * np.arange(nz), indexing="ij")
    x = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    masses = np.full(len(x), p.mass / len(x))
    pairs, kinds, areas = [], [], []
    # the area an edge spring carries: its cross-section cell face shared by the 4 edges
    # around it (a boundary edge carries less, as its cells are fewer; counted by adding
    # a quarter face per cell the edge borders)
    cells = np.ones((nx - 1, ny - 1, nz - 1))
    for axis, (a_face) in enumerate((dy * dz, dx * dz, dx * dy)):
        step = [0, 0, 0]
        step[axis] = 1
        sl = tuple(slice(0, n - s) for n, s in zip((nx, ny, nz), step))
        i0 = idx[sl]
        j0 = idx[tuple(slice(s, None) for s in step)]
        # cells bordering each edge: pad the cell grid and sum the (up to) 4 around it
        other = [d for d in range(3) if d != axis]
        pad = np.pad(cells, [(0, 0) if d == axis else (1, 1) for d in range(3)])
        count = np.zeros(i0.shape)
        for da in (0, 1):
            for db in (0, 1):
                s_ = [slice(None)] * 3
                s_[axis] = slice(0, i0.shape[axis])
                s_[other[0]] = slice(da, da + i0.shape[other[0]])
                s_[other[1]] = slice(db, db + i0.shape[other[1]])
                count += pad[tuple(s_)]
        pairs.append(np.stack([i0.ravel(), j0.ravel()], axis=1))
        kinds.append(np.zeros(i0.size, np.int64))
        areas.append(0.25 * a_face * count.ravel())
    # face diagonals of every cell face (both), body diagonals of every cell
    c = idx[:-1, :-1, :-1]
    corner = {(a, b, e): idx[a:nx - 1 + a, b:ny - 1 + b, e:nz - 1 + e]
              for a in (0, 1) for b in (0, 1) for e in (0, 1)}
    faces = set()
    for axis in range(3):
        o = [d for d in range(3) if d != axis]
        for side in (0, 1):
            for diag in ((0, 0, 1, 1), (1, 0, 0, 1)):
                u = [0, 0, 0]
                w = [0, 0, 0]
                u[axis] = w[axis] = side
                u[o[0]], u[o[1]], w[o[0]], w[o[1]] = diag
                a, b = corner[tuple(u)].ravel(), corner[tuple(w)].ravel()
                for s, t in zip(a, b):
                    faces.add((min(s, t), max(s, t)))
    fd = np.array(sorted(faces), np.int64)
    pairs.append(fd)
    kinds.append(np.ones(len(fd), np.int64))
    bd = np.concatenate([np.stack([corner[(0, 0, 0)].ravel(), corner[(1, 1, 1)].ravel()], 1),
                         np.stack([corner[(1, 0, 0)].ravel(), corner[(0, 1, 1)].ravel()], 1),
                         np.stack([corner[(0, 1, 0)].ravel(), corner[(1, 0, 1)].ravel()], 1),
                         np.stack([corner[(0, 0, 1)].ravel(), corner[(1, 1, 0)].ravel()], 1)])
    pairs.append(bd)
    kinds.append(np.full(len(bd), 2, np.int64))
    del c
    ij = np.concatenate(pairs)
    kind = np.concatenate(kinds)
    rest = np.linalg.norm(x[ij[:, 0]] - x[ij[:, 1]], axis=1)
    k = np.empty(len(ij))
    edge = kind == 0
    k[edge] = p.modulus * np.concatenate(areas) / rest[edge]
    # a brace: the modulus over the cell's mean face, as stiff per length as an inner edge
    face = (dx * dy + dy * dz + dx * dz) / 3.0
    k[~edge] = p.brace * p.modulus * face / rest[~edge]
    # the top layer of cells is a firmer foam (top_ratio times the modulus): competition
    # mats put a firm layer over a soft one, and a firm layer spreads a foot's load over the
    # soft foam as a plate (Mills, Pain & Yeadon 2006 model such a mat in layers)
    zmin = np.minimum(x[ij[:, 0], 2], x[ij[:, 1], 2])
    k[zmin >= p.thickness - dz - 1e-9] *= p.top_ratio
    # the cover: a stiff skin over the top face (vinyl over a firmer top foam) that spreads a
    # foot's load over the foam around it, as an area-elastic mat does; k = cover / length
    # on every spring lying in the top face (its edges and face diagonals)
    zi, zj = x[ij[:, 0], 2], x[ij[:, 1], 2]
    skin = (np.abs(zi - p.thickness) < 1e-9) & (np.abs(zj - p.thickness) < 1e-9)
    # the foam's viscosity on its share of each spring (the cover's share is not foam)
    kd = np.where(edge, p.foam_damping, p.brace_damping) * k
    k[skin] += p.cover / rest[skin]
    bottom = idx[:, :, 0].ravel()
    top = idx[:, :, -1].ravel()
    tris = np.concatenate([_grid_faces(idx[:, :, -1]), _grid_faces(idx[:, :, 0], True),
                           _grid_faces(idx[:, 0, :], True), _grid_faces(idx[:, -1, :]),
                           _grid_faces(idx[0, :, :]), _grid_faces(idx[-1, :, :], True)])
    # what a foot meets: every edge of the top face and both diagonals of each of its cells.
    # One diagonal per cell (a triangulation) is not mirror-symmetric: measured, it loaded a
    # landing's right toes 9 times the left ones and she fell sideways on a symmetric mat
    t = idx[:, :, -1]
    e = np.concatenate([np.stack([t[:-1, :].ravel(), t[1:, :].ravel()], 1),
                        np.stack([t[:, :-1].ravel(), t[:, 1:].ravel()], 1),
                        np.stack([t[:-1, :-1].ravel(), t[1:, 1:].ravel()], 1),
                        np.stack([t[1:, :-1].ravel(), t[:-1, 1:].ravel()], 1)])
    e = np.sort(e, axis=1)
    return Lattice(x, masses, ij[:, 0].copy(), ij[:, 1].copy(), rest, k, kd, kind, bottom, top,
                   tris, np.unique(e, axis=0), (nx, ny, nz))
