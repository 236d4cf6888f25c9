"""Contact kernels for spheres and points: a sphere against cord segments or points, a sphere
on a plane, points on a plane (SPEC 2.5). Each finds its contacts and applies the one contact
law (``contact_law``: stabilised penalty with the constraint term, regularised Coulomb
friction).

A contact law's coefficients travel as a row ``law`` (6,): THICKNESS (m, the contact skin, e.g.
a cord's radius), STIFFNESS c_s (N/m), DAMPING c_d (N s/m), FRICTION mu (-), EPS (m/s, the slip
speed of full Coulomb friction), CONSTRAINT (1: include the constraint term).
"""
from typing import NamedTuple

import numpy as np
from numba import njit

from .contact_law import friction_damping, friction_slope, normal_force, sliding_friction

THICKNESS, STIFFNESS, DAMPING, FRICTION, EPS, CONSTRAINT = range(6)


class Sphere(NamedTuple):
    """A moving sphere: centre c (3,) m, velocity v (3,) m/s, angular velocity w (3,) rad/s,
    radius (m), mass (kg), and its free acceleration acc (3,) m/s^2 from every other force
    (what the constraint term cancels)."""
    c: np.ndarray
    v: np.ndarray
    w: np.ndarray
    radius: float
    mass: float
    acc: np.ndarray


class Colliders(NamedTuple):
    """Rigid spheres that move along predicted paths c0 + v t + a t^2 / 2 through the substeps
    of a secondary that evaluates them itself (the sub-cycling hook): centres, velocities,
    spins, accels (k,3); radii, masses (k,); law (k,6) each one's contact law; impulses (k,7)
    receives, per advance, the impulse (N s) and angular impulse about the centre (N m s)
    the secondary exerted on each, and the peak force (N) of any substep."""
    centres: np.ndarray
    velocities: np.ndarray
    spins: np.ndarray
    accels: np.ndarray
    radii: np.ndarray
    masses: np.ndarray
    law: np.ndarray
    impulses: np.ndarray


def colliders(k: int) -> Colliders:
    """Zeroed Colliders for k spheres (an interaction fills them at every exchange)."""
    return Colliders(np.zeros((k, 3)), np.zeros((k, 3)), np.zeros((k, 3)), np.zeros((k, 3)),
                     np.zeros(k), np.zeros(k), np.zeros((k, 6)), np.zeros((k, 7)))


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
def sphere_elements(ball, pts, pt_acc, elems, law, dt, out, with_jacobian, wrench):
    """Contacts of a Sphere ``ball`` with elements of a network's Points: segments (s,2) of
    point indices, or points given as (p, p) pairs.

    Writes, into the PointForces ``out``, the forces on the elements' points (equal and
    opposite to the ball's, split by the closest-point weights; one entry per point of a
    touching element), with their 3x3 Jacobians when ``with_jacobian`` and the velocity of the
    ball's surface at the contact (what the penetration is relative to); and the total force
    (0:3) and torque about the centre (3:6) on the ball into ``wrench``. pt_acc (n,3): the
    points' accelerations from their other forces (for the constraint term). dt (s) is the
    step the forces are held for (friction's cap; <= 0: none). Returns the entries written.
    """
    c, vc, w, radius, ball_mass, ball_acc = ball
    x, v, m, _ = pts
    thickness, cs, cd, mu, eps = law[THICKNESS], law[STIFFNESS], law[DAMPING], law[FRICTION], law[EPS]
    constraint = law[CONSTRAINT] > 0.5
    for q in range(6):
        wrench[q] = 0.0
    reach = radius + thickness
    k = np.int64(0)  # not the literal 0: to_ends would compile twice (0 and int64)
    # scratch vectors, allocated once per call rather than per contact
    n = np.empty(3)
    r = np.empty(3)
    vball = np.empty(3)
    vrel = np.empty(3)
    vt = np.empty(3)
    F = np.empty(3)
    tau = np.empty(3)
    for s in range(elems.shape[0]):
        ia = elems[s, 0]
        ib = elems[s, 1]
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
        inv_m = 1.0 / ball_mass + wa * wa / m[ia] + wb * wb / m[ib]
        an = 0.0
        if constraint:
            for q in range(3):
                an += (ball_acc[q] - (wa * pt_acc[ia, q] + wb * pt_acc[ib, q])) * n[q]
        fn = normal_force(pen, vn, an, inv_m, cs, cd, constraint)
        if fn <= 0.0:
            continue
        vtn = 0.0
        for q in range(3):
            vt[q] = vrel[q] - vn * n[q]
            vtn += vt[q] * vt[q]
        vtn = np.sqrt(vtn)
        ft_scale = 0.0  # friction force = ft_scale * vt
        if vtn > 0.0:
            ft_scale = -sliding_friction(fn, vtn, mu, eps, inv_m, dt) / vtn
        for q in range(3):
            F[q] = fn * n[q] + ft_scale * vt[q]
        tau[0] = r[1] * F[2] - r[2] * F[1]
        tau[1] = r[2] * F[0] - r[0] * F[2]
        tau[2] = r[0] * F[1] - r[1] * F[0]
        for q in range(3):
            wrench[q] += F[q]
            wrench[3 + q] += tau[q]
        # Jacobians of the point forces: penalty along n; damping along n; friction in the
        # tangent plane (the law's slope where it is linear)
        visc = friction_slope(fn, vtn, mu, eps, inv_m, dt) if with_jacobian else 0.0
        k = to_ends(out, k, (ia, ib if ib != ia else -1, -1), (wa, wb, 0.0), F, n, vball,
                    (cs, cd, visc), with_jacobian)
    return k


