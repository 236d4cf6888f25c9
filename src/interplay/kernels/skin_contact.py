"""Cloth points against a moving, skinned body surface (one-way): projection with Coulomb
friction, and the exact certificates (penetration depth of points).

Notation (SI): the body's vertices X (nb,3) m and velocities V (nb,3) m/s at the end of the
step, its triangles (mb,3) wound outward; the cloth's Points (x, v, m, fixed); each point's
nearest body triangle ``tri`` (-1: none within reach), its closest point's barycentric
weights ``bary``, its signed distance ``s`` (m, negative inside) and outward normal ``nrm``
(kernels.trimesh_contact.signed_triangle_distance).
"""
from typing import NamedTuple

import numpy as np
from numba import njit, prange


class Skin(NamedTuple):
    """The body at the end of the step: vertices X (nb,3) m, velocities V (nb,3) m/s,
    triangles (mb,3)."""
    X: np.ndarray
    V: np.ndarray
    tris: np.ndarray


class Nearest(NamedTuple):
    """Each cloth point's nearest body triangle (-1 none), barycentric weights (n,3), signed
    distance s (n,) m and outward normal (n,3)."""
    tri: np.ndarray
    bary: np.ndarray
    s: np.ndarray
    nrm: np.ndarray


class Law(NamedTuple):
    """thickness (m): the gap kept between cloth and skin; friction mu (-); h (s): the step
    the velocity changes are impulses over."""
    thickness: float
    friction: float
    h: float


@njit(cache=True)
def project(pts, x0, skin, near, law, dv):
    """Resolve the step that took the points from x0 (n,3) to pts.x: every point that ended
    closer than the thickness to the skin moves out along the normal to the thickness, and
    friction acts on its slip over the step (its displacement relative to the skin's,
    tangent to the skin) in position form (Macklin et al. 2014, "Unified particle physics for
    real-time applications", section 6.1): the slip is undone when it is at most mu times the
    normal correction (sticking), else shortened by that much (sliding). Its velocity becomes
    the skin's plus that slip per step, and its own normal velocity away from the skin, if any
    (no bounce from the correction itself). dv (n,3) receives each point's velocity change
    (m/s, zero elsewhere); returns the contacts."""
    count = 0
    h = law.h
    for i in range(pts.x.shape[0]):
        dv[i, 0] = dv[i, 1] = dv[i, 2] = 0.0
        e = near.tri[i]
        if e < 0 or pts.fixed[i] or near.s[i] >= law.thickness:
            continue
        count += 1
        a, b, c = skin.tris[e, 0], skin.tris[e, 1], skin.tris[e, 2]
        w0, w1, w2 = near.bary[i, 0], near.bary[i, 1], near.bary[i, 2]
        nx, ny, nz = near.nrm[i, 0], near.nrm[i, 1], near.nrm[i, 2]
        push = law.thickness - near.s[i]
        vbx = w0 * skin.V[a, 0] + w1 * skin.V[b, 0] + w2 * skin.V[c, 0]
        vby = w0 * skin.V[a, 1] + w1 * skin.V[b, 1] + w2 * skin.V[c, 1]
        vbz = w0 * skin.V[a, 2] + w1 * skin.V[b, 2] + w2 * skin.V[c, 2]
        # the step's displacement relative to the skin's, and its tangential part
        rx = pts.x[i, 0] - x0[i, 0] - vbx * h
        ry = pts.x[i, 1] - x0[i, 1] - vby * h
        rz = pts.x[i, 2] - x0[i, 2] - vbz * h
        rn = rx * nx + ry * ny + rz * nz
        tx, ty, tz = rx - rn * nx, ry - rn * ny, rz - rn * nz
        slip = np.sqrt(tx * tx + ty * ty + tz * tz)
        cap = law.friction * push
        keep = 0.0 if slip <= cap else 1.0 - cap / slip
        # corrected end position: pushed out, slip undone or shortened
        pts.x[i, 0] += push * nx - (1.0 - keep) * tx
        pts.x[i, 1] += push * ny - (1.0 - keep) * ty
        pts.x[i, 2] += push * nz - (1.0 - keep) * tz
        # velocity: the skin's, the kept slip per step, and any normal velocity away
        ux, uy, uz = pts.v[i, 0] - vbx, pts.v[i, 1] - vby, pts.v[i, 2] - vbz
        un = max(ux * nx + uy * ny + uz * nz, 0.0)
        nvx = vbx + keep * tx / h + un * nx
        nvy = vby + keep * ty / h + un * ny
        nvz = vbz + keep * tz / h + un * nz
        dv[i, 0], dv[i, 1], dv[i, 2] = nvx - pts.v[i, 0], nvy - pts.v[i, 1], nvz - pts.v[i, 2]
        pts.v[i, 0], pts.v[i, 1], pts.v[i, 2] = nvx, nvy, nvz
    return count


