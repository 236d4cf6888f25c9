"""Per-triangle aerodynamic drag and lift (SPEC 2.2), spread over each triangle's points.

For triangle t with unit normal n, area s and velocity relative to the wind v (the mean of
its three points' velocities minus the wind at its centroid):

    f = -c_n s |v| (n.v) n - c_t s (v - (n.v) n)

The normal term is quadratic (pressure drag; at an angle of attack it has a component across
the wind: lift), the tangential one linear (skin friction). It is the same for either normal
orientation, so meshes need no consistent winding. Each point gets f / 3. The delta law
(``interactions.aero.AeroParams``) replaces the constant c_n by one that depends on the
triangle's angle of attack: f = -c(a) s |v| (n.v) n - c_t s (v - (n.v) n).
"""
import numpy as np
from numba import njit


@njit(cache=True)
def centroids(x, tris, out):
    """out[t] = mean of triangle t's three points (m)."""
    for t in range(tris.shape[0]):
        for c in range(3):
            out[t, c] = (x[tris[t, 0], c] + x[tris[t, 1], c] + x[tris[t, 2], c]) / 3.0


@njit(cache=True)
def normal_coefficient(sa, law, cn, kp, kv, sin_stall, c_stall):
    """The normal force's coefficient c (kg/m^3) at an angle of attack of sine sa: the plate
    law's cn (law 0) or the delta law's (law 1): kp cos^2 a + kv sin a cos a up to the stall
    (kp, kv: 0.5 rho K_p and 0.5 rho K_v), above it the larger of c_stall / sin a (the
    normal force held at its value at the stall, c_stall = 0.5 rho C_N there) and cn."""
    if law == 0:
        return cn
    if sa <= sin_stall:
        ca = np.sqrt(max(0.0, 1.0 - sa * sa))
        return ca * (kp * ca + kv * sa)
    return max(c_stall / sa, cn)


@njit(cache=True)
def triangle_forces(x, v, tris, wind, cn, ct, f, dfdv, with_jacobian, law=0, kp=0.0, kv=0.0,
                    sin_stall=1.0, c_stall=0.0, info=None):
    """Add each triangle's force f/3 (N) to f (n,3) of its points; return the total force.

    wind (m,3): the wind velocity (m/s) at each centroid; cn (N s^2/m^4 per m^2 of area and
    (m/s)^2: kg/m^3), ct (kg/(m^2 s)); law, kp, kv, sin_stall, c_stall: the normal force's
    law (``normal_coefficient``; 0, the default, is SPEC 2.2's constant cn). With
    with_jacobian, dfdv (n,3,3) receives a symmetric negative semidefinite d f / d v per
    point for implicit integrators: the triangle's -(c s (|v| + |n.v|) n n^T + c_t s (I - n
    n^T)) (the symmetric part of the exact derivative at the present coefficient c, exact for
    the plate law when v is along n) lumped as 1/3 to each point (the row sum over the three
    points sharing the triangle's velocity). The loop is serial: the scatter to shared
    points stays race-free, and a scene's aerodynamic meshes are small next to its springs.
    info (m,8), if given, receives per triangle its unit normal n (3), its normal force along
    n (N), its area s (m^2) and its velocity relative to the wind (3, m/s), for
    ``chordwise_centre``.
    """
    total = np.zeros(3)
    for t in range(tris.shape[0]):
        i, j, k = tris[t, 0], tris[t, 1], tris[t, 2]
        e10 = x[j, 0] - x[i, 0]
        e11 = x[j, 1] - x[i, 1]
        e12 = x[j, 2] - x[i, 2]
        e20 = x[k, 0] - x[i, 0]
        e21 = x[k, 1] - x[i, 1]
        e22 = x[k, 2] - x[i, 2]
        n0 = e11 * e22 - e12 * e21
        n1 = e12 * e20 - e10 * e22
        n2 = e10 * e21 - e11 * e20
        a2 = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if a2 == 0.0:
            if info is not None:
                info[t, 4] = 0.0  # no area: no force for chordwise_centre to move
            continue
        n0 /= a2
        n1 /= a2
        n2 /= a2
        s = 0.5 * a2
        r0 = (v[i, 0] + v[j, 0] + v[k, 0]) / 3.0 - wind[t, 0]
        r1 = (v[i, 1] + v[j, 1] + v[k, 1]) / 3.0 - wind[t, 1]
        r2 = (v[i, 2] + v[j, 2] + v[k, 2]) / 3.0 - wind[t, 2]
        speed = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        vn = n0 * r0 + n1 * r1 + n2 * r2
        c = cn if law == 0 or speed == 0.0 else normal_coefficient(
            abs(vn) / speed, law, cn, kp, kv, sin_stall, c_stall)
        cnn = -c * s * speed * vn
        if info is not None:
            info[t, 0], info[t, 1], info[t, 2], info[t, 3] = n0, n1, n2, cnn
            info[t, 4], info[t, 5], info[t, 6], info[t, 7] = s, r0, r1, r2
        f0 = cnn * n0 - ct * s * (r0 - vn * n0)
        f1 = cnn * n1 - ct * s * (r1 - vn * n1)
        f2 = cnn * n2 - ct * s * (r2 - vn * n2)
        total[0] += f0
        total[1] += f1
        total[2] += f2
        for p in (i, j, k):
            f[p, 0] += f0 / 3.0
            f[p, 1] += f1 / 3.0
            f[p, 2] += f2 / 3.0
        if with_jacobian:
            dn = c * s * (speed + abs(vn))
            dt = ct * s
            nn = (n0, n1, n2)
            for p in (i, j, k):
                for a in range(3):
                    for b in range(3):
                        eye = 1.0 if a == b else 0.0
                        dfdv[p, a, b] -= (dn * nn[a] * nn[b] + dt * (eye - nn[a] * nn[b])) / 3.0
    return total


