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
from numba import njit


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
