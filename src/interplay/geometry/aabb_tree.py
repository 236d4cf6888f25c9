"""Bounding-volume hierarchies of triangle (or segment) sets: build once, refit deforming
objects, transform rigid ones, and query (SPEC 2.5 detection; kernels in kernels/aabb_tree.py).

Not to be confused with io/motion_file.py, the BVH (Biovision Hierarchy) motion-capture reader.
"""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..kernels import aabb_tree as K
from ..kernels.trimesh_contact import edge_pairs_within, intersecting_pairs


def check_points(owner: str, x, what: str = "positions") -> np.ndarray:
    """x as a float (n,3) array, or ParameterError naming the first non-finite point."""
    x = np.ascontiguousarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ParameterError(f"{owner}: {what} must be an (n,3) array, got shape {x.shape}")
    bad = np.flatnonzero(~np.all(np.isfinite(x), axis=1))
    if len(bad):
        raise ParameterError(f"{owner}: {what} of point {bad[0]} is not finite ({x[bad[0]]}); "
                             "the simulation blew up or the input is broken: fix the input or "
                             "reduce the step")
    return x


def check_thickness(owner: str, thickness) -> float:
    t = float(thickness)
    if not (t >= 0.0) or not np.isfinite(t):
        raise ParameterError(f"{owner}: contact thickness must be zero or positive (m), got "
                             f"{thickness!r}; use e.g. 0.005 for cloth")
    return t


