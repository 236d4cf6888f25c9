"""Triangle meshes for spring-mass networks (SPEC 2.1): loading, validation and the spring
builder.

A mesh is vertices (n,3) in m and triangles (m,3) of vertex indices. ``validate`` refuses what
cannot be simulated and names the first offending element; ``load`` reads OBJ/PLY/STL through
trimesh (vertices kept as written: no merging or reordering, so indices in the file stay valid);
``mesh_springs`` builds the network:

* structural springs on every edge;
* one cross spring per interior edge (an edge shared by exactly two triangles), between the two
  vertices opposite it. It is a *shear* spring when the shared edge is the longest edge of both
  triangles (a quad's diagonal: the cross spring is the other diagonal) and a *bending* spring
  otherwise (it resists folding about the edge);
* stiffness k = (stress/strain ratio, N) / rest length, per kind;
* masses uniform or by incident triangle area (m_i = sum_t rho A_t / 3).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive

MASS_MODES = ("area", "uniform")
#: the largest mesh file read (bytes) and the most vertices a network is built from
MAX_FILE_BYTES = 256 * 2 ** 20
MAX_VERTICES = 2_000_000
MAX_COORDINATE = 1e6  # m: squared lengths and areas stay far from overflow
KINDS = ("structural", "shear", "bending")


def validate(vertices, triangles, name: str = "mesh") -> tuple[np.ndarray, np.ndarray]:
    """The mesh as float (n,3) and int64 (m,3) arrays, or ParameterError naming the first bad
    element: non-finite coordinates, indices out of range, a triangle repeating a vertex, a
    zero-length edge, a zero-area (degenerate) triangle, a duplicate triangle."""
    x = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles)
    if x.ndim != 2 or x.shape[1] != 3 or len(x) < 3:
        raise ParameterError(f"{name}: vertices must be an (n,3) array with n >= 3, got shape "
                             f"{x.shape}")
    if t.ndim != 2 or t.shape[1] != 3 or len(t) == 0:
        raise ParameterError(f"{name}: triangles must be an (m,3) array with m >= 1, got shape "
                             f"{t.shape}")
    if not np.issubdtype(t.dtype, np.integer):
        raise ParameterError(f"{name}: triangle indices must be integers, got {t.dtype}")
    t = t.astype(np.int64)
    bad = np.flatnonzero(~np.all(np.isfinite(x), axis=1))
    if len(bad):
        raise ParameterError(f"{name}: vertex {bad[0]} has a non-finite coordinate {x[bad[0]]}; "
                             "fix or remove it")
    bad = np.flatnonzero(np.abs(x).max(axis=1) > MAX_COORDINATE)
    if len(bad):
        raise ParameterError(f"{name}: vertex {bad[0]} at {x[bad[0]]} is more than "
                             f"{MAX_COORDINATE:g} m from the origin; check the file's units")
    bad = np.flatnonzero(np.any((t < 0) | (t >= len(x)), axis=1))
    if len(bad):
        raise ParameterError(f"{name}: triangle {bad[0]} {t[bad[0]].tolist()} references a vertex "
                             f"outside 0..{len(x) - 1}")
    bad = np.flatnonzero((t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 0] == t[:, 2]))
    if len(bad):
        raise ParameterError(f"{name}: triangle {bad[0]} {t[bad[0]].tolist()} repeats a vertex "
                             "(degenerate); remove it")
    scale = float(np.ptp(x, axis=0).max()) or 1.0
    for a, b in ((0, 1), (1, 2), (2, 0)):
        ln = np.linalg.norm(x[t[:, a]] - x[t[:, b]], axis=1)
        bad = np.flatnonzero(ln <= 1e-12 * scale)
        if len(bad):
            tri = bad[0]
            raise ParameterError(f"{name}: triangle {tri} has a zero-length edge between vertices "
                                 f"{t[tri, a]} and {t[tri, b]} (both at {x[t[tri, a]]}); merge "
                                 "the duplicate vertices")
    area = triangle_areas(x, t)
    # relative to the longest edge squared: a sliver whose area is lost in rounding is degenerate
    longest = np.max([np.sum((x[t[:, a]] - x[t[:, b]]) ** 2, axis=1)
                      for a, b in ((0, 1), (1, 2), (2, 0))], axis=0)
    bad = np.flatnonzero(area <= 1e-12 * longest)
    if len(bad):
        raise ParameterError(f"{name}: triangle {bad[0]} {t[bad[0]].tolist()} has zero area "
                             "(its vertices are collinear); remove it")
    key = np.sort(t, axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    if np.any(counts > 1):
        dup_key = key[first[counts > 1]]
        dups = np.flatnonzero(np.all(key[:, None, :] == dup_key[None, :, :], axis=2).any(axis=1))
        raise ParameterError(f"{name}: triangle {dups[1]} {t[dups[1]].tolist()} duplicates "
                             f"triangle {dups[0]}; remove one of them")
    return x, t


def triangle_areas(x, t) -> np.ndarray:
    """Area (m^2) of each triangle."""
    return 0.5 * np.linalg.norm(np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]), axis=1)


def load(path, name: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a triangle mesh (OBJ, PLY, STL, ... anything trimesh reads) and validate it.

    Vertices are kept exactly as in the file (trimesh's merging is off). Quads and polygons are
    triangulated by trimesh. A scene with several objects is concatenated."""
    from pathlib import Path

    import trimesh

    from ..io.inputs import regular_file
    p = Path(path)
    name = name or p.name
    if not p.exists():
        raise ParameterError(f"{name}: mesh file {p} does not exist")
    regular_file(p, MAX_FILE_BYTES, "mesh file", ParameterError)
    try:
        mesh = trimesh.load(p, force="mesh", process=False)
    except Exception as e:  # trimesh raises many kinds for unreadable files
        msg = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise ParameterError(f"{name}: cannot read mesh file {p}: {msg}") from None
    if not hasattr(mesh, "faces") or len(mesh.faces) == 0:
        raise ParameterError(f"{name}: {p} contains no triangles")
    if len(mesh.vertices) > MAX_VERTICES:
        raise ParameterError(f"{name}: {p} has {len(mesh.vertices):,} vertices, over the "
                             f"{MAX_VERTICES:,} a network may have; decimate it")
    return validate(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces), name)


