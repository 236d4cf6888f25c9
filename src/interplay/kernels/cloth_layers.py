"""A garment's layers kept apart at the position level: point-triangle pairs of one cloth mesh
(several garments joined into one) are found at the step's start and each point is held on
its side of each triangle, ``thickness`` off it, at the step's end (position-based dynamics,
Mueller et al. 2007; the side remembered from the step's start, as in Bridson, Fedkiw &
Anderson 2002, "Robust treatment of collisions, contact and friction for cloth animation").

Which side is a point's is decided at the step's start, by the body where it can be: for two
garments worn one over the other (``layer``: the order they were put on) the outer garment's
point lies farther out along the skin's outward normal than the inner garment's triangle,
whatever side it was on (a tee's hem that lies inside the pants is moved out); for one
garment's cloth cut over two limbs (a pants leg against the other, a sleeve against the tee's
side) the point lies between its own limb and the triangle, told by the skin nearest the
point, which may be either limb's; otherwise (a fold over one limb) by the side the point is
on, unless the point has gone through the triangle (``untangle``: then the side it came
from). Moves are capped per pass (``step``), so a deep crossing is undone over a few steps
rather than by a kick.

Notation (SI): points x (n,3) m, velocities v (n,3) m/s, inverse masses w (n,) 1/kg (0:
fixed); triangles tris (m,3); each point's candidate triangles ``tri`` (n,K) (-1: none) and
the side ``side`` (n,K) (+1: along the triangle's normal (b - a) x (c - a), -1: against it).
A point's neighbourhood as compressed rows (start (n+1,), nbr): a gathered triangle never has
a corner in it (the cloth's own curvature there is the bending springs' business); a crossed
one may. ``forced`` (n,K): a side untangle chose (+-1), IGNORE, or 0 (none).
"""
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from .aabb_tree import STACK, _box_dist2
from .skin_contact import _face_normal
from .trimesh_contact import _edge_hits, _orient, closest_on_triangle


#: ``forced``'s mark for a pair whose side is no guide (untangle): held neither way
IGNORE = 2.0


class Mesh(NamedTuple):
    """The cloth's triangles (m,3), its points' neighbourhoods (start (n+1,), nbr: the
    points within two edges, itself included), layer (n,) int64 (the garments' order,
    innermost 0) and limb (n,) int64 (the limb each point was cut over, -1: none)."""
    tris: np.ndarray
    start: np.ndarray
    nbr: np.ndarray
    layer: np.ndarray
    limb: np.ndarray


class Body(NamedTuple):
    """The skin's outward normal (n,3) at each point's nearest skin point and the limb
    (n,) int64 that skin point belongs to (-1: none found near)."""
    nrm: np.ndarray
    limb: np.ndarray


