"""Contact kernels: a sphere against cord segments and against a plane (SPEC 2.5 response).

Normal force f_n = f_c + c_s p + c_d pdot (clamped at zero: contacts push, never pull), where p
is the penetration depth (m), pdot its rate (m/s), and f_c the constraint term: the force that
cancels the relative acceleration (from all other forces) pushing the two bodies together,
f_c = -m_eff min(0, a_rel.n) with m_eff the pair's reduced mass at the contact point.
Friction is regularized Coulomb: f_t = -mu f_n min(1, |v_t|/eps) v_t/|v_t|.
"""
import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _closest_param(cx, cy, cz, ax, ay, az, bx, by, bz):
    """Parameter t in [0,1] of the point of segment a-b closest to c (scalars: no allocation)."""
    ex, ey, ez = bx - ax, by - ay, bz - az
    L2 = ex * ex + ey * ey + ez * ez
    if L2 <= 0.0:
        return 0.0
    t = ((cx - ax) * ex + (cy - ay) * ey + (cz - az) * ez) / L2
    return min(1.0, max(0.0, t))


@njit(cache=True, inline="always")
def _offset_from_segment(c, x, ia, ib):
    """(t, dx, dy, dz, d2): closest-point parameter on segment ia-ib and the offset c - q."""
    t = _closest_param(c[0], c[1], c[2], x[ia, 0], x[ia, 1], x[ia, 2],
                       x[ib, 0], x[ib, 1], x[ib, 2])
    dx = c[0] - (x[ia, 0] + t * (x[ib, 0] - x[ia, 0]))
    dy = c[1] - (x[ia, 1] + t * (x[ib, 1] - x[ia, 1]))
    dz = c[2] - (x[ia, 2] + t * (x[ib, 2] - x[ia, 2]))
    return t, dx, dy, dz, dx * dx + dy * dy + dz * dz


@njit(cache=True, inline="always")
def _far(c, reach, x, ia, ib):
    """True when the segment's bounding box misses the sphere's: a cheap early rejection."""
    for r in range(3):
        lo = min(x[ia, r], x[ib, r])
        hi = max(x[ia, r], x[ib, r])
        if c[r] + reach < lo or c[r] - reach > hi:
            return True
    return False


