"""A gymnastics landing mat: a foam block as a layered spring-mass lattice (SPEC 2.1, 4).

The block (a competition landing mat is about 2-3 m x 1.5-2 m x 0.2 m) is a regular lattice
of ``nx x ny x nz`` points, ``nz`` layers through its thickness. Every cell carries springs
along its 12 edges, across its 12 face diagonals and its 4 body diagonals (a cell squashed
flat must shorten them). The springs are derived from materials, not stated per spring, so
the mat's stiffness does not depend on the resolution: the foam is an isotropic solid of
Young's modulus E and Poisson's ratio 1/4 (the one isotropic solid a central-force lattice
can be), and each family's k is what makes a uniform strain store that solid's energy
(``foam_weights``); the top face carries a cover, a membrane of tension stiffness N (N/m)
whose springs are derived the same way on the top's grid (``cover_springs``). The foam is
viscoelastic (Kelvin-Voigt: each foam spring's force k (l - l0) + tau k dl/dt, tau the
foam's retardation time): landing mats absorb most of an impact rather than return it
(Mills, Pain & Yeadon 2006). The cover is undamped (it is not foam).

Calibration (docs/mat.md): Pain, Mills & Yeadon (2005, Med. Sci. Sports Exerc. 37) dropped a
24 kg impactor on a competition landing mat and measured 0.088-0.118 m of deformation; the
modulus and cover below put this lattice's deformation under that impactor in the band by a
3 m drop
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
    each (nz layers; no cell side more than ~1.7 times another); mass (kg): foam and cover;
    modulus (Pa): the foam's Young's modulus E (an isotropic solid, nu = 1/4); brace (-):
    the body diagonals' share of the foam's shear constants (below 1: the rest is the face
    diagonals'); cover (N/m): the top cover's tension stiffness N (a membrane, nu = 1/3);
    top_ratio (-): the top layer of cells' modulus over the foam's; foam_damping,
    brace_damping (s): the foam's retardation time tau on its edges and on its diagonals:
    kd = tau k of the foam's share of a spring; stiffness_damping (s): beta of every
    spring's Rayleigh damping, the cover's too; mass_damping (1/s); dt (s): the lattice's
    explicit step; x0 (m): the mat's near edge along x (the direction of the vault)."""
    enabled: bool = param(True, doc="false: a rigid floor at the mat's top instead")
    length: float = param(3.0, "m", gt=0.0, le=20.0)
    width: float = param(1.6, "m", gt=0.0, le=20.0)
    thickness: float = param(0.2, "m", gt=0.0, le=2.0)
    nx: int = param(46, "points", ge=2, le=200, cost="points")
    ny: int = param(37, "points", ge=2, le=200, cost="points")
    nz: int = param(4, "points", ge=2, le=20, cost="points")
    mass: float = param(37.5, "kg", gt=0.0, le=1000.0)
    modulus: float = param(1.1e5, "Pa", gt=0.0, le=1e9, doc="foam's Young's modulus")
    brace: float = param(0.5, "-", ge=0.0, lt=1.0, doc="body diagonals' share of the shear")
    cover: float = param(3.0e5, "N/m", ge=0.0, le=1e9, doc="the top cover's tension stiffness")
    top_ratio: float = param(1.0, "-", gt=0.0, le=1e3, doc="top layer's modulus / the foam's")
    foam_damping: float = param(3e-3, "s", ge=0.0, le=1.0, doc="foam edges' tau (viscosity)")
    brace_damping: float = param(3e-3, "s", ge=0.0, le=1.0, doc="foam braces' tau")
    stiffness_damping: float = param(0.0, "s", ge=0.0, le=1.0)
    mass_damping: float = param(20.0, "1/s", ge=0.0, le=1e3)
    dt: float = param(4e-5, "s", gt=0.0, le=0.01)
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


#: the lattice families: edges along x, y, z (0-2); face diagonals in the faces normal to x,
#: y, z (3-5); body diagonals (6). A family's cell weight W (Pa) is k l^2 / V summed over the
#: springs one cell holds of it (a spring k = W V / (per-cell count l^2) times its share of
#: the cells around it)
BODY = 6
_PER_CELL = np.array([1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 4.0])
_PAIRS = ((0, 1), (0, 2), (1, 2))


