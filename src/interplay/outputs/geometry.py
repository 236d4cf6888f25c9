"""Geometry the outputs share: vertex normals, a height field's wet surface, the separate
pieces of a mesh (each leaf), cords as chains (one polyline per cord), planar UVs, rotations.
"""
from __future__ import annotations

import numpy as np

from ..systems.shape import DRY

WATER_LOWER = 4e-3  # m: a dry column's water surface is drawn this far under its bed
WATER_DEPTH = 0.08  # m: water this deep lets through 1/e of the light from its bed


def vertex_normals(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals (n,3) of a triangle mesh, float32 (smooth shading;
    bincount: no Python loop)."""
    p = np.asarray(points, dtype=np.float64)
    tris = np.asarray(tris)
    fn = np.cross(p[tris[:, 1]] - p[tris[:, 0]], p[tris[:, 2]] - p[tris[:, 0]])
    idx = tris.reshape(-1)
    n = np.stack([np.bincount(idx, np.repeat(fn[:, k], 3), minlength=len(p))
                  for k in range(3)], axis=1)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return (n / np.where(length > 0, length, 1.0)).astype(np.float32)


def wet_surface(shape, points):
    """A height field's drawn points (n,3): dry columns (within DRY of their bed) just under
    their bed, so the bed cuts a smooth waterline; per-point opacity (n,) (shallow water shows
    its bed: 1 - exp(-depth / WATER_DEPTH), bounded); and a mask of the triangles with at
    least one wet corner (the others hold no water and are not drawn)."""
    depth = points[:, 2] - shape.base
    wet = depth > DRY
    p = points.copy()
    p[~wet, 2] = shape.base[~wet] - WATER_LOWER
    alpha = shape.look.opacity * (1.0 - np.exp(-np.maximum(depth, 0.0) / WATER_DEPTH))
    return p, np.clip(alpha, 0.12, 0.92), wet[shape.triangles].any(axis=1)


def pieces(tris: np.ndarray, n: int) -> list:
    """The connected pieces of a mesh over n points: [(point indices, triangles renumbered
    to them)], in order of their first point (a network of leaves: one per leaf)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    t = np.asarray(tris)
    a = coo_matrix((np.ones(2 * len(t)), (np.r_[t[:, 0], t[:, 1]], np.r_[t[:, 1], t[:, 2]])),
                   shape=(n, n))
    _, label = connected_components(a, directed=False)
    used = np.zeros(n, dtype=bool)
    used[t.ravel()] = True
    groups = np.unique(label[used])  # points in no triangle form no piece
    if len(groups) == 1:
        return [(np.arange(n), t)]
    out = []
    for k in groups:
        idx = np.flatnonzero((label == k) & used)
        local = np.full(n, -1)
        local[idx] = np.arange(len(idx))
        out.append((idx, local[t[label[t[:, 0]] == k]]))
    return out


def chains(segments: np.ndarray, points: np.ndarray) -> list:
    """Cords as polylines: lists of point indices, each segment in exactly one. A point
    between two segments passes the cord on; at a knot the incident segments are paired
    straightest-first (the cord goes on through it: a net's strands run through its knots);
    a segment left unpaired ends its chain there. points
    (n,3): the pose the pairing is judged in (the first frame)."""
    seg = np.asarray(segments, dtype=np.int64)
    p = np.asarray(points, dtype=float)
    incident: dict = {}
    for s, (a, b) in enumerate(seg):
        incident.setdefault(a, []).append(s)
        incident.setdefault(b, []).append(s)
    follow = {}  # (segment, knot) -> the segment the cord continues on through the knot
    for knot, ss in incident.items():
        if len(ss) < 2:
            continue
        out = []
        for s in ss:
            other = seg[s, 1] if seg[s, 0] == knot else seg[s, 0]
            d = p[other] - p[knot]
            out.append(d / max(np.linalg.norm(d), 1e-12))
        pairs = sorted((float(out[i] @ out[j]), i, j) for i in range(len(ss))
                       for j in range(i + 1, len(ss)))
        used = set()
        for cos, i, j in pairs:  # most opposite directions first: the straightest pass
            # a point on one cord only (two segments) always passes it on; at a knot a cord
            # goes on only where the two segments point apart
            if i not in used and j not in used and (cos < 0.0 or len(ss) == 2):
                used |= {i, j}
                follow[(ss[i], knot)] = ss[j]
                follow[(ss[j], knot)] = ss[i]
    done = np.zeros(len(seg), dtype=bool)
    result = []

    def walk(s, knot):
        """Indices from the far end of s through knot onwards, marking segments done."""
        line = []
        while True:
            done[s] = True
            line.append(int(knot))
            nxt = follow.get((s, knot))
            if nxt is None or done[nxt]:
                return line
            s = nxt
            knot = seg[s, 1] if seg[s, 0] == knot else seg[s, 0]

    for s in range(len(seg)):
        if done[s]:
            continue
        a, b = seg[s]
        forward = walk(s, b)
        done[s] = False
        backward = walk(s, a)
        if forward[-1] == a and len(forward) > 1:  # a closed loop came round
            result.append([int(a)] + forward)
        else:
            result.append(backward[::-1] + forward)
    return result


def planar_uv(points: np.ndarray) -> np.ndarray:
    """(n,2) texture coordinates 0..1 of a nearly flat piece (a flag, a leaf) in its own
    principal plane (its longest extent along u), from its rest pose."""
    p = np.asarray(points, float)
    c = p - p.mean(axis=0)
    _, _, vt = np.linalg.svd(c, full_matrices=False)
    uv = c @ vt[:2].T
    lo, span = uv.min(axis=0), np.ptp(uv, axis=0)
    return (uv - lo) / np.where(span > 0, span, 1.0)


def quat_mul(a, b) -> np.ndarray:
    """Hamilton products of quaternions (..., 4) w, x, y, z."""
    aw, ax, ay, az = np.moveaxis(np.asarray(a, float), -1, 0)
    bw, bx, by, bz = np.moveaxis(np.asarray(b, float), -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw],
                    axis=-1)


