"""Bodies cutting the water's columns (kernels/water.py): solids, their vertical chords, lids.

A solid is an ellipsoid, a capsule or an oriented box in world coordinates. What the water
needs of it is its *vertical chord* at a point (x, y): the interval [zlo, zhi] (m) of the
vertical line through (x, y) inside the solid, empty when the line misses it. Every solid is
convex, so the chord is one interval. Sampling chords over a grid of points and summing
(zhi - zlo) times each point's area gives the solid's volume below any height, which is how
both the columns (``add_solids``: one lid per column it shadows) and the still-water stand-in
(``submerged``: below a flat surface) see a body; the sampled volume is scaled to the exact
one, so a body always displaces exactly its volume when it is under.

Solids bundle: kind (k,) ELLIPSOID | CAPSULE | BOX; centre (k,3) m (a capsule's midpoint);
rot (k,3,3) its axes as columns (a capsule's axis is column 2); size (k,3) m: semi-axes, (radius,
half length of the axis segment, 0), or half extents; volume (k,) m^3; vz (k,) m/s the
vertical speed its lids carry on at within a coupling step.

Lids: where solids cut the columns (one per solid and column), and the content of a column
under them (``content``, ``column_level``): the water's side is kernels/water.py ``heads``.
"""
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .sorting import stable_argsort

ELLIPSOID, CAPSULE, BOX = 0, 1, 2
#: a chord that misses: zlo > zhi
_MISS = (1.0, 0.0)


class Solids(NamedTuple):
    """The solids of one body (see the module docstring)."""
    kind: np.ndarray
    centre: np.ndarray
    rot: np.ndarray
    size: np.ndarray
    volume: np.ndarray
    vz: np.ndarray


@njit(cache=True, inline="always")
def _ellipsoid_chord(c, R, a, x, y):
    """{p: |R^T (p - c) / a| <= 1}: the quadratic (p - c)^T A (p - c) = 1 along z, with A = R
    diag(1/a^2) R^T, solved for z."""
    dx = x - c[0]
    dy = y - c[1]
    # A = sum_k r_k r_k^T / a_k^2, r_k the k-th axis (a column of R)
    a00 = a01 = a02 = a11 = a12 = a22 = 0.0
    for k in range(3):
        w = 1.0 / (a[k] * a[k])
        r0, r1, r2 = R[0, k], R[1, k], R[2, k]
        a00 += w * r0 * r0
        a01 += w * r0 * r1
        a02 += w * r0 * r2
        a11 += w * r1 * r1
        a12 += w * r1 * r2
        a22 += w * r2 * r2
    bq = a02 * dx + a12 * dy
    cq = a00 * dx * dx + 2.0 * a01 * dx * dy + a11 * dy * dy - 1.0
    disc = bq * bq - a22 * cq
    if disc <= 0.0:
        return _MISS
    r = math.sqrt(disc)
    return c[2] + (-bq - r) / a22, c[2] + (-bq + r) / a22


@njit(cache=True, inline="always")
def _sphere_chord(cx, cy, cz, r, x, y):
    d2 = r * r - (x - cx) ** 2 - (y - cy) ** 2
    if d2 <= 0.0:
        return _MISS
    s = math.sqrt(d2)
    return cz - s, cz + s