def edges(t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique edges (e,2) (i < j), and for each the count of triangles using it and, for edges
    used by exactly two, the two triangles (e,2) (-1 where absent)."""
    half = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    tri = np.concatenate([np.arange(len(t))] * 3)
    half = np.sort(half, axis=1)
    uniq, inv, counts = np.unique(half, axis=0, return_inverse=True, return_counts=True)
    inv = inv.reshape(-1)
    order = np.argsort(inv, kind="stable")
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    pair = np.full((len(uniq), 2), -1, dtype=np.int64)
    two = counts == 2
    pair[two, 0] = tri[order[start[two]]]
    pair[two, 1] = tri[order[start[two] + 1]]
    return uniq, counts, pair


@dataclass(frozen=True)
class MeshSprings:
    """Spring index pairs (s,2), their kind (s,) as an index into KINDS, and per-point masses (kg)."""
    pairs: np.ndarray
    kind: np.ndarray
    masses: np.ndarray

    def count(self, kind: str) -> int:
        return int(np.sum(self.kind == KINDS.index(kind)))


def _opposite(t, tri, e):
    """The vertex of each triangle tri[k] that is not on edge e[k]."""
    tv = t[tri]
    mask = (tv != e[:, :1]) & (tv != e[:, 1:])
    return tv[mask]


def mesh_springs(vertices, triangles, total_mass: float, masses: str = "area",
                 name: str = "mesh") -> MeshSprings:
    """Structural, shear and bending spring pairs of a valid mesh, and point masses summing to
    total_mass (kg): by incident area (m_i = sum_t (total/A) A_t / 3) or uniform."""
    x, t = validate(vertices, triangles, name)
    total_mass = require_positive(name, "total_mass", total_mass, "kg")
    if masses not in MASS_MODES:
        raise ParameterError(f"{name}: unknown mass distribution {masses!r}; choose one of "
                             f"{', '.join(MASS_MODES)}")
    used = np.zeros(len(x), dtype=bool)
    used[t.ravel()] = True
    if not used.all():
        raise ParameterError(f"{name}: vertex {int(np.argmin(used))} belongs to no triangle; "
                             "remove unused vertices")
    e, counts, pair = edges(t)
    inner = np.flatnonzero(counts == 2)
    ea, eb = pair[inner, 0], pair[inner, 1]
    cross = np.stack([_opposite(t, ea, e[inner]), _opposite(t, eb, e[inner])], axis=1)
    # an edge is a quad diagonal when it is the longest edge of both its triangles
    elen = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
    longest = np.max([np.linalg.norm(x[t[:, a]] - x[t[:, b]], axis=1)
                      for a, b in ((0, 1), (1, 2), (2, 0))], axis=0)
    diag = (elen[inner] >= longest[ea] * (1 - 1e-9)) & (elen[inner] >= longest[eb] * (1 - 1e-9))
    pairs = np.concatenate([e, cross])
    kind = np.concatenate([np.zeros(len(e), np.int64), np.where(diag, 1, 2)])
    # two triangles may share an edge and also their opposite vertices' edge (a folded pair):
    # keep one spring per vertex pair, the structural one first
    _, keep = np.unique(np.sort(pairs, axis=1), axis=0, return_index=True)
    keep.sort()
    if masses == "area":
        area = triangle_areas(x, t)
        m = np.zeros(len(x))
        np.add.at(m, t.ravel(), np.repeat(area / 3.0, 3))
        m *= total_mass / area.sum()
    else:
        m = np.full(len(x), total_mass / len(x))
    return MeshSprings(pairs[keep], kind[keep], m)


def spring_stiffness(x, pairs, kind, stretch: float, shear: float, bend: float) -> np.ndarray:
    """k = ratio / rest length (N/m) with the stress/strain ratio (N) of each spring's kind."""
    ratio = np.array([require_positive("mesh springs", "stretch", stretch, "N"),
                      require_positive("mesh springs", "shear", shear, "N"),
                      require_positive("mesh springs", "bend", bend, "N")])[kind]
    return ratio / np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