@njit(cache=True)
def sphere_segments(c, vc, w, radius, ball_mass, ball_acc, x, v, m, pt_acc, seg, thickness,
                    cs, cd, mu, eps, constraint, dt, out_idx, out_f, out_dfdx, out_dfdv, out_vref,
                    ball_wrench):
    """Contacts of a sphere (centre c, velocity vc, angular velocity w) with segments of points.

    Writes forces on the segment end points (equal and opposite to the ball's, split by the
    closest-point weights) with their 3x3 Jacobians for implicit integrators and the velocity of
    the ball's surface at the contact (what the penetration is relative to) into out_*,
    and the total force (0:3) and torque about the centre (3:6) on the ball into ball_wrench.
    dt (s) is the step the forces will be held for: friction is capped at the force that stops
    the tangential slip within that step (m_eff |v_t| / dt), because the regularized law's
    viscous range (mu f_n / eps per m/s on a net knot of a fraction of a gram) would otherwise
    make explicit steps chatter. dt <= 0 disables the cap.
    Returns the number of point entries written (2 per touching segment).
    """
    for q in range(6):
        ball_wrench[q] = 0.0
    reach = radius + thickness
    k = 0
    # scratch vectors, allocated once per call rather than per contact
    n = np.empty(3)
    r = np.empty(3)
    vball = np.empty(3)
    vrel = np.empty(3)
    vt = np.empty(3)
    F = np.empty(3)
    tau = np.empty(3)
    for s in range(seg.shape[0]):
        ia = seg[s, 0]
        ib = seg[s, 1]
        if _far(c, reach, x, ia, ib):
            continue
        t, dx, dy, dz, d2 = _offset_from_segment(c, x, ia, ib)
        if d2 >= reach * reach or d2 <= 0.0:
            continue
        dist = np.sqrt(d2)
        pen = reach - dist
        wa = 1.0 - t
        wb = t
        n[0], n[1], n[2] = dx / dist, dy / dist, dz / dist
        for q in range(3):
            r[q] = -radius * n[q]
        # velocity of the ball's surface at the contact (v + w x r), relative to the cord's
        vball[0] = vc[0] + w[1] * r[2] - w[2] * r[1]
        vball[1] = vc[1] + w[2] * r[0] - w[0] * r[2]
        vball[2] = vc[2] + w[0] * r[1] - w[1] * r[0]
        vn = 0.0
        for q in range(3):
            vrel[q] = vball[q] - (wa * v[ia, q] + wb * v[ib, q])
            vn += vrel[q] * n[q]
        fn = cs * pen - cd * vn
        inv_m = 1.0 / ball_mass + wa * wa / m[ia] + wb * wb / m[ib]
        if constraint:
            an = 0.0
            for q in range(3):
                an += (ball_acc[q] - (wa * pt_acc[ia, q] + wb * pt_acc[ib, q])) * n[q]
            if an < 0.0:
                fn += -an / inv_m
        if fn <= 0.0:
            continue
        vtn = 0.0
        for q in range(3):
            vt[q] = vrel[q] - vn * n[q]
            vtn += vt[q] * vt[q]
        vtn = np.sqrt(vtn)
        ft_scale = 0.0  # friction force = ft_scale * vt
        if vtn > 0.0:
            fmag = mu * fn * min(1.0, vtn / eps)
            if dt > 0.0:
                fmag = min(fmag, vtn / (inv_m * dt))
            ft_scale = -fmag / vtn
        for q in range(3):
            F[q] = fn * n[q] + ft_scale * vt[q]
        tau[0] = r[1] * F[2] - r[2] * F[1]
        tau[1] = r[2] * F[0] - r[0] * F[2]
        tau[2] = r[0] * F[1] - r[1] * F[0]
        for q in range(3):
            ball_wrench[q] += F[q]
            ball_wrench[3 + q] += tau[q]
        # Jacobians of the point forces: penalty along n; damping along n; friction in the
        # tangent plane while it is in its viscous (regularized) range.
        visc = mu * fn / eps if vtn < eps else 0.0
        if dt > 0.0:
            visc = min(visc, 1.0 / (inv_m * dt))
        for side in range(2):
            p = ia if side == 0 else ib
            wgt = wa if side == 0 else wb
            out_idx[k] = p
            for a in range(3):
                out_vref[k, a] = vball[a]
            for a in range(3):
                out_f[k, a] = -wgt * F[a]
                for b in range(3):
                    nn = n[a] * n[b]
                    out_dfdx[k, a, b] = -wgt * wgt * cs * nn
                    tan = (1.0 if a == b else 0.0) - nn
                    out_dfdv[k, a, b] = -wgt * wgt * (cd * nn + visc * tan)
            k += 1
    return k


@njit(cache=True)
def sphere_plane(c, vc, w, radius, mass, inertia, acc_n, height, cs, cd, mu, eps, dt, wrench):
    """A sphere on the plane z = height (normal +z). acc_n: the sphere's free acceleration
    along +z (m/s^2); inertia: its moment of inertia (kg m^2). Writes force (0:3) and torque
    (3:6) on the sphere; returns True on contact. Friction is capped at the force that stops
    the contact point's slip within dt (through both the sphere's mass and its inertia), so a
    rolling ball does not chatter; dt <= 0 disables the cap."""
    for q in range(6):
        wrench[q] = 0.0
    pen = radius - (c[2] - height)
    if pen <= 0.0:
        return False
    # contact point r = (0, 0, -radius); its velocity v + w x r
    vx = vc[0] - w[1] * radius
    vy = vc[1] + w[0] * radius
    vz = vc[2]
    fn = cs * pen - cd * vz
    if acc_n < 0.0:
        fn += -mass * acc_n
    if fn <= 0.0:
        return False
    fx = 0.0
    fy = 0.0
    vtn = np.sqrt(vx * vx + vy * vy)
    if vtn > 0.0:
        fmag = mu * fn * min(1.0, vtn / eps)
        if dt > 0.0:
            fmag = min(fmag, vtn / ((1.0 / mass + radius * radius / inertia) * dt))
        fx = -fmag * vx / vtn
        fy = -fmag * vy / vtn
    wrench[0] = fx
    wrench[1] = fy
    wrench[2] = fn
    # torque r x F with r = (0, 0, -radius)
    wrench[3] = radius * fy
    wrench[4] = -radius * fx
    wrench[5] = 0.0
    return True


@njit(cache=True)
def sphere_segment_overlap(c, radius, x, seg, reach):
    """Sum over segments of the sphere's penetration depth into each, as a fraction of radius."""
    total = 0.0
    for s in range(seg.shape[0]):
        d2 = _offset_from_segment(c, x, seg[s, 0], seg[s, 1])[4]
        if d2 < reach * reach:
            total += (reach - np.sqrt(d2)) / radius
    return total
