"""Rigid impact zones: the fail-safe that keeps a cloth from crossing itself (Provot 1997,
"Collision and self-collision handling in cloth model dedicated to design garments";
Bridson, Fedkiw & Anderson 2002, "Robust treatment of collisions, contact and friction for
cloth animation", section 7.4). The points of the triangles that came to cross over a step
are gathered into zones (two crossing triangles' corners in one zone; zones that share a
point merge), and each zone moves over the step as one rigid body: the rotation and
translation that best fit its points' own moves (mass-weighted, Kabsch), applied to where
they were at the step's start. A rigid motion keeps the zone's own triangles as they were,
and a zone that still crosses grows, so the loop ends with no new crossing: at worst the
whole cloth moves rigidly from its start.

Notation (SI): points at the step's start x0 (n,3) m and now x (n,3) m, masses m (n,) kg,
fixed (n,) bool (points that ride the skin: they keep their place and the zone's fit);
triangles tris (m,3); label (n,) int64: each point's zone as a union-find parent (-1: none).
"""
import numpy as np
from numba import njit, prange

from .aabb_tree import STACK
from .trimesh_contact import triangles_intersect


@njit(cache=True)
def _root(label, i):
    while label[i] != i:
        label[i] = label[label[i]]  # path halving
        i = label[i]
    return i


@njit(cache=True)
def merge(tris, pairs, label):
    """Put the corners of each crossing triangle pair (pairs (k,2)) in one zone, merging the
    zones they are in already."""
    for j in range(pairs.shape[0]):
        first = tris[pairs[j, 0], 0]
        if label[first] < 0:
            label[first] = first
        for o in range(2):
            for r in range(3):
                c = tris[pairs[j, o], r]
                if label[c] < 0:
                    label[c] = c
                a, b = _root(label, first), _root(label, c)
                if a != b:
                    label[b] = a


@njit(cache=True)
def move_rigidly(x0, x, m, fixed, label):
    """Move each zone's free points by the zone's best rigid fit of x0 -> x (fixed points
    stay and count in the fit). Returns the number of zones."""
    members = np.flatnonzero(label >= 0)
    root = np.empty(members.shape[0], np.int64)
    for q in range(members.shape[0]):
        root[q] = _root(label, members[q])
    order = members[np.argsort(root, kind="mergesort")]  # stable: the fit sums in one order
    root = np.sort(root)
    n = members.shape[0]
    k = 0
    zones = 0
    while k < n:
        r = root[k]
        e = k
        while e < n and root[e] == r:
            e += 1
        zones += 1
        mass = 0.0
        c0 = np.zeros(3)
        c1 = np.zeros(3)
        for q in range(k, e):
            i = order[q]
            mass += m[i]
            c0 += m[i] * x0[i]
            c1 += m[i] * x[i]
        c0 /= mass
        c1 /= mass
        H = np.zeros((3, 3))
        for q in range(k, e):
            i = order[q]
            H += m[i] * np.outer(x0[i] - c0, x[i] - c1)
        U, s, Vt = np.linalg.svd(H)
        R = Vt.T @ U.T
        if np.linalg.det(R) < 0.0:  # a reflection fits a flat zone as well: not a motion
            Vt[2] = -Vt[2]
            R = Vt.T @ U.T
        for q in range(k, e):
            i = order[q]
            if not fixed[i]:
                x[i] = R @ (x0[i] - c0) + c1
        k = e
    return zones


@njit(cache=True, inline="always")
def _crossings_one(x, tris, tree, e, later, st, out, row, cap):
    """The triangles crossing triangle e (those after it only, if ``later``), written to
    out[row, :cap]; returns their count (may exceed cap)."""
    lo, hi, left, right, prim = tree
    a, b, c = tris[e, 0], tris[e, 1], tris[e, 2]
    blo0 = min(x[a, 0], x[b, 0], x[c, 0])
    blo1 = min(x[a, 1], x[b, 1], x[c, 1])
    blo2 = min(x[a, 2], x[b, 2], x[c, 2])
    bhi0 = max(x[a, 0], x[b, 0], x[c, 0])
    bhi1 = max(x[a, 1], x[b, 1], x[c, 1])
    bhi2 = max(x[a, 2], x[b, 2], x[c, 2])
    n = 0
    st[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = st[top]
        if (lo[node, 0] > bhi0 or blo0 > hi[node, 0] or lo[node, 1] > bhi1
                or blo1 > hi[node, 1] or lo[node, 2] > bhi2 or blo2 > hi[node, 2]):
            continue
        f = prim[node]
        if f < 0:
            st[top] = left[node]
            st[top + 1] = right[node]
            top += 2
            continue
        if later and f <= e:
            continue
        p, q, w = tris[f, 0], tris[f, 1], tris[f, 2]
        if p == a or p == b or p == c or q == a or q == b or q == c or w == a or w == b \
                or w == c:
            continue
        if triangles_intersect(x[a], x[b], x[c], x[p], x[q], x[w]):
            if n < cap:
                out[row, n] = f
            n += 1
    return n


@njit(cache=True)
def crossings_of(x, tris, tree, subset, out):
    """The triangle pairs (i, j) that cross, for each triangle i of ``subset`` against every
    triangle j of the mesh sharing no corner with it (the tree refit to x): what moved since
    the last look is all that can have come to cross. Writes up to len(out) pairs (k,2) and
    returns the count (call again with a larger out when it exceeds it); a pair with both
    triangles in the subset comes twice."""
    st = np.empty(STACK, np.int64)
    row = np.empty((1, 64), np.int64)
    cap = out.shape[0]
    n = 0
    for s in range(subset.shape[0]):
        e = subset[s]
        k = _crossings_one(x, tris, tree, e, False, st, row, 0, row.shape[1])
        if k > row.shape[1]:  # a tangle: a wider row, and that triangle again
            row = np.empty((1, k), np.int64)
            k = _crossings_one(x, tris, tree, e, False, st, row, 0, k)
        for j in range(k):
            if n < cap:
                out[n, 0], out[n, 1] = e, row[0, j]
            n += 1
    return n


@njit(cache=True, parallel=True)
def crossings_all(x, tris, tree, out, count):
    """Every crossing triangle pair of the mesh (no shared corner), each once: for each
    triangle e the crossing triangles after it in out[e, :] (count[e] of them; more than
    out's width are counted, not written). Parallel over the triangles: the guard's full
    look, 2x the serial one when the other core is free."""
    for e in prange(tris.shape[0]):
        st = np.empty(STACK, np.int64)
        count[e] = _crossings_one(x, tris, tree, e, True, st, out, e, out.shape[1])