#: skin edges farther than this many thicknesses from a cloth edge are not its contacts (the
#: deepest a ridge can be through an edge whose points are out: its sag, a few millimetres)
EDGE_REACH = 2.0


@njit(cache=True, inline="always")
def _lines_closest(x, a, b, X, p, q):
    """The closest points of the lines through segments (x[a], x[b]) and (X[p], X[q]): their
    parameters (s, u) along each and the squared distance (inf for parallel lines). Inside
    both segments (0 < s, u < 1) they are the segments' own closest points."""
    d10, d11, d12 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
    d20, d21, d22 = X[q, 0] - X[p, 0], X[q, 1] - X[p, 1], X[q, 2] - X[p, 2]
    r0, r1, r2 = x[a, 0] - X[p, 0], x[a, 1] - X[p, 1], x[a, 2] - X[p, 2]
    A = d10 * d10 + d11 * d11 + d12 * d12
    E = d20 * d20 + d21 * d21 + d22 * d22
    B = d10 * d20 + d11 * d21 + d12 * d22
    C = d10 * r0 + d11 * r1 + d12 * r2
    F = d20 * r0 + d21 * r1 + d22 * r2
    den = A * E - B * B
    if den <= 1e-12 * A * E:
        return -1.0, -1.0, np.inf
    s = (B * F - C * E) / den
    u = (A * F - B * C) / den
    e0, e1, e2 = r0 + s * d10 - u * d20, r1 + s * d11 - u * d21, r2 + s * d12 - u * d22
    return s, u, e0 * e0 + e1 * e1 + e2 * e2


@njit(cache=True)
def _deepest_edge(pts, a, b, skin, across, tri, reach, cand):
    """The skin edge nearest cloth edge (a, b) along its pseudonormal, among the edges of the
    triangles its points found (tri) and the triangles across their edges, whose closest
    points to it lie strictly inside both segments (a corner's contact is a point's) and within
    ``reach`` (m) of it. Returns (signed gap along the normal, m: inf if none; s, u: the
    closest points' parameters on the cloth and skin edges; the skin edge's ends p, q; its
    unit pseudonormal)."""
    nc = 0
    for t0 in (tri[a], tri[b]):
        for j in range(-1, 3):
            t = t0 if j < 0 else across[t0, j]
            seen = t < 0
            for c in range(nc):
                seen = seen or cand[c] == t
            if not seen:
                cand[nc] = t
                nc += 1
    best, bs, bu, bp, bq, m0, m1, m2 = np.inf, 0.0, 0.0, -1, -1, 0.0, 0.0, 0.0
    x = pts.x
    for c in range(nc):
        t = cand[c]
        for j in range(3):
            p, q = skin.tris[t, j], skin.tris[t, (j + 1) % 3]
            sc, uc, d2 = _lines_closest(x, a, b, skin.X, p, q)
            if sc <= 0.0 or sc >= 1.0 or uc <= 0.0 or uc >= 1.0 or d2 > reach * reach:
                continue
            if across[t, j] < 0:
                continue
            # the edge's pseudonormal: the sum of its two faces' normals (exact for the side
            # of a point whose closest feature is the edge; Baerentzen & Aanaes 2005)
            f = _face_normal(skin.X, skin.tris, t)
            g = _face_normal(skin.X, skin.tris, across[t, j])
            n0, n1, n2 = f[0] + g[0], f[1] + g[1], f[2] + g[2]
            nl = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            if nl == 0.0:
                continue
            gap = 0.0
            for r, nr in ((0, n0), (1, n1), (2, n2)):
                gap += ((1.0 - sc) * x[a, r] + sc * x[b, r]
                        - (1.0 - uc) * skin.X[p, r] - uc * skin.X[q, r]) * nr / nl
            if gap < best:
                best, bs, bu, bp, bq = gap, sc, uc, p, q
                m0, m1, m2 = n0 / nl, n1 / nl, n2 / nl
    return best, bs, bu, bp, bq, np.array((m0, m1, m2))