def quat_rotate(q, v) -> np.ndarray:
    """Vectors v (..., 3) rotated by unit quaternions q (..., 4)."""
    qv = np.concatenate([np.zeros(np.shape(v)[:-1] + (1,)), v], axis=-1)
    conj = np.asarray(q, float) * [1.0, -1.0, -1.0, -1.0]
    return quat_mul(quat_mul(q, qv), conj)[..., 1:]


def local_poses(pos, quat, parents):
    """Each part's pose relative to its parent's: pos (f,k,3) m and unit quaternions (f,k,4)
    in the world, parents (k,) (-1: the root, whose pose stays the world's)."""
    lp, lq = np.array(pos, float), np.array(quat, float)
    for k, par in enumerate(parents):
        if par >= 0:
            inv = quat[:, par] * [1.0, -1.0, -1.0, -1.0]
            lp[:, k] = quat_rotate(inv, pos[:, k] - pos[:, par])
            lq[:, k] = quat_mul(inv, quat[:, k])
    return lp, lq


def quat_matrix(q) -> np.ndarray:
    """Rotation matrix (3,3) of a unit quaternion (w,x,y,z)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def coarser_height_field(shape, stride: int):
    """(point indices, Shape) of a height field drawn at every stride-th column each way (the
    outer ones kept): its faces over the squares whose four corners hold fluid."""
    from dataclasses import replace
    xs, ys = np.unique(shape.grid_xy[:, 0]), np.unique(shape.grid_xy[:, 1])
    nx, ny = len(xs), len(ys)
    ix = np.unique(np.r_[np.arange(0, nx, stride), nx - 1])
    iy = np.unique(np.r_[np.arange(0, ny, stride), ny - 1])
    sub = (ix[:, None] * ny + iy[None, :]).ravel()  # grid_xy rows run j fastest
    fluid = np.zeros(nx * ny, dtype=bool)
    fluid[shape.triangles.ravel()] = True
    f = fluid[sub].reshape(len(ix), len(iy))
    idx = np.arange(len(sub)).reshape(len(ix), len(iy))
    ok = (f[:-1, :-1] & f[1:, :-1] & f[:-1, 1:] & f[1:, 1:]).ravel()
    a, b = idx[:-1, :-1].ravel()[ok], idx[1:, :-1].ravel()[ok]
    c, d = idx[1:, 1:].ravel()[ok], idx[:-1, 1:].ravel()[ok]
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return sub, replace(shape, triangles=tris, grid_xy=shape.grid_xy[sub], base=shape.base[sub])