@njit(cache=True)
def to_ends(out, k, ends, w, F, n, vref, gains, with_jacobian):
    """Write -F (N, the reaction of a contact force F on the other body) to an element's
    points (ends: up to three point indices, -1 for none; w their barycentric weights) in the
    PointForces ``out`` from entry k, with the Jacobians when ``with_jacobian``: the penalty's
    c_s and the damping's c_d along the normal n, the friction's slope visc in the tangent
    plane (gains = (c_s, c_d, visc); contact_law.friction_slope), relative to the other
    body's velocity vref. Returns the next free entry."""
    out_idx, out_f, out_dfdx, out_dfdv, out_vref = out
    cs, cd, visc = gains
    for side in range(3):
        p = ends[side]
        if p < 0:
            continue
        wgt = w[side]
        out_idx[k] = p
        for a in range(3):
            out_f[k, a] = -wgt * F[a]
        if with_jacobian:
            for a in range(3):
                out_vref[k, a] = vref[a]
                for b in range(3):
                    nn = n[a] * n[b]
                    out_dfdx[k, a, b] = -wgt * wgt * cs * nn
                    tan = (1.0 if a == b else 0.0) - nn
                    out_dfdv[k, a, b] = -wgt * wgt * (cd * nn + visc * tan)
        k += 1
    return k


@njit(cache=True)
def sphere_plane(ball, inertia, height, law, dt, skin, wrench):
    """A Sphere on the plane z = height (m, normal +z), its acc the free acceleration whose z
    part the constraint term cancels; inertia (kg m^2) its moment of inertia. Writes force
    (0:3) and torque (3:6) on the sphere; returns True on contact. Friction's cap acts through
    both the sphere's mass and its inertia (the contact point's effective mass for slip), so a
    rolling ball does not chatter; dt <= 0 disables the cap.

    skin (m): the contact is kept up to this far above the plane, where the law's spring
    pulls (c_s pen < 0) and only lightens the constraint force: a resting ball settles at
    pen = 0 with the force m g, its equilibrium inside the contact. Without it the spring on
    top of the constraint force lifted a resting ball off every other step (the basketball's
    ball on its floor hopped at up to 5.6 cm/s, pressing 1.035 m g on average)."""
    c, vc, w, radius, mass, acc = ball
    for q in range(6):
        wrench[q] = 0.0
    pen = radius - (c[2] - height)
    if pen <= -skin or (pen <= 0.0 and law[CONSTRAINT] < 0.5):
        return False
    # contact point r = (0, 0, -radius); its velocity v + w x r
    vx = vc[0] - w[1] * radius
    vy = vc[1] + w[0] * radius
    vz = vc[2]
    fn = normal_force(pen, vz, acc[2], 1.0 / mass, law[STIFFNESS], law[DAMPING],
                      law[CONSTRAINT] > 0.5)
    if fn <= 0.0:
        return False
    fx = 0.0
    fy = 0.0
    vtn = np.sqrt(vx * vx + vy * vy)
    if vtn > 0.0:
        fmag = sliding_friction(fn, vtn, law[FRICTION], law[EPS],
                                1.0 / mass + radius * radius / inertia, dt)
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


