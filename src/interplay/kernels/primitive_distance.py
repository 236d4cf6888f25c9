"""How near a rigid part's primitive (sphere, capsule, box, its edges and corners possibly
rounded) comes to a spring-mass network's elements: a segment (a spring, a triangle's edge),
a point, or a triangle's face (kernels/part_contact.py runs the contact law on them).

A segment by its deepest point (Ericson 5.1.9 for spheres and capsules; for a box the signed
distance along the segment is convex in its parameter, so golden-section search finds it).
A face by the primitive's features: a box's eight corners, a capsule's two ends, a sphere's
centre, each a ball of the rounding's or the radius's size, against the triangle's interior;
where a feature's foot falls outside the triangle its edges answer. Edges and features
together cover every way a convex part meets a triangle short of passing through it: a foot
narrower than the bed's facets then rests on a facet's inside instead of wedging between its
edges and falling through (docs/trampoline.md).

The part at centre c, rotation R (part to world); the primitive's data as in
part_contact.Parts (p, q, size; a box's rounding in q[0]). Units m; normals unit, pointing
from the element towards the part.
"""
import numpy as np
from numba import njit

SPHERE, CAPSULE, BOX = 0, 1, 2


@njit(cache=True, inline="always")
def _local_sd(l0, l1, l2, h0, h1, h2):
    """Signed distance (m) of a point (l0, l1, l2) in a box's frame from the box of half
    extents h0, h1, h2 centred there."""
    q0, q1, q2 = abs(l0) - h0, abs(l1) - h1, abs(l2) - h2
    if q0 > 0.0 or q1 > 0.0 or q2 > 0.0:
        e0, e1, e2 = max(q0, 0.0), max(q1, 0.0), max(q2, 0.0)
        return np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    return max(q0, max(q1, q2))


@njit(cache=True)
def _box_sd(C, R, h0, h1, h2, px, py, pz, g):
    """Signed distance (m) of point p from a box (centre C, rotation R, half extents h0, h1,
    h2) and the outward unit normal there, in the world, into g."""
    dx, dy, dz = px - C[0], py - C[1], pz - C[2]
    l0 = R[0, 0] * dx + R[1, 0] * dy + R[2, 0] * dz
    l1 = R[0, 1] * dx + R[1, 1] * dy + R[2, 1] * dz
    l2 = R[0, 2] * dx + R[1, 2] * dy + R[2, 2] * dz
    q0, q1, q2 = abs(l0) - h0, abs(l1) - h1, abs(l2) - h2
    if q0 > 0.0 or q1 > 0.0 or q2 > 0.0:
        e0, e1, e2 = max(q0, 0.0), max(q1, 0.0), max(q2, 0.0)
        d = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        u0 = (e0 if l0 >= 0.0 else -e0) / d
        u1 = (e1 if l1 >= 0.0 else -e1) / d
        u2 = (e2 if l2 >= 0.0 else -e2) / d
    else:  # inside: out through the nearest face
        d = max(q0, max(q1, q2))
        u0 = (1.0 if l0 >= 0.0 else -1.0) if d == q0 else 0.0
        u1 = (1.0 if l1 >= 0.0 else -1.0) if (d == q1 and d != q0) else 0.0
        u2 = (1.0 if l2 >= 0.0 else -1.0) if (d == q2 and d != q0 and d != q1) else 0.0
    for r in range(3):
        g[r] = R[r, 0] * u0 + R[r, 1] * u1 + R[r, 2] * u2
    return d