def _cosines(cell):
    """Squared direction cosines (3,) of each face family's diagonal (in its plane's two
    axes, the normal's cosine 0) and of the body diagonal: rows 3-6 of the families."""
    d = np.asarray(cell, float)
    rows = []
    for normal in range(3):
        v = d.copy()
        v[normal] = 0.0
        rows.append(v * v / (v @ v))
    rows.append(d * d / (d @ d))
    return np.array(rows)


def elastic_constants(weights, cell) -> np.ndarray:
    """The lattice's elastic constants (Pa) under a uniform strain: C (3,3), C[a, b] the
    stress along a per strain along b (a central-force lattice's shear constants equal its
    C[a, b], a != b: the Cauchy relations). A spring of direction cosines n stores
    k l^2 (n.e.n)^2 / 2 under the strain e: per volume, the sum over a family's springs of a
    cell gives W n_a^2 n_b^2 to C[a, b] (the +-sign diagonals' shear cross terms cancel)."""
    c = np.diag(np.asarray(weights[:3], float))
    for w, n2 in zip(weights[3:], _cosines(cell)):
        c += w * np.outer(n2, n2)
    return c


def foam_weights(modulus: float, body_share: float, cell) -> np.ndarray:
    """The 7 families' cell weights (Pa) for a cell (dx, dy, dz) m that give the lattice the
    elastic constants of an isotropic foam of Young's modulus ``modulus`` and Poisson's ratio
    1/4, whatever the resolution. A central-force lattice's shear constants equal its
    C[a, b] (the Cauchy relations), and the isotropic solid that obeys them has nu = 1/4:
    C[a, a] = 6 E / 5, C[a, b] = 2 E / 5. The body diagonals take ``body_share`` of the
    weakest pair's C[a, b] (their cosines load all three pairs), the face diagonals the rest
    of each C[a, b], the edges what is left of each C[a, a] (>= 0 while no cell is more than
    about sqrt(3) times longer one way than another)."""
    target = np.full((3, 3), 0.4 * modulus) + np.eye(3) * 0.8 * modulus
    cos = _cosines(cell)
    w = np.zeros(7)
    w[BODY] = body_share * min(target[a, b] / (cos[3, a] * cos[3, b]) for a, b in _PAIRS)
    for a, b in _PAIRS:
        normal = 3 - a - b
        w[3 + normal] = (target[a, b] - w[BODY] * cos[3, a] * cos[3, b]) / (
            cos[normal, a] * cos[normal, b])
    w[:3] = np.diag(target) - np.diag(elastic_constants(np.r_[0.0, 0.0, 0.0, w[3:]], cell))
    if w[:3].min() < 0.0:
        raise ParameterError(
            f"mat: cells of {cell[0]:.3g} x {cell[1]:.3g} x {cell[2]:.3g} m are too elongated "
            f"for the lattice to hold an isotropic foam (the diagonals would need edges of "
            f"negative stiffness); choose nx, ny, nz so no cell side is over ~1.7 times "
            f"another, or a larger mat.brace")
    return w