@njit(cache=True, inline="always")
def _capsule_chord(c, u, r, hl, x, y):
    """The points within r of the segment c +- hl u: the union of the two end spheres and the
    cylinder between them (its infinite cylinder cut by the two end planes), one interval
    because the capsule is convex."""
    lo, hi = _sphere_chord(c[0] + hl * u[0], c[1] + hl * u[1], c[2] + hl * u[2], r, x, y)
    lo2, hi2 = _sphere_chord(c[0] - hl * u[0], c[1] - hl * u[1], c[2] - hl * u[2], r, x, y)
    if hi2 > lo2:
        if hi > lo:
            lo, hi = min(lo, lo2), max(hi, hi2)
        else:
            lo, hi = lo2, hi2
    # the line p(z) = (x, y, z): w = p - c = w0 + z e_z; distance^2 to the axis |w|^2 -
    # (w.u)^2 = A z^2 + 2 B z + C; its axial coordinate s = w.u = s0 + u_z z
    w0x, w0y, w0z = x - c[0], y - c[1], -c[2]
    s0 = w0x * u[0] + w0y * u[1] + w0z * u[2]
    qa = 1.0 - u[2] * u[2]
    qb = w0z - s0 * u[2]
    qc = w0x * w0x + w0y * w0y + w0z * w0z - s0 * s0 - r * r
    if qa > 1e-12:
        disc = qb * qb - qa * qc
        if disc <= 0.0:
            return lo, hi
        q = math.sqrt(disc)
        zl, zh = (-qb - q) / qa, (-qb + q) / qa
    elif qc <= 0.0:  # a vertical axis: the line is inside the infinite cylinder or not
        zl, zh = -1e300, 1e300
    else:
        return lo, hi
    if abs(u[2]) > 1e-12:  # the slab |s| <= hl
        t1, t2 = (-hl - s0) / u[2], (hl - s0) / u[2]
        zl, zh = max(zl, min(t1, t2)), min(zh, max(t1, t2))
    elif abs(s0) > hl:
        return lo, hi
    if zh > zl:
        if hi > lo:
            return min(lo, zl), max(hi, zh)
        return zl, zh
    return lo, hi


@njit(cache=True, inline="always")
def _box_chord(c, R, h, x, y):
    """Slabs: along each box axis e_k the line's coordinate (p - c).e_k = d_k + z e_k,z must
    stay within +-h_k."""
    zl, zh = -1e300, 1e300
    for k in range(3):
        d = (x - c[0]) * R[0, k] + (y - c[1]) * R[1, k] - c[2] * R[2, k]
        ez = R[2, k]
        if abs(ez) > 1e-12:
            t1, t2 = (-h[k] - d) / ez, (h[k] - d) / ez
            zl, zh = max(zl, min(t1, t2)), min(zh, max(t1, t2))
        elif abs(d) > h[k]:
            return _MISS
    if zh > zl:
        return zl, zh
    return _MISS


@njit(cache=True)
def chord(solids, k, x, y):
    """Vertical chord (zlo, zhi) m of solid k at (x, y); zlo > zhi when the line misses."""
    kind, c, R, s = solids.kind[k], solids.centre[k], solids.rot[k], solids.size[k]
    if kind == CAPSULE:
        return _capsule_chord(c, R[:, 2], s[0], s[1], x, y)
    if kind == BOX:
        return _box_chord(c, R, s, x, y)
    return _ellipsoid_chord(c, R, s, x, y)


@njit(cache=True)
def half_extents(solids, k):
    """Half extents (m) of solid k's shadow on the ground: its horizontal bounding box."""
    kind, R, s = solids.kind[k], solids.rot[k], solids.size[k]
    if kind == CAPSULE:
        return (abs(R[0, 2]) * s[1] + s[0], abs(R[1, 2]) * s[1] + s[0])
    if kind == BOX:
        return (abs(R[0, 0]) * s[0] + abs(R[0, 1]) * s[1] + abs(R[0, 2]) * s[2],
                abs(R[1, 0]) * s[0] + abs(R[1, 1]) * s[1] + abs(R[1, 2]) * s[2])
    ex = ey = 0.0
    for j in range(3):
        ex += (R[0, j] * s[j]) ** 2
        ey += (R[1, j] * s[j]) ** 2
    return math.sqrt(ex), math.sqrt(ey)