@njit(cache=True, parallel=True)
def _edges_near(pts, edges, skin, across, tri, s, law, out):
    """out (k,) bool: the cloth edges (edges (k,2)) that ``project_edges`` resolves (both
    points found a skin triangle, not both fixed, a skin edge nearer than the thickness).
    In parallel over chunks of edges: the look is most of the cost, and few are near."""
    chunk = 1024
    for c in prange((edges.shape[0] + chunk - 1) // chunk):
        cand = np.empty(8, np.int64)
        for k in range(c * chunk, min(edges.shape[0], (c + 1) * chunk)):
            a, b = edges[k, 0], edges[k, 1]
            out[k] = False
            if tri[a] < 0 or tri[b] < 0 or (pts.fixed[a] and pts.fixed[b]):
                continue
            # a skin edge within REACH of the edge's point at t is within t L + REACH of a
            # and (1 - t) L + REACH of b, neither nearer than its own nearest skin point (s,
            # before the point contact put it out: no farther)
            L = np.sqrt((pts.x[a, 0] - pts.x[b, 0]) ** 2 + (pts.x[a, 1] - pts.x[b, 1]) ** 2
                        + (pts.x[a, 2] - pts.x[b, 2]) ** 2)
            if s[a] + s[b] >= L + 2.0 * EDGE_REACH * law.thickness:
                continue
            gap = _deepest_edge(pts, a, b, skin, across, tri, EDGE_REACH * law.thickness, cand)[0]
            out[k] = gap < law.thickness


@njit(cache=True)
def project_edges(pts, x0, edges, skin, across, near, law, dv):
    """Edge-edge contacts, after ``project`` has put every point out: a skin ridge can still
    pass between a cloth edge's two points (the edge sags through it while both points are
    outside). Each cloth edge (a, b) (edges (k,2)) whose points both found a skin triangle
    (near: the points' Nearest, before ``project``) is
    held off its deepest skin edge (``_deepest_edge``, within EDGE_REACH thicknesses) by the
    thickness along that edge's pseudonormal n: its two points move along n in proportion to
    their weights at the closest point (1 - s, s; a fixed point does not move), so that the
    closest point moves out by the missing gap; friction acts on that point's slip over the
    step as in ``project`` (undone up to mu times the push, distributed the same way). Each
    point loses the part of its velocity relative to the skin that approaches it along n, and
    takes the friction's change per step. dv (n,3) receives the velocity changes (added);
    returns the contacts. An edge with a fixed end is held only where its closest point is
    on its free half (nearer the fixed end, its free point would move more than twice the
    push). The edges near are found in parallel (``_edges_near``), then resolved in turn."""
    count = 0
    h = law.h
    cand = np.empty(8, np.int64)
    tri = near.tri
    close = np.empty(edges.shape[0], np.bool_)
    _edges_near(pts, edges, skin, across, tri, near.s, law, close)
    for k in np.flatnonzero(close):
        a, b = edges[k, 0], edges[k, 1]
        gap, s, u, p, q, n = _deepest_edge(pts, a, b, skin, across, tri,
                                           EDGE_REACH * law.thickness, cand)
        wa = 0.0 if pts.fixed[a] else 1.0 - s
        wb = 0.0 if pts.fixed[b] else s
        if gap >= law.thickness or wa * wa + wb * wb < 0.25:
            continue
        count += 1
        lam = 1.0 / (wa * wa + wb * wb)  # a move m of the closest point: wa lam m, wb lam m
        push = law.thickness - gap
        # the closest point's slip over the step relative to the skin's, tangent to it
        slip = np.empty(3)
        vs = np.empty(3)
        for r in range(3):
            vs[r] = (1.0 - u) * skin.V[p, r] + u * skin.V[q, r]
            slip[r] = ((1.0 - s) * (pts.x[a, r] - x0[a, r]) + s * (pts.x[b, r] - x0[b, r])
                       - vs[r] * h)
        sn = slip[0] * n[0] + slip[1] * n[1] + slip[2] * n[2]
        slip -= sn * n
        length = np.sqrt(slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2])
        cap = law.friction * push
        undo = 1.0 if length <= cap else cap / length
        for i, w in ((a, wa), (b, wb)):
            if w == 0.0:
                continue
            for r in range(3):
                move = w * lam * (push * n[r] - undo * slip[r])
                pts.x[i, r] += move
            un = 0.0
            for r in range(3):
                un += (pts.v[i, r] - vs[r]) * n[r]
            for r in range(3):
                dvr = -min(un, 0.0) * n[r] - w * lam * undo * slip[r] / h
                pts.v[i, r] += dvr
                dv[i, r] += dvr
    return count


