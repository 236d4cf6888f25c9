"""Strain limiting of a spring network by iterative position correction (Provot 1995,
"Deformation constraints in a mass-spring model to describe rigid cloth behavior"): a spring
longer than its cap is shortened, its end points moving along it in proportion to their
inverse masses, as in position-based dynamics (Mueller et al. 2007), so that
m_a dx_a + m_b dx_b = 0: each correction keeps the network's linear momentum; a fixed point
(1/m = 0) does not move. Gauss-Seidel passes over the springs repeat until none is over its
cap. Each pass starts with the long range attachments (``Reach``: a point no farther from
its pin than its rest path allows), which carry a correction along a hanging garment at
once, and ends with the points near a body put back on the outer side of their contact
planes (half-spaces n . x >= o), so the limit cannot pull cloth into the body. Each
correction is over-relaxed (OVERRELAX): on the runner's garments that left fewer springs
over 5% at the same number of passes (docs/clothing.md).

Why not a global projection (Goldenthal et al. 2007, "Efficient simulation of inextensible
cloth": Newton steps on all the stretched springs at once): on a triangle mesh the springs
of a stretched patch outnumber its points' in-plane freedoms (E ~ 3V against 2V), the
projection's matrix J W J^T is then singular, and its linearised steps overshot by strains
of 4 to 100 on a hanging strip (tried; docs/clothing.md). A single spring's projection
cannot overshoot.

The garments of one network share no point, so each garment's passes run on their own, the
garments in parallel (a tee and sweat pants: 0.7x the time of one after the other on the
two cores): the springs, reaches and planes come grouped by garment (``starts``: each
garment's first entry, then the count).

Notation (SI): points x (n,3) m, velocities v (n,3) m/s, inverse masses w (n,) 1/kg (0:
fixed); Limits: the springs' end points i, j (s,) and caps (s,) m; Planes: points idx (k,),
unit normals n (k,3), offsets o (k,) m.
"""
from typing import NamedTuple

import numpy as np
from numba import njit, prange

#: a spring over its cap is shortened to (1 - UNDERSHOOT) of it: the passes then stop for
#: good once none is over, instead of creeping towards the cap from above
UNDERSHOOT = 1e-3
#: springs shorter than (1 - NEAR) of their caps at a full pass are left out of the passes
#: until the next full one
NEAR = 0.03
#: successive over-relaxation of each correction (1: exactly to the cap)
OVERRELAX = 1.5
#: a full pass over all springs every this many passes
REFRESH = 8


class Limits(NamedTuple):
    """The limited springs: end points i, j (s,) int64 and cap (s,) m, each spring's longest
    allowed length (l0 (1 + limit))."""
    i: np.ndarray
    j: np.ndarray
    cap: np.ndarray


class Reach(NamedTuple):
    """Each point idx (a,) stays within dist (a,) m of the fixed point pin (a,): its path's
    rest length through the cloth to its nearest fixed point, times 1 + the limit (the
    long range attachments of Kim, Chentanez & Mueller 2012). A network within its limits
    meets them all, so they never hold a valid state; they move a point pulled away from
    its pin back at once, where the springs' passes take one pass per spring on the way
    (and far more against a heavy load)."""
    idx: np.ndarray
    pin: np.ndarray
    dist: np.ndarray


class Planes(NamedTuple):
    """Half-spaces n . x >= o (m) that points idx (k,) must stay in (contact planes)."""
    idx: np.ndarray
    n: np.ndarray
    o: np.ndarray


def no_planes() -> Planes:
    return Planes(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0))


@njit(cache=True)
def _reach(x, w, reach):
    """Move every point of ``reach`` farther than its dist from its pin back onto that
    sphere (the pin is fixed: only the point moves; a held one, w = 0, does not)."""
    for k in range(reach.idx.shape[0]):
        p = reach.idx[k]
        if w[p] == 0.0:
            continue
        q = reach.pin[k]
        d0 = x[p, 0] - x[q, 0]
        d1 = x[p, 1] - x[q, 1]
        d2 = x[p, 2] - x[q, 2]
        ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if ln > reach.dist[k]:
            f = reach.dist[k] / ln
            x[p, 0] = x[q, 0] + f * d0
            x[p, 1] = x[q, 1] + f * d1
            x[p, 2] = x[q, 2] + f * d2


