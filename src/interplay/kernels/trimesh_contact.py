"""Contact geometry and response for triangle meshes and simple shapes (SPEC 2.5).

Geometry: the closest point of a triangle, closest points of two segments, whether two
triangles intersect, signed distances to a plane, box, sphere and capsule.
Response (``respond``, per contact): the one contact law (``contact_law``): the stabilised
penalty normal force with the constraint term, and Coulomb friction that sticks through a
tangential spring below the cone (a block on a slope flatter than atan(mu) then holds instead
of creeping), with stiffness and damping chosen from each contact's effective mass when not
given.
"""
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from .contact import CONSTRAINT, DAMPING, EPS, FRICTION, STIFFNESS
from .contact_law import normal_force, sticking_friction


class Contacts(NamedTuple):
    """c contacts seen from their point side: n (c,3) unit normals towards it, pen (c,)
    penetrations (m), vrel, arel (c,3) its velocity (m/s) and acceleration (m/s^2) relative to
    the other side, inv_m (c,) the pair's inverse effective mass along n (1/kg)."""
    n: np.ndarray
    pen: np.ndarray
    vrel: np.ndarray
    arel: np.ndarray
    inv_m: np.ndarray


class ContactForces(NamedTuple):
    """Forces on the point side of c contacts: f (c,3) N and their Jacobians with respect to
    its position jx (c,3,3) N/m and velocity jv (c,3,3) N s/m."""
    f: np.ndarray
    jx: np.ndarray
    jv: np.ndarray


@njit(cache=True, inline="always")
def _dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@njit(cache=True)
def closest_on_triangle(p, a, b, c):
    """Barycentric weights (u, v, w) of the point of triangle abc closest to p, and the squared
    distance (Ericson, Real-Time Collision Detection 5.1.5: Voronoi regions of the features).
    Scalar arithmetic only: this runs for every leaf a query reaches, and temporary arrays
    would dominate its cost."""
    abx, aby, abz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    acx, acy, acz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    apx, apy, apz = p[0] - a[0], p[1] - a[1], p[2] - a[2]
    d1 = _dot(abx, aby, abz, apx, apy, apz)
    d2 = _dot(acx, acy, acz, apx, apy, apz)
    if d1 <= 0.0 and d2 <= 0.0:
        u, v, w = 1.0, 0.0, 0.0
    else:
        bpx, bpy, bpz = p[0] - b[0], p[1] - b[1], p[2] - b[2]
        d3 = _dot(abx, aby, abz, bpx, bpy, bpz)
        d4 = _dot(acx, acy, acz, bpx, bpy, bpz)
        vc = d1 * d4 - d3 * d2
        if d3 >= 0.0 and d4 <= d3:
            u, v, w = 0.0, 1.0, 0.0
        elif vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
            t = d1 / (d1 - d3)
            u, v, w = 1.0 - t, t, 0.0
        else:
            cpx, cpy, cpz = p[0] - c[0], p[1] - c[1], p[2] - c[2]
            d5 = _dot(abx, aby, abz, cpx, cpy, cpz)
            d6 = _dot(acx, acy, acz, cpx, cpy, cpz)
            vb = d5 * d2 - d1 * d6
            va = d3 * d6 - d5 * d4
            if d6 >= 0.0 and d5 <= d6:
                u, v, w = 0.0, 0.0, 1.0
            elif vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
                t = d2 / (d2 - d6)
                u, v, w = 1.0 - t, 0.0, t
            elif va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
                t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
                u, v, w = 0.0, 1.0 - t, t
            else:
                den = va + vb + vc
                v = vb / den
                w = vc / den
                u = 1.0 - v - w
    dx = p[0] - (u * a[0] + v * b[0] + w * c[0])
    dy = p[1] - (u * a[1] + v * b[1] + w * c[1])
    dz = p[2] - (u * a[2] + v * b[2] + w * c[2])
    return u, v, w, dx * dx + dy * dy + dz * dz


@njit(cache=True)
def closest_segments(p1, q1, p2, q2):
    """Parameters (s, t) in [0,1] of the closest points p1 + s (q1-p1), p2 + t (q2-p2) of two
    segments and their squared distance (Ericson 5.1.9; parallel segments handled)."""
    d1 = q1 - p1
    d2 = q2 - p2
    r = p1 - p2
    a = d1 @ d1
    e = d2 @ d2
    f = d2 @ r
    tiny = 1e-30
    if a <= tiny and e <= tiny:
        s, t = 0.0, 0.0
    elif a <= tiny:
        s, t = 0.0, min(1.0, max(0.0, f / e))
    else:
        c = d1 @ r
        if e <= tiny:
            s, t = min(1.0, max(0.0, -c / a)), 0.0
        else:
            b = d1 @ d2
            den = a * e - b * b
            s = min(1.0, max(0.0, (b * f - c * e) / den)) if den > 1e-14 * a * e else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t, s = 0.0, min(1.0, max(0.0, -c / a))
            elif t > 1.0:
                t, s = 1.0, min(1.0, max(0.0, (b - c) / a))
    d = (p1 + s * d1) - (p2 + t * d2)
    return s, t, d @ d