@njit(cache=True)
def submerged(solids, level, ns, out):
    """Each solid below the flat surface z = level (m), sampled at ns x ns chords over its
    shadow: out (k, 4) = [volume below (m^3), centre of that volume (3) m]. The sampled
    volumes are scaled so the whole solid has its exact volume (a solid wholly under has
    exactly its volume); a solid wholly above gets zeros and its own centre."""
    for k in range(solids.kind.shape[0]):
        ex, ey = half_extents(solids, k)
        c = solids.centre[k]
        full = 0.0
        v = sx = sy = sz = 0.0
        for i in range(ns):
            x = c[0] - ex + (i + 0.5) * 2.0 * ex / ns
            for j in range(ns):
                y = c[1] - ey + (j + 0.5) * 2.0 * ey / ns
                lo, hi = chord(solids, k, x, y)
                if hi <= lo:
                    continue
                full += hi - lo
                top = min(hi, level)
                if top > lo:
                    d = top - lo
                    v += d
                    sx += d * x
                    sy += d * y
                    sz += d * 0.5 * (lo + top)
        if v > 0.0:
            out[k, 0] = v * solids.volume[k] / full
            out[k, 1], out[k, 2], out[k, 3] = sx / v, sy / v, sz / v
        else:
            out[k, 0] = 0.0
            out[k, 1], out[k, 2], out[k, 3] = c[0], c[1], c[2]


class Lids(NamedTuple):
    """Where bodies cut the columns: cell (k,) a column's flat index, owner (k,) the solid it
    belongs to (numbered in the order solids register in a coupling step), zlo, zhi (k, s^2)
    the bottom and top (m) of the solid's vertical chord at each sample point, scale (k,) the
    solid's volume scale, vz (k,) its vertical speed (m/s). Kept sorted by cell
    (``group_lids``): the lids over one column are one contiguous run."""
    cell: np.ndarray
    owner: np.ndarray
    zlo: np.ndarray
    zhi: np.ndarray
    scale: np.ndarray
    vz: np.ndarray


@njit(cache=True, inline="always")
def content(H, b, lo, chord, kappa):
    """Water (m of column height) a sample point under a body holds when the column's head is
    H, and its slope dC/dH. Below the body's bottom lo the water is free; above it, water
    pressed a height e into the body meets the penalty head kappa e (so e = (H - lo) /
    (1 + kappa)), until that head reaches the chord: then the water stands on the body."""
    if chord <= 0.0 or H <= lo:
        return H - b, 1.0
    if (H - lo) * kappa <= chord * (1.0 + kappa):
        return lo - b + (H - lo) / (1.0 + kappa), 1.0 / (1.0 + kappa)
    return H - b - chord, 1.0


@njit(cache=True, inline="always")
def lid_sample(zlo, zhi, scale, b):
    """Bottom (m, not below the bed b) and volume-scaled chord (m) of a lid's sample."""
    lo = max(zlo, b)
    return lo, scale * max(zhi - lo, 0.0)


@njit(cache=True, inline="always")
def merged(lids, k0, k1, s, b):
    """Bottom (m) and chord (m) of the bodies over sample s of a column (its lids [k0, k1)):
    the lowest bottom and the sum of their chords, i.e. packed from the lowest bottom up.
    Exact for one body and for bodies stacked without gaps (a diver's segments along his
    axis); a gap of air between two bodies over one sample is closed."""
    lo = 1e300
    ch = 0.0
    for k in range(k0, k1):
        l, c = lid_sample(lids.zlo[k, s], lids.zhi[k, s], lids.scale[k], b)
        if c > 0.0:
            lo = min(lo, l)
            ch += c
    if ch <= 0.0:
        return b, 0.0
    return lo, ch


@njit(cache=True, inline="always")
def run_end(cell, k, n):
    """End of the run of lids over the same column as lid k (lids are sorted by cell)."""
    k1 = k + 1
    while k1 < n and cell[k1] == cell[k]:
        k1 += 1
    return k1