@njit(cache=True)
def reaction(x, m, dv, h, centre):
    """Force (N) and torque (N m, about centre) the cloth's velocity changes dv over h put on
    the body: minus the cloth's momentum change per time."""
    f = np.zeros(3)
    tau = np.zeros(3)
    for i in range(x.shape[0]):
        if dv[i, 0] == 0.0 and dv[i, 1] == 0.0 and dv[i, 2] == 0.0:
            continue
        fx, fy, fz = -m[i] * dv[i, 0] / h, -m[i] * dv[i, 1] / h, -m[i] * dv[i, 2] / h
        f[0] += fx
        f[1] += fy
        f[2] += fz
        rx, ry, rz = x[i, 0] - centre[0], x[i, 1] - centre[1], x[i, 2] - centre[2]
        tau[0] += ry * fz - rz * fy
        tau[1] += rz * fx - rx * fz
        tau[2] += rx * fy - ry * fx
    return f, tau


@njit(cache=True)
def vertex_normals(X, tris, out):
    """Angle-weighted unit vertex normals (nb,3) of a closed outward-wound mesh: each face's
    unit normal weighted by its angle at the vertex, the pseudonormal whose side test is
    exact at a vertex (Baerentzen & Aanaes 2005, "Signed distance computation using the
    angle weighted pseudonormal")."""
    out[:] = 0.0
    for t in range(tris.shape[0]):
        a, b, c = tris[t, 0], tris[t, 1], tris[t, 2]
        ux, uy, uz = X[b, 0] - X[a, 0], X[b, 1] - X[a, 1], X[b, 2] - X[a, 2]
        vx, vy, vz = X[c, 0] - X[a, 0], X[c, 1] - X[a, 1], X[c, 2] - X[a, 2]
        nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        nl = np.sqrt(nx * nx + ny * ny + nz * nz)
        if nl == 0.0:
            continue
        nx, ny, nz = nx / nl, ny / nl, nz / nl
        for j in range(3):
            k, k1, k2 = tris[t, j], tris[t, (j + 1) % 3], tris[t, (j + 2) % 3]
            ex, ey, ez = X[k1, 0] - X[k, 0], X[k1, 1] - X[k, 1], X[k1, 2] - X[k, 2]
            fx, fy, fz = X[k2, 0] - X[k, 0], X[k2, 1] - X[k, 1], X[k2, 2] - X[k, 2]
            le = np.sqrt(ex * ex + ey * ey + ez * ez) * np.sqrt(fx * fx + fy * fy + fz * fz)
            if le == 0.0:
                continue
            angle = np.arccos(min(1.0, max(-1.0, (ex * fx + ey * fy + ez * fz) / le)))
            out[k, 0] += angle * nx
            out[k, 1] += angle * ny
            out[k, 2] += angle * nz
    for k in range(out.shape[0]):
        n = np.sqrt(out[k, 0] ** 2 + out[k, 1] ** 2 + out[k, 2] ** 2)
        if n > 0.0:
            out[k, 0] /= n
            out[k, 1] /= n
            out[k, 2] /= n


CORNER = 1e-9  # a barycentric weight below this puts the closest point on an edge or corner