BETA = 40.0  # the largest |b|: exp(-40) moves the whole force to the leading edge
BISECTIONS = 50  # halves the bracket of b to 80 / 2^50


@njit(cache=True)
def chordwise_centre(x, tris, cent, info, f):
    """Move a flat sail's centre of pressure along its chord as a flat plate's moves with its
    angle of attack, keeping each triangle's force normal to it and the sum of their sizes.

    The per-triangle law puts each triangle's normal force at its centroid, so the sail's
    centre of pressure is its area centroid x_A at every angle. A flat plate's lies at
    0.2 + 0.3 sin a of the chord c from its leading edge (Joessel's measurements; ESDU 70015,
    1970): a quarter chord near a = 0, the centroid at 90 deg. Generalised to any planform as
    x_le + (x_A - x_le)(0.4 + 0.6 sin a) along the chord, which is that for a rectangle.

    The sail's plane is its area-weighted normal N (each triangle's normal turned to agree with
    the first's), its flow the area-weighted mean of the triangles' velocities relative to the
    wind V (info's columns 4-7, from ``triangle_forces``); a = the angle between V and the
    plane; the chord runs downstream along V's part in the plane, from the most upstream point
    (x_le). Each triangle's normal force F_t (info column 3, along its normal, columns 0-2) is
    scaled by w_t = exp(-b u_t) W (u_t its centroid's chord position over the chord's length,
    W keeping sum |F_t| w_t = sum |F_t|), b found by bisection so that the forces' centre
    (weighted by |F_t| w_t) lies at the plate's. The change, (w_t - 1) F_t n_t, is added to
    f (n,3) N, a third to each point; returns its total (3,) N (zero for a flat sail: a
    couple). cent (m,3): the triangles' centroids (m). The velocity Jacobian is left as the
    per-triangle law's: the couple only moves where the force acts.
    """
    m = tris.shape[0]
    total = np.zeros(3)
    ref = -1
    for t in range(m):
        if info[t, 4] > 0.0:
            ref = t
            break
    if ref < 0:
        return total
    N = np.zeros(3)
    V = np.zeros(3)
    area = 0.0
    for t in range(m):
        s = info[t, 4]
        if s <= 0.0:
            continue
        d = info[t, 0] * info[ref, 0] + info[t, 1] * info[ref, 1] + info[t, 2] * info[ref, 2]
        sgn = -1.0 if d < 0.0 else 1.0
        for r in range(3):
            N[r] += s * sgn * info[t, r]
            V[r] += s * info[t, 5 + r]
        area += s
    nn = np.sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2])
    speed = np.sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2]) / area
    if nn == 0.0 or speed == 0.0:
        return total
    N /= nn
    V /= area
    vn = V[0] * N[0] + V[1] * N[1] + V[2] * N[2]
    e = -(V - vn * N)  # the air's flow along the plane, downstream
    el = np.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    if el <= 1e-9 * speed:
        return total  # the flow meets the plane square on: the centroid is the plate's centre
    e /= el
    sin_a = abs(vn) / speed
    le, hi = np.inf, -np.inf
    for i in range(tris.shape[0]):
        for k in range(3):
            p = tris[i, k]
            xs = x[p, 0] * e[0] + x[p, 1] * e[1] + x[p, 2] * e[2]
            le = min(le, xs)
            hi = max(hi, xs)
    chord = hi - le
    xi = np.empty(m)
    mag = np.empty(m)
    xa, total_mag = 0.0, 0.0
    for t in range(m):
        xi[t] = cent[t, 0] * e[0] + cent[t, 1] * e[1] + cent[t, 2] * e[2]
        mag[t] = abs(info[t, 3]) if info[t, 4] > 0.0 else 0.0
        xa += info[t, 4] * xi[t] if info[t, 4] > 0.0 else 0.0
        total_mag += mag[t]
    if total_mag == 0.0 or chord <= 0.0:
        return total
    xa /= area
    target = le + (xa - le) * (0.4 + 0.6 * sin_a)
    lo_b, hi_b = -BETA, BETA  # the centre moves upstream as b grows
    for _ in range(BISECTIONS):
        b = 0.5 * (lo_b + hi_b)
        num, den = 0.0, 0.0
        for t in range(m):
            w = mag[t] * np.exp(-b * (xi[t] - le) / chord)
            num += w * xi[t]
            den += w
        if num / den > target:
            lo_b = b
        else:
            hi_b = b
    b = 0.5 * (lo_b + hi_b)
    w = np.exp(-b * (xi - le) / chord)
    scale = total_mag / (mag * w).sum()
    for t in range(m):
        if info[t, 4] <= 0.0:
            continue
        dw = (w[t] * scale - 1.0) * info[t, 3]
        for r in range(3):
            d = dw * info[t, r]
            total[r] += d
            for k in range(3):
                f[tris[t, k], r] += d / 3.0
    return total