def cover_springs(tension: float, dx: float, dy: float, kind, rest, share) -> np.ndarray:
    """k (N/m) of the top face's springs (kind 0, 1: edges along x, y; 5: the cells' face
    diagonals; ``share``: each one's share of the 3-D cells around it) for a membrane of
    tension stiffness ``tension`` (N/m) on the grid dx by dy (m). The only isotropic membrane
    a grid of edges and both diagonals can be has Poisson's ratio 1/3 (its C12 equals its
    shear C66), so C11 = C22 = 9 N / 8 and C12 = 3 N / 8. Under a uniform in-plane strain e a
    cell (area A) stores sum k l^2 (n.e.n)^2 / 2 over its springs: its two diagonals
    (cosines a, b) give W_d a^2 b^2 to C12 with W_d = 2 k_d l_d^2 / A, and W_d a^4, W_d b^4 to
    C11, C22; its edges (each shared by 2 cells) W_x = k_x l_x^2 / A to C11 and W_y to C22.
    So W_d = C12 / (a^2 b^2), W_x = C11 - W_d a^4, W_y = C22 - W_d b^4: a uniform stretch
    stores the membrane's energy at any spacing (W_x, W_y >= 0 needs dx / dy within
    1/sqrt(3) .. sqrt(3)). A top edge's share of 3-D cells is half its share of top cells,
    a top diagonal's 1/2 of its one cell."""
    if tension == 0.0:
        return np.zeros(len(kind))
    area, d2 = dx * dy, dx * dx + dy * dy
    a2, b2 = dx * dx / d2, dy * dy / d2
    c11, c12 = 9.0 * tension / 8.0, 3.0 * tension / 8.0
    wd = c12 / (a2 * b2)
    wx, wy = c11 - wd * a2 * a2, c11 - wd * b2 * b2
    if min(wx, wy) < 0.0:
        raise ParameterError(
            f"mat: the cover's grid of {dx:.3g} x {dy:.3g} m cannot hold an isotropic "
            f"membrane (dx / dy = {dx / dy:.3g}, allowed 0.577..1.73); choose nx, ny so the "
            f"top's cells are nearer square")
    per = np.select([kind == 0, kind == 1, kind == 5], [wx * 2.0, wy * 2.0, wd], 0.0)
    return per * area / rest ** 2 * share


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
    pairs, kinds, shares = [], [], []
    # each spring's share of the cells around it (a boundary spring has fewer cells): an
    # edge is shared by 4 cells, a face diagonal by the 2 cells on its face, a body diagonal
    # is its cell's own; a spring's k is its family's cell weight times that share
    cells = np.ones((nx - 1, ny - 1, nz - 1))
    for axis in range(3):
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
        kinds.append(np.full(i0.size, axis, np.int64))
        shares.append(0.25 * count.ravel())
    # face diagonals of every cell face (both), counted once per cell they border
    corner = {(a, b, e): idx[a:nx - 1 + a, b:ny - 1 + b, e:nz - 1 + e]
              for a in (0, 1) for b in (0, 1) for e in (0, 1)}
    faces = {}
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
                    key = (min(s, t), max(s, t))
                    faces[key] = faces.get(key, 0) + 1
    keys = sorted(faces)
    fd = np.array(keys, np.int64)
    # a face diagonal's family is its face's normal: the one axis it does not cross
    pairs.append(fd)
    kinds.append(3 + np.argmax(np.abs(x[fd[:, 1]] - x[fd[:, 0]]) < 1e-12, axis=1))
    shares.append(0.5 * np.array([faces[e] for e in keys], float))
    bd = np.concatenate([np.stack([corner[(0, 0, 0)].ravel(), corner[(1, 1, 1)].ravel()], 1),
                         np.stack([corner[(1, 0, 0)].ravel(), corner[(0, 1, 1)].ravel()], 1),
                         np.stack([corner[(0, 1, 0)].ravel(), corner[(1, 0, 1)].ravel()], 1),
                         np.stack([corner[(0, 0, 1)].ravel(), corner[(1, 1, 0)].ravel()], 1)])
    pairs.append(bd)
    kinds.append(np.full(len(bd), BODY, np.int64))
    shares.append(np.ones(len(bd)))
    ij = np.concatenate(pairs)
    kind = np.concatenate(kinds)
    share = np.concatenate(shares)
    rest = np.linalg.norm(x[ij[:, 0]] - x[ij[:, 1]], axis=1)
    # the foam: each family's k from the cell weights that give every resolution the
    # reference lattice's elastic constants (foam_weights)
    w = foam_weights(p.modulus, p.brace, (dx, dy, dz))
    vol = dx * dy * dz
    k = w[kind] * vol / (_PER_CELL[kind] * rest ** 2) * share
    # the top layer of cells is a firmer foam (top_ratio times the modulus): competition
    # mats put a firm layer over a soft one, and a firm layer spreads a foot's load over the
    # soft foam as a plate (Mills, Pain & Yeadon 2006 model such a mat in layers)
    zmin = np.minimum(x[ij[:, 0], 2], x[ij[:, 1], 2])
    k[zmin >= p.thickness - dz - 1e-9] *= p.top_ratio
    # the foam's viscosity on its share of each spring (the cover's share is not foam)
    edge = kind <= 2
    kd = np.where(edge, p.foam_damping, p.brace_damping) * k
    # the cover: a membrane of tension stiffness N = cover (N/m) over the top face (vinyl
    # over a firmer top foam) that spreads a foot's load over the foam around it
    zi, zj = x[ij[:, 0], 2], x[ij[:, 1], 2]
    skin = (np.abs(zi - p.thickness) < 1e-9) & (np.abs(zj - p.thickness) < 1e-9)
    k[skin] += cover_springs(p.cover, dx, dy, kind[skin], rest[skin], share[skin])
    kind = np.where(edge, 0, np.where(kind == BODY, 2, 1))
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