@njit(cache=True)
def column_level(eta, b, lids, k0, k1, kappa):
    """The head H (m) of a column under bodies (its lids [k0, k1)): the root of mean_s
    C_s(H) = eta - b (its water), a monotone piecewise-linear equation solved by Newton's
    method kept inside a bracket (exact once on the right linear piece)."""
    ns2 = lids.zlo.shape[1]
    target = eta - b
    cmax = 0.0
    for s in range(ns2):
        cmax = max(cmax, merged(lids, k0, k1, s, b)[1])
    a, z = eta, eta + cmax * (1.0 + 1.0 / kappa) + 1e-12
    H = eta
    for _ in range(60):
        c = 0.0
        dc = 0.0
        for s in range(ns2):
            lo, ch = merged(lids, k0, k1, s, b)
            ci, di = content(H, b, lo, ch, kappa)
            c += ci
            dc += di
        f = c / ns2 - target
        if abs(f) <= 1e-14 * (abs(target) + abs(H)):
            break
        if f > 0.0:
            z = H
        else:
            a = H
        Hn = H - f * ns2 / dc
        H = Hn if a < Hn < z else 0.5 * (a + z)
    return H


@njit(cache=True)
def add_solids(solids, grid, ns, lids, n, owner0):
    """Append the lids of the solids (kernels/solids.py) from index n, solid k owning them as
    owner0 + k: one per fluid column its shadow touches, sampled at ns x ns points, each
    carrying the solid's vertical speed. The scale (solid volume) / (sampled volume) gives
    every sampled solid its exact volume. Returns the new count, or -1 if the buffers are too
    small. ``group_lids`` must follow before the lids are used."""
    fluid, x0, y0, l = grid.fluid, grid.x0, grid.y0, grid.l
    nx, ny = fluid.shape
    for k in range(solids.kind.shape[0]):
        c = solids.centre[k]
        ex, ey = half_extents(solids, k)
        i_lo = int(math.floor((c[0] - ex - x0) / l + 0.5))
        i_hi = int(math.floor((c[0] + ex - x0) / l + 0.5))
        j_lo = int(math.floor((c[1] - ey - y0) / l + 0.5))
        j_hi = int(math.floor((c[1] + ey - y0) / l + 0.5))
        sampled = 0.0
        start = n
        for i in range(i_lo, i_hi + 1):
            for j in range(j_lo, j_hi + 1):
                inside = 0 <= i < nx and 0 <= j < ny and fluid[i, j]
                if inside and n >= lids.cell.shape[0]:
                    return -1
                touched = False
                for si in range(ns):
                    x = x0 + (i - 0.5 + (si + 0.5) / ns) * l
                    for sj in range(ns):
                        zlo, zhi = chord(solids, k, x, y0 + (j - 0.5 + (sj + 0.5) / ns) * l)
                        if zhi <= zlo:
                            zlo = zhi = -1e30  # no body here: a chord of zero length
                        else:
                            sampled += (zhi - zlo) * l * l / (ns * ns)
                            touched = True
                        if inside:
                            lids.zlo[n, si * ns + sj] = zlo
                            lids.zhi[n, si * ns + sj] = zhi
                if inside and touched:
                    lids.cell[n] = i * ny + j
                    lids.owner[n] = owner0 + k
                    lids.vz[n] = solids.vz[k]
                    n += 1
        for m in range(start, n):
            lids.scale[m] = solids.volume[k] / sampled
    return n


@njit(cache=True)
def group_lids(lids, n):
    """Sort the first n lids by column (stable: lids of one column keep their order).
    Gathered by a loop, not NumPy's fancy indexing, which costs Numba seconds to compile for
    each array type (7.5 s against 2.6 s for this kernel on an empty cache); sorted by
    ``sorting.stable_argsort``, the same order as NumPy's merge sort without its compile."""
    order = stable_argsort(lids.cell[:n])
    cell, owner = lids.cell[:n].copy(), lids.owner[:n].copy()
    scale, vz = lids.scale[:n].copy(), lids.vz[:n].copy()
    zlo, zhi = lids.zlo[:n].copy(), lids.zhi[:n].copy()
    for m in range(n):
        o = order[m]
        lids.cell[m], lids.owner[m] = cell[o], owner[o]
        lids.scale[m], lids.vz[m] = scale[o], vz[o]
        for s in range(zlo.shape[1]):
            lids.zlo[m, s] = zlo[o, s]
            lids.zhi[m, s] = zhi[o, s]