def edge_neighbours(tris) -> np.ndarray:
    """(mb,3) int64: the triangle across each triangle's edge j (from corner j to corner j+1)
    of a closed mesh (every edge in two triangles)."""
    tris = np.asarray(tris, np.int64)
    m = len(tris)
    a = tris.ravel()
    b = np.roll(tris, -1, axis=1).ravel()
    owner = np.repeat(np.arange(m), 3)
    key = np.minimum(a, b) * (int(tris.max()) + 1) + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    k = key[order]
    out = np.full(3 * m, -1, np.int64)
    pair = np.flatnonzero(k[1:] == k[:-1])
    out[order[pair]] = owner[order[pair + 1]]
    out[order[pair + 1]] = owner[order[pair]]
    return out.reshape(m, 3)


@njit(cache=True)
def _face_normal(X, tris, t):
    a, b, c = tris[t, 0], tris[t, 1], tris[t, 2]
    ux, uy, uz = X[b, 0] - X[a, 0], X[b, 1] - X[a, 1], X[b, 2] - X[a, 2]
    vx, vy, vz = X[c, 0] - X[a, 0], X[c, 1] - X[a, 1], X[c, 2] - X[a, 2]
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    nl = np.sqrt(nx * nx + ny * ny + nz * nz)
    if nl > 0.0:
        return nx / nl, ny / nl, nz / nl
    return 0.0, 0.0, 0.0


@njit(cache=True)
def signed_distance(pts, tri, bary, dist, X, tris, across, vn, out_s, out_n):
    """Signed distance (m, negative inside) and outward normal of each point from its
    nearest skin triangle (tri[i] >= 0; closest point by bary). The side is told by the
    pseudonormal of the feature the closest point lies on, which is exact for a closed mesh
    (Baerentzen & Aanaes 2005): inside a face, its normal; on an edge, the sum of its two
    faces' normals (``across``: edge_neighbours); at a corner, the angle-weighted vertex
    normal ``vn`` (vertex_normals). A face's normal alone gives the wrong side at an edge or
    corner in a crease (armpit, crotch); vertex normals interpolated over the triangle gave
    it off a thin part's tip (a point 4 cm from a hand told 4 cm inside)."""
    for i in range(pts.shape[0]):
        e = tri[i]
        if e < 0:
            out_s[i] = np.inf
            continue
        a, b, c = tris[e, 0], tris[e, 1], tris[e, 2]
        w0, w1, w2 = bary[i, 0], bary[i, 1], bary[i, 2]
        on = (w0 > CORNER) + (w1 > CORNER) + (w2 > CORNER)
        mx, my, mz = _face_normal(X, tris, e)
        if on == 2:  # on the edge opposite the corner whose weight is zero
            j = 1 if w0 <= CORNER else (2 if w1 <= CORNER else 0)
            if across[e, j] >= 0:
                ox, oy, oz = _face_normal(X, tris, across[e, j])
                mx, my, mz = mx + ox, my + oy, mz + oz
        elif on == 1:  # at a corner
            k = a if w0 > CORNER else (b if w1 > CORNER else c)
            mx, my, mz = vn[k, 0], vn[k, 1], vn[k, 2]
        ml = np.sqrt(mx * mx + my * my + mz * mz)
        if ml > 0.0:
            mx, my, mz = mx / ml, my / ml, mz / ml
        d = dist[i]
        px = w0 * X[a, 0] + w1 * X[b, 0] + w2 * X[c, 0]
        py = w0 * X[a, 1] + w1 * X[b, 1] + w2 * X[c, 1]
        pz = w0 * X[a, 2] + w1 * X[b, 2] + w2 * X[c, 2]
        if d > 1e-12:
            ux, uy, uz = (pts[i, 0] - px) / d, (pts[i, 1] - py) / d, (pts[i, 2] - pz) / d
            sign = -1.0 if ux * mx + uy * my + uz * mz < 0.0 else 1.0
            out_s[i] = sign * d
            out_n[i, 0], out_n[i, 1], out_n[i, 2] = sign * ux, sign * uy, sign * uz
        else:
            out_s[i] = 0.0
            out_n[i, 0], out_n[i, 1], out_n[i, 2] = mx, my, mz