@njit(cache=True, inline="always")
def _gather_one(x, i, radius, tree, mesh, out_tri, st, best, near):
    """Point i's row of ``gather``."""
    K = out_tri.shape[1]
    lo, hi, left, right, prim = tree
    for k in range(K):
        out_tri[i, k] = -1
        best[k] = radius * radius
    for k in range(mesh.start[i], mesh.start[i + 1]):
        near[mesh.nbr[k]] = True
    p = x[i]
    st[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = st[top]
        if _box_dist2(p, lo, hi, node) > best[K - 1]:
            continue
        e = prim[node]
        if e < 0:
            st[top] = left[node]
            st[top + 1] = right[node]
            top += 2
            continue
        ia, ib, ic = mesh.tris[e, 0], mesh.tris[e, 1], mesh.tris[e, 2]
        if near[ia] or near[ib] or near[ic]:
            continue
        u, v, w, d2 = closest_on_triangle(p, x[ia], x[ib], x[ic])
        if d2 >= best[K - 1]:
            continue
        k = K - 1
        while k > 0 and best[k - 1] > d2:
            best[k] = best[k - 1]
            out_tri[i, k] = out_tri[i, k - 1]
            k -= 1
        best[k] = d2
        out_tri[i, k] = e
    for k in range(mesh.start[i], mesh.start[i + 1]):
        near[mesh.nbr[k]] = False


@njit(cache=True, parallel=True)
def gather(x, radius, tree, mesh, out_tri):
    """For each point, its K (out_tri's columns) nearest triangles within ``radius`` (m) with
    no corner in its neighbourhood, nearest first (-1: none). In parallel over chunks of
    points, each with its own scratch (race-free: a point writes only its own row)."""
    n = x.shape[0]
    chunk = 256  # points per task, sharing one scratch stack and mark array
    for c in prange((n + chunk - 1) // chunk):
        st = np.empty(STACK, np.int64)
        best = np.empty(out_tri.shape[1])
        near = np.zeros(n, np.bool_)  # the point's neighbourhood, marked while it is queried
        for i in range(c * chunk, min(n, (c + 1) * chunk)):
            _gather_one(x, i, radius, tree, mesh, out_tri, st, best, near)


@njit(cache=True)
def sides(x, mesh, body, tri, forced, out_side):
    """The side (+1, -1) each point is to stay on of each of its triangles ``tri`` (n,K)
    (see the module docstring); ``forced`` (n,K): where the body cannot tell, the side
    ``untangle`` found for a point that has crossed its triangle (0: none)."""
    n, K = tri.shape
    for i in range(n):
        p = x[i]
        for k in range(K):
            e = tri[i, k]
            if e < 0:
                continue
            ia, ib, ic = mesh.tris[e, 0], mesh.tris[e, 1], mesh.tris[e, 2]
            u, v, w, d2 = closest_on_triangle(p, x[ia], x[ib], x[ic])
            n0, n1, n2 = _face_normal(x, mesh.tris, e)
            li, lt = mesh.layer[i], mesh.layer[ia]
            ci, ct = mesh.limb[i], mesh.limb[ia]
            b = body.limb[i]
            up = n0 * body.nrm[i, 0] + n1 * body.nrm[i, 1] + n2 * body.nrm[i, 2]
            outward = 1.0 if up >= 0.0 else -1.0
            if b >= 0 and li != lt:
                # worn one over the other: the outer garment's point lies outside the
                # inner one's triangle along the skin's normal
                out_side[i, k] = outward * (1.0 if li > lt else -1.0)
            elif b >= 0 and ci != ct and (b == ci or b == ct):
                # one garment's cloth over two limbs (a pants leg against the other, a
                # sleeve against the side): going out from a limb's skin its own cloth
                # comes first, whichever of the two the point is nearest
                out_side[i, k] = -outward if b == ci else outward
            elif forced[i, k] == IGNORE:
                out_side[i, k] = 0.0
            elif forced[i, k] != 0.0:
                out_side[i, k] = forced[i, k]
            else:
                s = (n0 * (p[0] - u * x[ia, 0] - v * x[ib, 0] - w * x[ic, 0])
                     + n1 * (p[1] - u * x[ia, 1] - v * x[ib, 1] - w * x[ic, 1])
                     + n2 * (p[2] - u * x[ia, 2] - v * x[ib, 2] - w * x[ic, 2]))
                out_side[i, k] = 1.0 if s >= 0.0 else -1.0


@njit(cache=True)
def project(x, v, w, mesh, tri, side, forced, thickness, margin, step, passes, h):
    """Hold every point on its side of its candidate triangles, ``thickness`` (m) off their
    planes, in up to ``passes`` Gauss-Seidel passes; a crossed pair (``forced`` +-1: see
    ``untangle``) only ``margin`` (m) through. A pair acts while the point lies over its
    triangle (its closest point's offset within the triangle's plane is under
    ``thickness``), a crossed pair wherever the point is: its edge through the triangle may
    pass near the rim while the point itself lies beside it, and once the point is on the
    plane's other side that edge no longer crosses. A pair marked IGNORE (side 0) does not
    act. Each correction is split over the point and the triangle's corners by inverse mass
    and barycentric weight (momentum kept) and capped at ``step`` (m). The velocities change
    by the moves over the step h (s)."""
    x0 = x.copy()
    n, K = tri.shape
    for _ in range(passes):
        count = 0
        for i in range(n):
            for k in range(K):
                e = tri[i, k]
                if e < 0:
                    break
                a, b, c = mesh.tris[e, 0], mesh.tris[e, 1], mesh.tris[e, 2]
                u, vv, ww, d2 = closest_on_triangle(x[i], x[a], x[b], x[c])
                n0, n1, n2 = _face_normal(x, mesh.tris, e)
                d0 = x[i, 0] - u * x[a, 0] - vv * x[b, 0] - ww * x[c, 0]
                d1 = x[i, 1] - u * x[a, 1] - vv * x[b, 1] - ww * x[c, 1]
                d2_ = x[i, 2] - u * x[a, 2] - vv * x[b, 2] - ww * x[c, 2]
                s = n0 * d0 + n1 * d1 + n2 * d2_
                sg = side[i, k]
                if sg == 0.0:
                    continue
                crossed = sg == forced[i, k]  # a side untangle chose (not the body's rule)
                if d2 - s * s > thickness * thickness and not crossed:
                    continue  # beside the triangle, not over it
                gap = (margin if crossed else thickness) - sg * s
                if gap <= 0.0:
                    continue
                den = w[i] + u * u * w[a] + vv * vv * w[b] + ww * ww * w[c]
                if den == 0.0:
                    continue
                lam = min(gap, step) / den
                count += 1
                for r in range(3):
                    dr = sg * lam * (n0 if r == 0 else (n1 if r == 1 else n2))
                    x[i, r] += w[i] * dr
                    x[a, r] -= w[a] * u * dr
                    x[b, r] -= w[b] * vv * dr
                    x[c, r] -= w[c] * ww * dr
        if count == 0:
            break
    for p in range(n):
        if w[p] > 0.0:
            for r in range(3):
                v[p, r] += (x[p, r] - x0[p, r]) / h


@njit(cache=True)
def untangle(x, mesh, pairs, tri, forced):
    """The sides that undo crossings: ``pairs`` (k,2) are the garments' triangle pairs that
    intersect (no shared corner). Each edge of one that passes through the other has one end
    on the wrong side of it: the end nearer its plane (a crossing is made by a point slipping
    a little way through between two gatherings, so the shallow end is the one that went
    through; a local version of Baraff, Witkin & Kass 2003, "Untangling cloth", which flood
    fills the region inside each intersection curve). That end gets the triangle as a
    candidate (in place of its farthest one without a forced side) and, in ``forced``, the
    side of the edge's other end (+1 along the triangle's normal), even where the triangle
    has a corner within two edges of it (which ``gather`` leaves out: 98% of the runner's
    crossings were such tight folds). A corner of a crossed triangle keeps no remembered
    side of another crossed triangle (IGNORE): the side it is on there is the crossed one.
    ``forced`` is cleared first."""
    forced[:] = 0.0
    K = tri.shape[1]
    for j in range(pairs.shape[0]):
        for o in range(2):
            ea, eb = pairs[j, o], pairs[j, 1 - o]
            a, b, c = mesh.tris[eb, 0], mesh.tris[eb, 1], mesh.tris[eb, 2]
            for r in range(3):
                p, q = mesh.tris[ea, r], mesh.tris[ea, (r + 1) % 3]
                if not _edge_hits(x[p], x[q], x[a], x[b], x[c]):
                    continue
                op, oq = _orient(x[a], x[b], x[c], x[p]), _orient(x[a], x[b], x[c], x[q])
                end, other = (p, oq) if abs(op) < abs(oq) else (q, op)
                if other == 0.0:
                    continue
                slot = -1
                for k in range(K):
                    if tri[end, k] == eb:
                        slot = k
                if slot < 0:  # the first empty slot (the candidates stay contiguous)
                    for k in range(K):
                        if tri[end, k] < 0:
                            slot = k
                            break
                if slot < 0:  # else the farthest candidate without a forced side
                    for k in range(K - 1, -1, -1):
                        if forced[end, k] == 0.0:
                            slot = k
                            break
                if slot < 0:
                    continue
                tri[end, slot] = eb
                forced[end, slot] = 1.0 if other > 0.0 else -1.0
    # the side a point is on of a crossed triangle is no guide near the crossing: a corner
    # of a crossed triangle holds no other side of one
    crossed = np.zeros(mesh.tris.shape[0], np.bool_)
    corner = np.zeros(x.shape[0], np.bool_)
    for j in range(pairs.shape[0]):
        for o in range(2):
            crossed[pairs[j, o]] = True
            for r in range(3):
                corner[mesh.tris[pairs[j, o], r]] = True
    for i in range(x.shape[0]):
        if corner[i]:
            for k in range(K):
                if tri[i, k] >= 0 and forced[i, k] == 0.0 and crossed[tri[i, k]]:
                    forced[i, k] = IGNORE