@njit(cache=True)
def midpoints(x, seg, out):
    """out[s] = the middle of segment s's two points (m)."""
    for s in range(seg.shape[0]):
        for c in range(3):
            out[s, c] = 0.5 * (x[seg[s, 0], c] + x[seg[s, 1], c])


@njit(cache=True)
def segment_forces(x, v, seg, wind, cn, ct, f, dfdv, with_jacobian):
    """Add each cord segment's drag, half to each end point, to f (n,3) N; return the total.

    A segment of unit direction t, length l and diameter d (cn = 1/2 rho C_D d, kg/m^2;
    ct = 1/2 rho C_f pi d, kg/m^2), moving at v (the mean of its ends' velocities minus the
    wind at its middle) relative to the air, feels the cross-flow drag of a cylinder on the
    part of v across it (the independence principle) and skin friction along it:

        f = -cn l |v_n| v_n - ct l |v_t| v_t,   v_t = (v.t) t,  v_n = v - v_t.

    dfdv (n,3,3) receives the exact derivative with respect to v (symmetric negative
    semidefinite: -cn l (|v_n| P + v_n v_n^T / |v_n|) - 2 ct l |v.t| t t^T, P = I - t t^T),
    lumped as 1/2 to each end (the row sum over the two points sharing the velocity)."""
    total = np.zeros(3)
    for s in range(seg.shape[0]):
        i, j = seg[s, 0], seg[s, 1]
        t0 = x[j, 0] - x[i, 0]
        t1 = x[j, 1] - x[i, 1]
        t2 = x[j, 2] - x[i, 2]
        ln = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        if ln == 0.0:
            continue
        t0 /= ln
        t1 /= ln
        t2 /= ln
        r0 = 0.5 * (v[i, 0] + v[j, 0]) - wind[s, 0]
        r1 = 0.5 * (v[i, 1] + v[j, 1]) - wind[s, 1]
        r2 = 0.5 * (v[i, 2] + v[j, 2]) - wind[s, 2]
        vt = r0 * t0 + r1 * t1 + r2 * t2
        n0 = r0 - vt * t0
        n1 = r1 - vt * t1
        n2 = r2 - vt * t2
        vn = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        a = cn * ln * vn
        b = ct * ln * abs(vt)
        f0 = -a * n0 - b * vt * t0
        f1 = -a * n1 - b * vt * t1
        f2 = -a * n2 - b * vt * t2
        total[0] += f0
        total[1] += f1
        total[2] += f2
        for p in (i, j):
            f[p, 0] += 0.5 * f0
            f[p, 1] += 0.5 * f1
            f[p, 2] += 0.5 * f2
        if with_jacobian:
            tt = (t0, t1, t2)
            nn = (n0, n1, n2)
            inv = 1.0 / vn if vn > 0.0 else 0.0
            for p in (i, j):
                for r in range(3):
                    for c in range(3):
                        eye = 1.0 if r == c else 0.0
                        d = (a * (eye - tt[r] * tt[c]) + cn * ln * nn[r] * nn[c] * inv
                             + 2.0 * b * tt[r] * tt[c])
                        dfdv[p, r, c] -= 0.5 * d
    return total


@njit(cache=True)
def point_forces(v, idx, wind, cd_area, f, dfdv, with_jacobian):
    """Add the drag of small bluff bodies at points idx (a tail's bows) to f (n,3) N; return
    the total: f = -cd_area |v| v with v the point's velocity minus the wind there (wind (b,3))
    and cd_area (b,) = 1/2 rho C_D A (kg/m). dfdv gets -cd_area (|v| I + v v^T / |v|)."""
    total = np.zeros(3)
    for b in range(idx.shape[0]):
        p = idx[b]
        r0 = v[p, 0] - wind[b, 0]
        r1 = v[p, 1] - wind[b, 1]
        r2 = v[p, 2] - wind[b, 2]
        speed = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        c = cd_area[b] * speed
        f[p, 0] -= c * r0
        f[p, 1] -= c * r1
        f[p, 2] -= c * r2
        total[0] -= c * r0
        total[1] -= c * r1
        total[2] -= c * r2
        if with_jacobian:
            rr = (r0, r1, r2)
            inv = cd_area[b] / speed if speed > 0.0 else 0.0
            for r in range(3):
                dfdv[p, r, r] -= c
                for q in range(3):
                    dfdv[p, r, q] -= inv * rr[r] * rr[q]
    return total