class AABBTree:
    """A hierarchy over elements (rows of vertex indices: (m,3) triangles or (m,2) segments)
    of a vertex set (n,3) m. Boxes are grown by ``pad`` (m) and span the motion of the step."""

    def __init__(self, vertices, elements, owner: str = "mesh", pad: float = 0.0):
        self.owner = owner
        x = check_points(owner, vertices, "vertices")
        e = np.ascontiguousarray(elements, dtype=np.int64)
        if e.ndim != 2 or e.shape[0] == 0 or e.shape[1] not in (1, 2, 3):
            raise ParameterError(f"{owner}: a collision mesh needs at least one triangle or "
                                 f"segment, got elements of shape {e.shape}; give the object a "
                                 "surface or leave it out of collisions")
        if e.min() < 0 or e.max() >= len(x):
            raise ParameterError(f"{owner}: element indices must be in 0..{len(x) - 1}, got "
                                 f"{e.min()}..{e.max()}")
        self.elements = e
        self.pad = check_thickness(owner, pad)
        self.left, self.right, self.prim = K.build(x, e)
        nn = len(self.prim)
        self.lo, self.hi = np.zeros((nn, 3)), np.zeros((nn, 3))
        self.tree = K.Tree(self.lo, self.hi, self.left, self.right, self.prim)
        self.x = x
        self.refit(x)
        # each node's parent and each element's leaf, for refitting a few elements
        self.parent = np.full(nn, -1, np.int64)
        inner = np.flatnonzero(self.prim < 0)
        self.parent[self.left[inner]] = inner
        self.parent[self.right[inner]] = inner
        self.leaf = np.empty(len(e), np.int64)
        self.leaf[self.prim[self.prim >= 0]] = np.flatnonzero(self.prim >= 0)
        # body-frame boxes, kept so a rigid object's tree is transformed, never rebuilt
        self.lo0, self.hi0 = self.lo.copy(), self.hi.copy()
        self.body_x = x.copy()

    def refit(self, x, x_end=None):
        """Refit every box to vertices x (and x_end, the positions at the end of the step)."""
        self.x = check_points(self.owner, x)
        x1 = self.x if x_end is None else check_points(self.owner, x_end)
        fit = K.refit if len(self.elements) >= K.PARALLEL_LEAVES else K.refit_serial
        fit(self.tree, self.elements, self.x, x1, self.pad)

    def refit_some(self, x, elements) -> None:
        """Refit the boxes of the elements (k,) int alone to vertices x, the others' vertices
        unmoved since the last refit, which was at one position (no x_end)."""
        some = np.ascontiguousarray(elements, np.int64)
        check_points(self.owner, x[self.elements[some].ravel()])
        self.x = x
        K.refit_some(self.tree, self.elements, x, self.pad, self.parent, self.leaf, some)

    def transform(self, R, t, R_end=None, t_end=None):
        """Rigid motion: world boxes from the body-frame boxes at pose (R, t) (and the pose at
        the end of the step); ``self.x`` becomes the world vertices at (R, t)."""
        R = np.ascontiguousarray(R, dtype=float)
        t = np.ascontiguousarray(t, dtype=float)
        R1 = R if R_end is None else np.ascontiguousarray(R_end, dtype=float)
        t1 = t if t_end is None else np.ascontiguousarray(t_end, dtype=float)
        K.transform_boxes(self.lo0, self.hi0, R, t, R1, t1, 0.0, self.lo, self.hi)
        self.x = self.body_x @ R.T + t

    def nearest(self, points, radius: float, skip_incident: bool = False, hint=None):
        """For each point (n,3): nearest triangle within radius (m) of it (-1 if none), the
        distance (m) and the barycentric weights of the closest point. hint (n,) int: each
        point's answer at the last query (or -1), to search from: the same answer, faster when
        the points moved little."""
        if self.elements.shape[1] != 3:
            raise ParameterError(f"{self.owner}: nearest-triangle queries need triangles")
        p = check_points(self.owner, points, "query points")
        n = len(p)
        tri, d, bary = np.empty(n, np.int64), np.empty(n), np.empty((n, 3))
        hint = (np.full(n, -1, np.int64) if hint is None
                else np.ascontiguousarray(hint, np.int64))
        if hint.shape != (n,) or hint.max(initial=-1) >= len(self.elements):
            raise ParameterError(f"{self.owner}: a nearest-triangle hint must be one triangle "
                                 f"index (or -1) per query point, below {len(self.elements)}")
        K.nearest_triangles(p, float(radius), self.tree, self.elements, self.x, skip_incident,
                            hint, tri, d, bary)
        return tri, d, bary

    def overlapping(self, other: "AABBTree | None" = None) -> np.ndarray:
        """(k,2) element pairs whose boxes overlap: this tree against another, or against itself
        (each unordered pair once) when other is None."""
        o = self if other is None else other
        out = np.empty((max(64, 4 * len(self.elements)), 2), np.int64)
        while True:
            n = K.overlap_pairs(self.tree, o.tree, other is None, out)
            if n <= len(out):
                return out[:n].copy()
            out = np.empty((n, 2), np.int64)

    def intersections(self, other: "AABBTree | None" = None) -> np.ndarray:
        """(k,2) pairs of triangles that interpenetrate: of this mesh and another, or of this
        mesh with itself (``crossings``) when other is None."""
        if other is None:
            return self.crossings()
        pairs = self.overlapping(other)
        hit = np.zeros(len(pairs), np.bool_)
        intersecting_pairs(self.x, self.elements, other.x, other.elements, pairs, hit)
        return pairs[hit]

    def crossings(self, subset=None) -> np.ndarray:
        """The mesh's self-intersections (triangles sharing a corner apart): (k,2) pairs,
        each once, the smaller triangle first, sorted. subset (k,) int: only the pairs with a
        triangle in it (what moved since the pairs were last found). Each triangle against
        the tree, in parallel (all of them: 7 ms for the runner's 18,600 garment triangles,
        21 ms by the boxes' overlap and a filter)."""
        x, tris = self.x, self.elements
        rows = np.arange(len(tris)) if subset is None else np.ascontiguousarray(subset, np.int64)
        width = 16  # partners per triangle written; more: looked at again wider
        while True:
            out, count = np.empty((len(rows), width), np.int64), np.empty(len(rows), np.int64)
            if subset is None:
                K.crossings_all(x, tris, self.tree, out, count)
            else:
                K.crossings_of(x, tris, self.tree, rows, out, count)
            if count.max(initial=0) <= width:
                break
            width = int(count.max())
        on = np.arange(width) < count[:, None]
        pairs = np.column_stack([rows[np.nonzero(on)[0]], out[on]])
        return np.unique(np.sort(pairs, axis=1), axis=0).reshape(-1, 2)

    def edge_contacts(self, other: "AABBTree", reach: float):
        """Segment pairs of two segment trees closer than reach (m): (pairs (k,2), closest-point
        parameters (k,2), distances (k,))."""
        pairs = self.overlapping(other)
        st, d = np.empty((len(pairs), 2)), np.empty(len(pairs))
        edge_pairs_within(self.x, self.elements, other.x, other.elements, pairs, float(reach),
                          st, d)
        keep = np.isfinite(d)
        return pairs[keep], st[keep], d[keep]