@njit(cache=True, inline="always")
def _orient(a, b, c, d):
    """Six times the signed volume of tetrahedron abcd (> 0: d above the plane abc): (b - a)
    x (c - a) . (d - a). Scalar arithmetic: this runs twelve times for every candidate pair
    of every frame's certificate, and NumPy's cross and dot allocated three arrays a call."""
    ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    wx, wy, wz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    return _dot(uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx,
                d[0] - a[0], d[1] - a[1], d[2] - a[2])


@njit(cache=True)
def _edge_hits(p, q, a, b, c):
    o1 = _orient(a, b, c, p)
    o2 = _orient(a, b, c, q)
    if (o1 > 0.0 and o2 > 0.0) or (o1 < 0.0 and o2 < 0.0) or (o1 == 0.0 and o2 == 0.0):
        return False
    s1 = _orient(p, q, a, b)
    s2 = _orient(p, q, b, c)
    s3 = _orient(p, q, c, a)
    return (s1 >= 0.0 and s2 >= 0.0 and s3 >= 0.0) or (s1 <= 0.0 and s2 <= 0.0 and s3 <= 0.0)


@njit(cache=True)
def triangles_intersect(a0, a1, a2, b0, b1, b2):
    """True when two non-coplanar triangles (closed sets) intersect: then an edge of one
    crosses the other (the intersection segment ends on the triangles' boundaries). Coplanar
    pairs report False: they touch without interpenetrating, which the proximity contacts
    handle."""
    return (_edge_hits(a0, a1, b0, b1, b2) or _edge_hits(a1, a2, b0, b1, b2)
            or _edge_hits(a2, a0, b0, b1, b2) or _edge_hits(b0, b1, a0, a1, a2)
            or _edge_hits(b1, b2, a0, a1, a2) or _edge_hits(b2, b0, a0, a1, a2))


@njit(cache=True, parallel=True)
def intersecting_pairs(xa, ta, xb, tb, pairs, out):
    """out[i] = whether triangle pairs[i,0] of mesh a intersects pairs[i,1] of mesh b."""
    for i in prange(pairs.shape[0]):
        s, t = ta[pairs[i, 0]], tb[pairs[i, 1]]
        out[i] = triangles_intersect(xa[s[0]], xa[s[1]], xa[s[2]], xb[t[0]], xb[t[1]], xb[t[2]])


@njit(cache=True)
def edge_pairs_within(xa, ea, xb, eb, pairs, reach, out_st, out_d):
    """Closest points (s, t) and distance of segment pairs (pairs[i] = (ea row, eb row));
    distance inf when farther than reach (m)."""
    for i in range(pairs.shape[0]):
        u, w = ea[pairs[i, 0]], eb[pairs[i, 1]]
        s, t, d2 = closest_segments(xa[u[0]], xa[u[1]], xb[w[0]], xb[w[1]])
        out_st[i, 0], out_st[i, 1] = s, t
        out_d[i] = np.sqrt(d2) if d2 <= reach * reach else np.inf


@njit(cache=True, parallel=True)
def signed_triangle_distance(pts, tri, bary, dist, x, tris, signed, out_s, out_n):
    """Signed distance and outward contact normal of each point from its nearest triangle
    (tri[i] >= 0, closest point given by bary). signed: the triangle's winding gives its
    outside (closed or one-sided meshes: a point behind the face is inside, s < 0); otherwise
    the normal points from the triangle to the point, s = distance. Scalar arithmetic: no
    temporaries per point."""
    for i in prange(pts.shape[0]):
        e = tri[i]
        if e < 0:
            continue
        ia, ib, ic = tris[e, 0], tris[e, 1], tris[e, 2]
        abx, aby, abz = x[ib, 0] - x[ia, 0], x[ib, 1] - x[ia, 1], x[ib, 2] - x[ia, 2]
        acx, acy, acz = x[ic, 0] - x[ia, 0], x[ic, 1] - x[ia, 1], x[ic, 2] - x[ia, 2]
        nx, ny, nz = aby * acz - abz * acy, abz * acx - abx * acz, abx * acy - aby * acx
        nl = np.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / nl, ny / nl, nz / nl
        d = dist[i]
        if d > 1e-9 * (1.0 + np.sqrt(abx * abx + aby * aby + abz * abz)):
            b0, b1, b2 = bary[i, 0], bary[i, 1], bary[i, 2]
            ux = (pts[i, 0] - (b0 * x[ia, 0] + b1 * x[ib, 0] + b2 * x[ic, 0])) / d
            uy = (pts[i, 1] - (b0 * x[ia, 1] + b1 * x[ib, 1] + b2 * x[ic, 1])) / d
            uz = (pts[i, 2] - (b0 * x[ia, 2] + b1 * x[ib, 2] + b2 * x[ic, 2])) / d
            sign = -1.0 if signed and ux * nx + uy * ny + uz * nz < 0.0 else 1.0
            out_s[i] = sign * d
            out_n[i, 0], out_n[i, 1], out_n[i, 2] = sign * ux, sign * uy, sign * uz
        else:
            out_s[i] = 0.0
            out_n[i, 0], out_n[i, 1], out_n[i, 2] = nx, ny, nz