@njit(cache=True)
def points_on_plane(pts, level, law, h, out, with_jacobian):
    """Points (a network's Points) below the plane z = level (m) pushed up and held by
    friction, the law per kilogram of point mass (law's STIFFNESS in N/m per kg = 1/s^2,
    DAMPING in 1/s: every point sinks the same g / stiffness whatever its mass; no constraint
    term, no friction cap). Friction is the law's regularised Coulomb written as a saturating
    damper, -friction_damping(...) v_t.

    A point still above the plane that would pass it within the coming step of h seconds
    (z + v_z h < level; h = 0: none) is a speculative contact, or a leaf blown down at 2 m/s
    would sink 8 mm in 1/240 s before the penalty saw it. With Jacobians (an implicit network)
    it gets the spring-damper unclamped, k (level - z) - c v_z per kg, and its Jacobian: the
    implicit solve evaluates it at the step's end, where the point has reached the plane
    (the force a leaf needs to stop is shared with the rest of the leaf through its springs,
    which only the solve knows). Without (explicit substeps), the force that cuts the point's
    own approach to (level - z) / h over the step. Writes the forces (and their Jacobians when
    ``with_jacobian``) of every such point into the PointForces ``out``; returns their count
    (a point whose normal force clamps to zero gets a zero entry)."""
    x, v, m, _ = pts
    out_idx, out_f, out_dfdx, out_dfdv, out_vref = out
    k_kg, c_kg, mu, eps = law[STIFFNESS], law[DAMPING], law[FRICTION], law[EPS]
    k = 0
    for p in range(x.shape[0]):
        below = x[p, 2] < level
        ahead = not below and h > 0.0 and x[p, 2] + v[p, 2] * h < level
        if below:
            fn = m[p] * normal_force(level - x[p, 2], v[p, 2], 0.0, 1.0, k_kg, c_kg, False)
            pressing = fn > 0.0
            if not pressing:
                fn = 0.0
        elif ahead and with_jacobian:
            fn = m[p] * (k_kg * (level - x[p, 2]) - c_kg * v[p, 2])
            pressing = True
        elif ahead:
            fn = m[p] * ((level - x[p, 2]) / h - v[p, 2]) / h
            pressing = False
        else:
            continue
        vtn = np.hypot(v[p, 0], v[p, 1])
        visc = friction_damping(max(fn, 0.0), vtn, mu, eps, 1.0, 0.0)
        out_idx[k] = p
        out_f[k, 0] = -visc * v[p, 0]
        out_f[k, 1] = -visc * v[p, 1]
        out_f[k, 2] = fn
        if with_jacobian:
            for a in range(3):
                out_vref[k, a] = 0.0
                for b in range(3):
                    out_dfdx[k, a, b] = 0.0
                    out_dfdv[k, a, b] = 0.0
            if pressing:
                out_dfdx[k, 2, 2] = -m[p] * k_kg
                out_dfdv[k, 2, 2] = -m[p] * c_kg
            out_dfdv[k, 0, 0] = -visc
            out_dfdv[k, 1, 1] = -visc
        k += 1
    return k