@njit(cache=True, inline="always")
def closest(kind, p, q, size, c, R, x, ia, ib, A, B, X, P, n, golden):
    """Deepest approach of a part's primitive (kind, p, q, size as in Parts; the part at
    centre c, rotation R) to element ia-ib: returns (the element's parameter t in [0,1],
    signed gap s: distance from the part's surface, negative inside); writes the element's
    contact point X, the part's surface point P and the unit normal n (element towards
    part). A, B are scratch (3,). golden: a box's golden-section steps along the segment (its
    bracket shrinks to 0.618^golden of the segment: 14 ~ 1e-3, 40 ~ 4e-9)."""
    for r in range(3):
        A[r] = c[r] + R[r, 0] * p[0] + R[r, 1] * p[1] + R[r, 2] * p[2]
    xa, xb = x[ia], x[ib]
    if kind == BOX:
        # the element in the box's frame: the signed distance along it is then a cheap
        # function of t, convex, minimised by golden-section search
        ax, ay, az = xa[0] - A[0], xa[1] - A[1], xa[2] - A[2]
        a0 = R[0, 0] * ax + R[1, 0] * ay + R[2, 0] * az
        a1 = R[0, 1] * ax + R[1, 1] * ay + R[2, 1] * az
        a2 = R[0, 2] * ax + R[1, 2] * ay + R[2, 2] * az
        bx, by, bz = xb[0] - A[0], xb[1] - A[1], xb[2] - A[2]
        e0 = R[0, 0] * bx + R[1, 0] * by + R[2, 0] * bz - a0
        e1 = R[0, 1] * bx + R[1, 1] * by + R[2, 1] * bz - a1
        e2 = R[0, 2] * bx + R[1, 2] * by + R[2, 2] * bz - a2
        # a rounded box is the inner box (half extents less the rounding) grown by the
        # rounding: its signed distance the inner box's less the rounding, the same normal
        rnd = q[0]
        h0, h1, h2 = size[0] - rnd, size[1] - rnd, size[2] - rnd
        t = 0.0
        if ia != ib:
            lo, hi = 0.0, 1.0
            gr = 0.6180339887498949
            t1, t2 = 1.0 - gr, gr
            f1 = _local_sd(a0 + t1 * e0, a1 + t1 * e1, a2 + t1 * e2, h0, h1, h2)
            f2 = _local_sd(a0 + t2 * e0, a1 + t2 * e1, a2 + t2 * e2, h0, h1, h2)
            for _ in range(golden):
                if f1 <= f2:
                    hi, t2, f2 = t2, t1, f1
                    t1 = hi - gr * (hi - lo)
                    f1 = _local_sd(a0 + t1 * e0, a1 + t1 * e1, a2 + t1 * e2, h0, h1, h2)
                else:
                    lo, t1, f1 = t1, t2, f2
                    t2 = lo + gr * (hi - lo)
                    f2 = _local_sd(a0 + t2 * e0, a1 + t2 * e1, a2 + t2 * e2, h0, h1, h2)
            # a convex function's minimum may sit at an end of the segment
            t = 0.5 * (lo + hi)
            best = _local_sd(a0 + t * e0, a1 + t * e1, a2 + t * e2, h0, h1, h2)
            f0 = _local_sd(a0, a1, a2, h0, h1, h2)
            if f0 < best:
                t, best = 0.0, f0
            fe = _local_sd(a0 + e0, a1 + e1, a2 + e2, h0, h1, h2)
            if fe < best:
                t = 1.0
        for r in range(3):
            X[r] = xa[r] + t * (xb[r] - xa[r])
        s = _box_sd(A, R, h0, h1, h2, X[0], X[1], X[2], n) - rnd
        for r in range(3):
            P[r] = X[r] - s * n[r]  # the box's surface point nearest X
            n[r] = -n[r]  # outward from the box points at the element: flip to element -> part
        return t, s
    radius = size[0]
    if kind == CAPSULE:
        for r in range(3):
            B[r] = c[r] + R[r, 0] * q[0] + R[r, 1] * q[1] + R[r, 2] * q[2]
        sa, t = _segments(A, B, xa, xb)
        for r in range(3):
            A[r] += sa * (B[r] - A[r])  # the axis point nearest the element
    else:
        ex, ey, ez = xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]
        L2 = ex * ex + ey * ey + ez * ez
        t = 0.0 if L2 <= 0.0 else min(1.0, max(0.0, ((A[0] - xa[0]) * ex + (A[1] - xa[1]) * ey
                                                     + (A[2] - xa[2]) * ez) / L2))
    d2 = 0.0
    for r in range(3):
        X[r] = xa[r] + t * (xb[r] - xa[r])
        n[r] = A[r] - X[r]
        d2 += n[r] * n[r]
    d = np.sqrt(d2)
    if d <= 0.0:  # the element passes through the axis: push along +z (does not happen at rest)
        n[0], n[1], n[2] = 0.0, 0.0, 1.0
    else:
        for r in range(3):
            n[r] /= d
    for r in range(3):
        P[r] = A[r] - radius * n[r]
    return t, d - radius


@njit(cache=True, inline="always")
def _segments(p1, q1, p2, q2):
    """Parameters (s, t) of the closest points of segments p1-q1 and p2-q2 (Ericson 5.1.9,
    scalar: no temporaries)."""
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    rx, ry, rz = p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    tiny = 1e-30
    if a <= tiny and e <= tiny:
        return 0.0, 0.0
    if a <= tiny:
        return 0.0, min(1.0, max(0.0, f / e))
    c = d1x * rx + d1y * ry + d1z * rz
    if e <= tiny:
        return min(1.0, max(0.0, -c / a)), 0.0
    b = d1x * d2x + d1y * d2y + d1z * d2z
    den = a * e - b * b
    s = min(1.0, max(0.0, (b * f - c * e) / den)) if den > 1e-14 * a * e else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        return min(1.0, max(0.0, -c / a)), 0.0
    if t > 1.0:
        return min(1.0, max(0.0, (b - c) / a)), 1.0
    return s, t