@njit(cache=True)
def _correct(x, w, lim, s):
    """Shorten spring s to (1 - UNDERSHOOT) of its cap if it is over the cap; returns its
    excess over the cap (a strain; <= 0 if none)."""
    a = lim.i[s]
    b = lim.j[s]
    wa = w[a]
    wb = w[b]
    d0 = x[a, 0] - x[b, 0]
    d1 = x[a, 1] - x[b, 1]
    d2 = x[a, 2] - x[b, 2]
    ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    c = lim.cap[s]
    e = ln / c - 1.0
    ws = wa + wb
    if e <= 0.0 or ws == 0.0:
        return e if ws > 0.0 else 0.0
    # shortening per unit inverse mass, over-relaxed (never by more than half the spring)
    f = min(OVERRELAX * (ln - c * (1.0 - UNDERSHOOT)), 0.5 * ln) / (ln * ws)
    x[a, 0] -= wa * f * d0
    x[a, 1] -= wa * f * d1
    x[a, 2] -= wa * f * d2
    x[b, 0] += wb * f * d0
    x[b, 1] += wb * f * d1
    x[b, 2] += wb * f * d2
    return e


@njit(cache=True)
def _keep_out(x, w, planes):
    """Move every plane's point back onto its half-space; returns how many moved."""
    moved = 0
    for k in range(planes.idx.shape[0]):
        p = planes.idx[k]
        if w[p] == 0.0:
            continue
        d = planes.n[k, 0] * x[p, 0] + planes.n[k, 1] * x[p, 1] + planes.n[k, 2] * x[p, 2]
        gap = planes.o[k] - d
        if gap > 0.0:
            for r in range(3):
                x[p, r] += gap * planes.n[k, r]
            moved += 1
    return moved


@njit(cache=True)
def _passes(x, w, lim, a, b, reach, planes, sweeps, near):
    """The passes over the springs a..b-1 of ``lim`` (one garment), its reach and planes:
    see ``limit_strain``; near: scratch for the springs' indices (its a..b-1 are used).
    Returns (passes taken, the largest excess over a cap the last pass found)."""
    m = 0
    worst = 0.0
    taken = 0
    since = REFRESH  # passes since the last full one: the first is full
    while taken < sweeps:
        full = since >= REFRESH
        worst = 0.0
        _reach(x, w, reach)
        if full:
            m = 0
            since = 0
        count = b - a if full else m
        for q in range(count):
            t = q if taken % 2 == 0 else count - 1 - q
            s = a + t if full else near[a + t]
            e = _correct(x, w, lim, s)
            if full and e > -NEAR:
                near[a + m] = s
                m += 1
            worst = max(worst, e)
        moved = _keep_out(x, w, planes)
        taken += 1
        since += 1
        if worst <= 0.0 and moved == 0:
            if full:
                break
            since = REFRESH  # the near springs are done: a full pass to confirm
    return taken, max(worst, 0.0)


@njit(cache=True, parallel=True)
def limit_strain(x, v, w, lim, lstart, reach, rstart, planes, pstart, h, sweeps):
    """Shorten every spring of ``lim`` longer than its cap, in up to ``sweeps`` Gauss-Seidel
    passes alternating forward and backward, each after the Reach and followed by the
    planes, until a full pass finds no spring over its cap and the planes move nothing.
    Between full passes only the springs within NEAR of their caps at the last full one are
    visited. Each garment g (its springs lim[lstart[g]:lstart[g+1]], its reach
    rstart[g]:rstart[g+1], its planes pstart[g]:pstart[g+1]) on its own, in parallel: they
    share no point. The velocities v change by each point's move over the step h (s), as
    Provot's do, so that x - x_n = h v still holds for the step that ends here. Returns
    (the most passes a garment took, the largest excess over a cap the last passes found:
    0 if none)."""
    parts = lstart.shape[0] - 1
    x0 = x.copy()
    near = np.empty(lim.i.shape[0], np.int64)
    taken = np.zeros(parts, np.int64)
    worst = np.zeros(parts)
    for g in prange(parts):
        r0, r1, p0, p1 = rstart[g], rstart[g + 1], pstart[g], pstart[g + 1]
        taken[g], worst[g] = _passes(
            x, w, lim, lstart[g], lstart[g + 1],
            Reach(reach.idx[r0:r1], reach.pin[r0:r1], reach.dist[r0:r1]),
            Planes(planes.idx[p0:p1], planes.n[p0:p1], planes.o[p0:p1]), sweeps, near)
    for p in range(x.shape[0]):
        if w[p] > 0.0:
            for r in range(3):
                v[p, r] += (x[p, r] - x0[p, r]) / h
    return taken.max(), worst.max()


def starts(part, idx, parts: int) -> tuple[np.ndarray, np.ndarray]:
    """The order that groups entries on points idx (k,) by their garment part[idx] (part
    (n,) int64, 0..parts-1; the entries' own order kept within a garment), and each
    garment's first entry in that order, then k (parts+1,)."""
    order = np.argsort(part[idx], kind="stable")
    return order, np.searchsorted(part[idx][order], np.arange(parts + 1))