@njit(cache=True, parallel=True)
def box_distance(pts, centre, R, half, out_s, out_n):
    """Signed distance (m) and outward normal of points from a box (centre, rotation R whose
    columns are its axes, half extents)."""
    for i in prange(pts.shape[0]):
        loc = R.T @ (pts[i] - centre)
        q = np.abs(loc) - half
        if q.max() > 0.0:
            cl = np.maximum(q, 0.0)
            d = np.sqrt(cl @ cl)
            g = np.sign(loc) * cl / d
            out_s[i] = d
        else:
            ax = int(np.argmax(q))
            g = np.zeros(3)
            g[ax] = 1.0 if loc[ax] >= 0.0 else -1.0
            out_s[i] = q[ax]
        out_n[i] = R @ g


@njit(cache=True, parallel=True)
def capsule_distance(pts, a, b, radius, out_s, out_n):
    """Signed distance (m) and outward normal of points from a capsule (segment ab, radius m);
    a == b is a sphere."""
    ab = b - a
    L2 = ab @ ab
    for i in prange(pts.shape[0]):
        t = 0.0 if L2 <= 0.0 else min(1.0, max(0.0, ((pts[i] - a) @ ab) / L2))
        u = pts[i] - (a + t * ab)
        d = np.sqrt(u @ u)
        out_s[i] = d - radius
        if d > 0.0:
            out_n[i] = u / d
        else:
            out_n[i, 0], out_n[i, 1], out_n[i, 2] = 0.0, 0.0, 1.0


@njit(cache=True)
def respond(contacts, law, omega, dt, stretch, out):
    """The contact law on each of the Contacts: writes force and its 3x3 Jacobians (d/dx, d/dv
    of the point side) into the ContactForces ``out``; returns the active mask. law (6,): see
    ``contact``; its STIFFNESS (N/m) and DAMPING (N s/m) < 0 choose them from the pair's mass
    and the step: c_s = m_eff omega^2, c_d = 2 m_eff omega (critically damped: no bounce),
    omega (rad/s) well below 1/dt (s) so the held force stays stable. stretch (c,3) m: each
    contact's tangential spring, updated in place (zero for a new contact)."""
    nrm, pen, vrel, arel, inv_m = contacts
    out_f, out_jx, out_jv = out
    stiffness, damping, mu, eps = law[STIFFNESS], law[DAMPING], law[FRICTION], law[EPS]
    constraint = law[CONSTRAINT] > 0.5
    nc = nrm.shape[0]
    active = np.zeros(nc, np.bool_)
    ft = np.empty(3)
    for i in range(nc):
        n = nrm[i]
        meff = 1.0 / inv_m[i]
        cs = stiffness if stiffness >= 0.0 else meff * omega * omega
        cd = damping if damping >= 0.0 else 2.0 * meff * omega
        vn = vrel[i] @ n
        fn = normal_force(pen[i], vn, arel[i] @ n, inv_m[i], cs, cd, constraint)
        out_f[i] = 0.0
        out_jx[i] = 0.0
        out_jv[i] = 0.0
        if fn <= 0.0:
            continue
        active[i] = True
        # the stretch is shared by all contacts of a rigid body, so contacts far from their cap
        # take up the load those at it cannot: a block sticks whenever mu N suffices
        stick, visc = sticking_friction(n, vrel[i] - vn * n, fn, cs, cd, mu, eps, meff, dt,
                                        stretch[i], ft)
        out_f[i] = fn * n + ft
        for a in range(3):
            for b in range(3):
                nn = n[a] * n[b]
                tan = (1.0 if a == b else 0.0) - nn
                out_jx[i, a, b] = -cs * nn - stick * tan
                out_jv[i, a, b] = -cd * nn - visc * tan
    return active