@njit(cache=True)
def features(kind):
    """How many features of a part of this kind a face is tested against: a box's eight
    corners, a capsule's two ends, a sphere's centre."""
    return 8 if kind == BOX else (2 if kind == CAPSULE else 1)


@njit(cache=True, inline="always")
def face_feature(kind, p, q, size, c, R, f, x, ia, ib, ic, X, P, n, w):
    """Feature f (0 .. features(kind) - 1) of a part's primitive against the triangle
    ia-ib-ic: returns the signed gap (m; negative inside) between the feature's ball and the
    triangle's plane, or inf where the feature's foot on the plane falls outside the triangle
    (its edges answer there) or the feature lies on the plane's far side by more than the part
    can reach through it (a box's corner: the inner box's thickness, its smallest extent; an
    end's or a sphere's centre: none), which is a part that has passed the face, or a face
    turned away from it. (Half the thickness let a foot box through the bed under 2000 N:
    under a bed point pressed by ~1000 N a corner sinks 3 cm into the contact's skin.)
    Writes the face point X (the feature's foot), the part's surface point P, the normal n
    (the face's, turned towards the part's centre c) and X's barycentric weights w (3,) on
    ia, ib, ic."""
    xa, xb, xc = x[ia], x[ib], x[ic]
    if kind == BOX:
        rnd = q[0]
        h0, h1, h2 = size[0] - rnd, size[1] - rnd, size[2] - rnd
        s0 = h0 if f & 1 else -h0
        s1 = h1 if f & 2 else -h1
        s2 = h2 if f & 4 else -h2
        l0, l1, l2 = p[0] + s0, p[1] + s1, p[2] + s2
        radius, through = rnd, 2.0 * min(h0, min(h1, h2))
    else:
        src = q if (kind == CAPSULE and f == 1) else p
        l0, l1, l2 = src[0], src[1], src[2]
        radius, through = size[0], 0.0
    F0 = c[0] + R[0, 0] * l0 + R[0, 1] * l1 + R[0, 2] * l2
    F1 = c[1] + R[1, 0] * l0 + R[1, 1] * l1 + R[1, 2] * l2
    F2 = c[2] + R[2, 0] * l0 + R[2, 1] * l1 + R[2, 2] * l2
    e1x, e1y, e1z = xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]
    e2x, e2y, e2z = xc[0] - xa[0], xc[1] - xa[1], xc[2] - xa[2]
    nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    area2 = np.sqrt(nx * nx + ny * ny + nz * nz)
    if area2 <= 0.0:
        return np.inf
    nx, ny, nz = nx / area2, ny / area2, nz / area2
    d = (F0 - xa[0]) * nx + (F1 - xa[1]) * ny + (F2 - xa[2]) * nz
    # the foot's barycentric weights: r = X - xa = wb e1 + wc e2, so (r x e2) . n = wb |e1 x e2|
    # and (e1 x r) . n = wc |e1 x e2|
    rx, ry, rz = F0 - d * nx - xa[0], F1 - d * ny - xa[1], F2 - d * nz - xa[2]
    wb = ((ry * e2z - rz * e2y) * nx + (rz * e2x - rx * e2z) * ny
          + (rx * e2y - ry * e2x) * nz) / area2
    wc = ((e1y * rz - e1z * ry) * nx + (e1z * rx - e1x * rz) * ny
          + (e1x * ry - e1y * rx) * nz) / area2
    wa = 1.0 - wb - wc
    if wa < 0.0 or wb < 0.0 or wc < 0.0:
        return np.inf
    if (c[0] - xa[0]) * nx + (c[1] - xa[1]) * ny + (c[2] - xa[2]) * nz < 0.0:
        nx, ny, nz, d = -nx, -ny, -nz, -d  # the side the part's centre is on
    if d < -through:
        return np.inf
    X[0], X[1], X[2] = F0 - d * nx, F1 - d * ny, F2 - d * nz
    w[0], w[1], w[2] = wa, wb, wc
    n[0], n[1], n[2] = nx, ny, nz
    P[0], P[1], P[2] = F0 - radius * nx, F1 - radius * ny, F2 - radius * nz
    return d - radius
