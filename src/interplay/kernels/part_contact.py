"""Rigid parts (spheres, capsules, boxes: a ball, a figure's segments) against a spring-mass
network's segments, points or faces, through the one contact law (SPEC 2.5).

The parts move along predicted paths through a coupling step of h: centre of mass
c0 + v t + a t^2 / 2 and rotation exp([w t]) R0, their own forces changing those paths by far
less than the network's points move (a gymnast's foot under 8 body weights gains 0.08 m/s in
1 ms; a bed point of 27 g is thrown across its contact skin in a fraction of that). So a light,
stiff network can integrate the contact inside its own substeps (kernels/subcycle.py), while
each part receives the step's impulse: equal and opposite to what the points received, and
momentum is conserved exactly.

Geometry per (part, element) in kernels/primitive_distance.py. A network's element is a
segment (a spring, a triangle's edge) given as (a, b, -1), a point as (p, p, -1), or a
triangle's face as (a, b, c), against which each of the part's features (a box's corners, a
capsule's ends) is a contact of its own, its force shared by the face's three points by the
foot's barycentric weights. Units SI; normals point from the element towards the part.
"""
from typing import NamedTuple

import numpy as np
from numba import njit

from .contact import CONSTRAINT, DAMPING, EPS, FRICTION, STIFFNESS, THICKNESS, to_ends
from .contact_law import friction_damping, normal_force, sliding_friction, sticking_friction
from .primitive_distance import BOX, CAPSULE, SPHERE, closest, face_feature, features

KINDS = {"sphere": SPHERE, "capsule": CAPSULE, "box": BOX}


class Parts(NamedTuple):
    """k rigid parts and the network elements they may touch in one coupling step.

    Primitive in each part's frame, relative to its centre of mass: kind (k,) SPHERE, CAPSULE
    or BOX; p (k,3) a sphere's or box's centre or a capsule's first end (m); q (k,3) a
    capsule's second end (m), or in q[0] a box's rounding: its edges and corners rounded by
    that radius (m; 0: sharp); size (k,3) the radius in [0] (sphere, capsule) or a box's half
    extents (m, the rounding within them); reach (k,) m the primitive's farthest point from
    the centre of mass.
    Motion at the step's start: centres (k,3) m, rotations (k,3,3) part to world, velocities
    (k,3) m/s, spins (k,3) rad/s, accels (k,3) m/s^2; masses (k,) kg; law (k,6) each part's
    contact law (kernels/contact.py; STIFFNESS, DAMPING < 0: from the pair's mass, resolving
    a penetration over ``steps`` substeps, critically damped); golden: a box's golden-section
    steps along a segment (primitive_distance.closest). elems (s,3) the network's
    elements (module docstring); start (k+1,), cand (c,) candidate elements of each part
    (``candidates``).
    Out: impulses (k,7) impulse (N s), angular impulse about the centre of mass (N m s) and
    peak force (N) per part over the step; peak (1,) the largest total force (N) of any
    substep; received (3,) the impulse (N s) the network's points received (minus the parts'
    sum: the exchange is equal and opposite).
    Sticking friction (``touch_forces``) when stretch has a row per network point, else it is
    (k,0,3) and the friction is the regularised law: stretch (k,n,3) m, each point's
    tangential spring to where it first held on part k; stamp (k,n) the call of
    ``touch_forces`` that last set it, clock (1,) the calls so far; sums (k,n,3) and weights
    (k,n) the calls' scratch (zero between calls)."""
    kind: np.ndarray
    p: np.ndarray
    q: np.ndarray
    size: np.ndarray
    reach: np.ndarray
    centres: np.ndarray
    rotations: np.ndarray
    velocities: np.ndarray
    spins: np.ndarray
    accels: np.ndarray
    masses: np.ndarray
    law: np.ndarray
    steps: float
    golden: int
    elems: np.ndarray
    start: np.ndarray
    cand: np.ndarray
    impulses: np.ndarray
    peak: np.ndarray
    received: np.ndarray
    stretch: np.ndarray
    stamp: np.ndarray
    clock: np.ndarray
    sums: np.ndarray
    weights: np.ndarray


@njit(cache=True)
def _primitive_box(parts, j, c, R, lo, hi):
    """The world box (lo, hi) of part j's primitive with its centre of mass at c, rotation R."""
    kind, p, q, size = parts.kind[j], parts.p[j], parts.q[j], parts.size[j]
    for r in range(3):
        a = c[r] + R[r, 0] * p[0] + R[r, 1] * p[1] + R[r, 2] * p[2]
        if kind == BOX:
            ext = abs(R[r, 0]) * size[0] + abs(R[r, 1]) * size[1] + abs(R[r, 2]) * size[2]
            lo[r], hi[r] = a - ext, a + ext
        elif kind == CAPSULE:
            b = c[r] + R[r, 0] * q[0] + R[r, 1] * q[1] + R[r, 2] * q[2]
            lo[r], hi[r] = min(a, b) - size[0], max(a, b) + size[0]
        else:
            lo[r], hi[r] = a - size[0], a + size[0]


@njit(cache=True)
def candidates(parts, x, v, h, margin):
    """Fill parts.start / parts.cand with, per part, the elements whose bounding box meets the
    box its primitive sweeps over h (s): its boxes at the step's start and end (the spin's
    turn bounded by |w| h reach), grown by the contact skin, by how far the network's points
    move in h at their fastest and by ``margin`` (m). Returns the total count; parts away from
    the network's box are skipped whole, so flight costs a box test per part. The elements'
    boxes are computed once and sorted along x, so a part tests only those in its x slab (a
    body lying on a bed tested all 1,650 of the bed's edges and faces per part, 37% of the
    trampoline's run); each part's candidates are kept in element order, as a full scan
    gives them (the same sums, to the bit)."""
    elems, start, cand = parts.elems, parts.start, parts.cand
    n = x.shape[0]
    nlo = np.empty(3)
    nhi = np.empty(3)
    vmax = 0.0
    for r in range(3):
        nlo[r] = x[0, r]
        nhi[r] = x[0, r]
    for i in range(n):
        s2 = 0.0
        for r in range(3):
            nlo[r] = min(nlo[r], x[i, r])
            nhi[r] = max(nhi[r], x[i, r])
            s2 += v[i, r] * v[i, r]
        vmax = max(vmax, s2)
    grow = np.sqrt(vmax) * h + margin
    lo, hi, lo1, hi1 = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    c1 = np.empty(3)
    k = 0
    boxes = False  # the elements' boxes, computed when a part first comes near the network
    ne = elems.shape[0]
    elo, ehi = np.empty((ne, 3)), np.empty((ne, 3))
    order = np.empty(ne, np.int64)
    xlo = np.empty(ne)
    wide = 0.0  # the widest element along x
    for j in range(parts.kind.shape[0]):
        start[j] = k
        R = parts.rotations[j]
        _primitive_box(parts, j, parts.centres[j], R, lo, hi)
        w = parts.spins[j]
        turn = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * h * parts.reach[j]
        for r in range(3):
            c1[r] = (parts.centres[j, r] + parts.velocities[j, r] * h
                     + 0.5 * parts.accels[j, r] * h * h)
        _primitive_box(parts, j, c1, R, lo1, hi1)
        pad = parts.law[j, THICKNESS] + grow + turn
        far = False
        for r in range(3):
            lo[r] = min(lo[r], lo1[r]) - pad
            hi[r] = max(hi[r], hi1[r]) + pad
            if hi[r] < nlo[r] or lo[r] > nhi[r]:
                far = True
        if far:
            continue
        if not boxes:
            _element_boxes(x, elems, elo, ehi)
            order[:] = np.argsort(elo[:, 0])
            xlo[:] = elo[order, 0]
            wide = (ehi[:, 0] - elo[:, 0]).max() if ne else 0.0
            boxes = True
        first = k
        for q in range(np.searchsorted(xlo, lo[0] - wide), np.searchsorted(xlo, hi[0], "right")):
            e = order[q]
            if (ehi[e, 0] >= lo[0] and ehi[e, 1] >= lo[1] and elo[e, 1] <= hi[1]
                    and ehi[e, 2] >= lo[2] and elo[e, 2] <= hi[2]):
                cand[k] = e
                k += 1
        cand[first:k].sort()
    start[parts.kind.shape[0]] = k
    return k


@njit(cache=True)
def _element_boxes(x, elems, elo, ehi):
    """Each element's bounding box (lo, hi) over its points (-1: none) into elo, ehi (s,3)."""
    for e in range(elems.shape[0]):
        for r in range(3):
            elo[e, r] = x[elems[e, 0], r]
            ehi[e, r] = x[elems[e, 0], r]
        for s_ in range(1, 3):
            p = elems[e, s_]
            if p >= 0:
                for r in range(3):
                    elo[e, r] = min(elo[e, r], x[p, r])
                    ehi[e, r] = max(ehi[e, r], x[p, r])


@njit(cache=True)
def pose_at(parts, j, tau, c, R):
    """The part's predicted centre of mass c (3,) and rotation R (3,3) at tau (s) into the
    step: c0 + v tau + a tau^2 / 2, and R0 turned by the spin over tau (Rodrigues)."""
    w = parts.spins[j]
    R0 = parts.rotations[j]
    for r in range(3):
        c[r] = (parts.centres[j, r] + parts.velocities[j, r] * tau
                + 0.5 * parts.accels[j, r] * tau * tau)
    wn = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    th = wn * tau
    if th < 1e-12:
        for a in range(3):
            for b in range(3):
                R[a, b] = R0[a, b]
        return
    kx, ky, kz = w[0] / wn, w[1] / wn, w[2] / wn
    s, cm = np.sin(th), 1.0 - np.cos(th)
    # exp([k] th) = I + sin th [k] + (1 - cos th) [k]^2
    E00, E01, E02 = 1.0 - cm * (ky * ky + kz * kz), -s * kz + cm * kx * ky, s * ky + cm * kx * kz
    E10, E11, E12 = s * kz + cm * kx * ky, 1.0 - cm * (kx * kx + kz * kz), -s * kx + cm * ky * kz
    E20, E21, E22 = -s * ky + cm * kx * kz, s * kx + cm * ky * kz, 1.0 - cm * (kx * kx + ky * ky)
    for b in range(3):
        R[0, b] = E00 * R0[0, b] + E01 * R0[1, b] + E02 * R0[2, b]
        R[1, b] = E10 * R0[0, b] + E11 * R0[1, b] + E12 * R0[2, b]
        R[2, b] = E20 * R0[0, b] + E21 * R0[1, b] + E22 * R0[2, b]


class Touches(NamedTuple):
    """Scratch for one substep's contacts (capacity c: ``capacity`` of the step's
    candidates): part (c,), the element's points ends (c,3) (-1: none; a segment has two, a
    point one, a face three) and the contact point's weights on them w (c,3), penetration pen
    (c,) m, normal n (c,3) (element towards part), part surface point P (c,3) m and its
    velocity vp (c,3) m/s; per part its predicted centre of mass c (k,3) m at the substep; per
    network point the summed weight share (n,) of its contacts (zero between substeps); tau
    (1,) s the substep's time into the step."""
    part: np.ndarray
    ends: np.ndarray
    w: np.ndarray
    pen: np.ndarray
    n: np.ndarray
    P: np.ndarray
    vp: np.ndarray
    c: np.ndarray
    share: np.ndarray
    tau: np.ndarray


def touches(capacity: int, parts: int, points: int) -> Touches:
    """Empty Touches for up to ``capacity`` contacts of ``parts`` parts on ``points`` points."""
    return Touches(np.zeros(capacity, np.int64), np.zeros((capacity, 3), np.int64),
                   np.zeros((capacity, 3)), np.zeros(capacity), np.zeros((capacity, 3)),
                   np.zeros((capacity, 3)), np.zeros((capacity, 3)), np.zeros((parts, 3)),
                   np.zeros(points), np.zeros(1))


@njit(cache=True)
def capacity(parts):
    """The most touches the found candidates can give in one substep: one per segment or
    point, one per feature of the part (primitive_distance.features) per face."""
    total = 0
    for j in range(parts.kind.shape[0]):
        per_face = features(parts.kind[j])
        for e in range(parts.start[j], parts.start[j + 1]):
            total += 1 if parts.elems[parts.cand[e], 2] < 0 else per_face
    return total


@njit(cache=True, inline="always")
def _meets(x, el, lo, hi, pad):
    """Does the box of element el's points (-1: none) meet the box lo-hi grown by pad (m)?"""
    for r in range(3):
        emin, emax = x[el[0], r], x[el[0], r]
        for s in range(1, 3):
            if el[s] >= 0:
                emin = min(emin, x[el[s], r])
                emax = max(emax, x[el[s], r])
        if hi[r] + pad < emin or lo[r] - pad > emax:
            return False
    return True


@njit(cache=True, inline="always")
def _record(tc, cnt, j, pen, n, P, c, lin, acc, w, tau):
    """Touch cnt of part j (its ends and weights already in tc.ends / tc.w): penetration pen
    (m), normal n, surface point P, and the part's surface velocity there, v + a tau + w x r;
    adds the weights to the points' shares."""
    tc.part[cnt], tc.pen[cnt] = j, pen
    rx, ry, rz = P[0] - c[0], P[1] - c[1], P[2] - c[2]
    for r in range(3):
        tc.n[cnt, r] = n[r]
        tc.P[cnt, r] = P[r]
        if tc.ends[cnt, r] >= 0:
            tc.share[tc.ends[cnt, r]] += tc.w[cnt, r]
    tc.vp[cnt, 0] = lin[0] + acc[0] * tau + w[1] * rz - w[2] * ry
    tc.vp[cnt, 1] = lin[1] + acc[1] * tau + w[2] * rx - w[0] * rz
    tc.vp[cnt, 2] = lin[2] + acc[2] * tau + w[0] * ry - w[1] * rx


@njit(cache=True)
def find_touches(parts, tau, x, tc):
    """Pass 1 at tau (s) into the step: every candidate element within its part's contact
    skin (a face: each of the part's features over it), into the Touches ``tc``, and each
    touched point's summed weight into tc.share. Returns the count."""
    R = np.empty((3, 3))
    lo, hi = np.empty(3), np.empty(3)
    A, B, X, P, n, bary = (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3),
                           np.empty(3))
    cand, elems = parts.cand, parts.elems
    tc.tau[0] = tau
    cnt = 0
    for j in range(parts.kind.shape[0]):
        if parts.start[j + 1] == parts.start[j]:
            continue
        c = tc.c[j]
        pose_at(parts, j, tau, c, R)
        thickness = parts.law[j, THICKNESS]
        _primitive_box(parts, j, c, R, lo, hi)
        kind, pj, qj, size = parts.kind[j], parts.p[j], parts.q[j], parts.size[j]
        w, lin, acc = parts.spins[j], parts.velocities[j], parts.accels[j]
        for e in range(parts.start[j], parts.start[j + 1]):
            el = elems[cand[e]]
            if not _meets(x, el, lo, hi, thickness):
                continue  # the element's box misses the primitive's: no contact this substep
            ia, ib, ic = el[0], el[1], el[2]
            if ic < 0:  # a segment, or a point (ia == ib)
                t, gap = closest(kind, pj, qj, size, c, R, x, ia, ib, A, B, X, P, n,
                                 parts.golden)
                pen = thickness - gap
                if pen <= 0.0:
                    continue
                tc.ends[cnt, 0], tc.w[cnt, 0] = ia, 1.0 - t if ib != ia else 1.0
                tc.ends[cnt, 1], tc.w[cnt, 1] = (ib, t) if ib != ia else (-1, 0.0)
                tc.ends[cnt, 2], tc.w[cnt, 2] = -1, 0.0
                _record(tc, cnt, j, pen, n, P, c, lin, acc, w, tau)
                cnt += 1
                continue
            for f in range(features(kind)):
                gap = face_feature(kind, pj, qj, size, c, R, f, x, ia, ib, ic, X, P, n, bary)
                pen = thickness - gap
                if pen <= 0.0:
                    continue
                for s in range(3):
                    tc.ends[cnt, s], tc.w[cnt, s] = el[s], bary[s]
                _record(tc, cnt, j, pen, n, P, c, lin, acc, w, tau)
                cnt += 1
    return cnt


@njit(cache=True)
def touch_forces(parts, tc, cnt, pts, pt_acc, dt, out, with_jacobian, wrenches):
    """Pass 2: the law at each of the ``cnt`` Touches. A network point touched by several
    contacts (a bed point under a foot is an end of six edges) lends each a share of its mass
    in proportion to the contact's weight on it, m_p w / W_p (W_p its summed weight), so the
    point sees one contact's stiffness, damping and constraint force in total, not six: the
    contact's inverse mass is 1/m_part + sum_p w W_p / m_p. Writes the forces on the points
    into the PointForces ``out`` (one entry per point of a contact, equal and opposite to the
    part's; Jacobians and vref when ``with_jacobian``) and each part's force (0:3) and torque
    about its centre of mass (3:6) into ``wrenches`` (k,6); clears tc.share. dt (s): the
    step the forces are held for (friction's cap; its inverse over ``parts.steps`` the law's
    rate where the law gives no stiffness). Where ``parts`` keeps a stretch per point, friction
    sticks (contact_law.sticking_friction): a contact's spring is its ends' stretches weighted
    as its point is, and each end keeps the weighted mean of its contacts' new stretches; an
    end that no contact of the part held at the previous call starts from none. Returns the
    entries written."""
    x, v, m, _ = pts
    omega = 1.0 / (parts.steps * dt)
    wrenches[:, :] = 0.0
    vrel, vt, F = np.empty(3), np.empty(3), np.empty(3)
    stick = parts.stretch.shape[1] > 0
    clock = parts.clock[0] + 1
    parts.clock[0] = clock
    spring, ft_stick, vs = np.empty(3), np.empty(3), np.empty(3)
    k = np.int64(0)  # not the literal 0: to_ends would compile twice (0 and int64)
    for i in range(cnt):
        j, ends, w = tc.part[i], tc.ends[i], tc.w[i]
        law = parts.law[j]
        mu, eps = law[FRICTION], law[EPS]
        n = tc.n[i]
        vn = 0.0
        an = 0.0
        inv_m = 1.0 / parts.masses[j]
        for r in range(3):
            vrel[r] = tc.vp[i, r]
            an += parts.accels[j, r] * n[r]
        for s in range(3):
            p = ends[s]
            if p < 0:
                continue
            inv_m += w[s] * tc.share[p] / m[p]
            for r in range(3):
                vrel[r] -= w[s] * v[p, r]
                an -= w[s] * pt_acc[p, r] * n[r]
        for r in range(3):
            vn += vrel[r] * n[r]
        meff = 1.0 / inv_m
        cs = law[STIFFNESS] if law[STIFFNESS] >= 0.0 else meff * omega * omega
        cd = law[DAMPING] if law[DAMPING] >= 0.0 else 2.0 * meff * omega
        fn = normal_force(tc.pen[i], vn, an, inv_m, cs, cd, law[CONSTRAINT] > 0.5)
        if fn <= 0.0:
            continue
        vtn = 0.0
        for r in range(3):
            vt[r] = vrel[r] - vn * n[r]
            vtn += vt[r] * vt[r]
        vtn = np.sqrt(vtn)
        if stick:
            # the spring follows the slip on the part's motion at the step's start, without
            # its free acceleration's a tau: the step's impulse takes that away from the real
            # motion (a held part would otherwise stretch by a h^2 / 2 a step and be pushed
            # back against its load at a h / 2)
            an_t = 0.0
            for r in range(3):
                an_t += parts.accels[j, r] * n[r]
            for r in range(3):
                vs[r] = vt[r] - (parts.accels[j, r] - an_t * n[r]) * tc.tau[0]
            _gather(parts, j, ends, w, clock, spring)
            _, visc = sticking_friction(n, vs, fn, cs, cd, mu, eps, meff, dt, spring, ft_stick)
            for r in range(3):
                F[r] = fn * n[r] + ft_stick[r]
            for s in range(3):
                if ends[s] >= 0:
                    for r in range(3):
                        parts.sums[j, ends[s], r] += w[s] * spring[r]
                    parts.weights[j, ends[s]] += w[s]
        else:
            ft = -sliding_friction(fn, vtn, mu, eps, inv_m, dt) / vtn if vtn > 0.0 else 0.0
            for r in range(3):
                F[r] = fn * n[r] + ft * vt[r]
            visc = friction_damping(fn, vtn, mu, eps, inv_m, dt) if with_jacobian else 0.0
        rx, ry, rz = (tc.P[i, 0] - tc.c[j, 0], tc.P[i, 1] - tc.c[j, 1],
                      tc.P[i, 2] - tc.c[j, 2])
        wrenches[j, 0] += F[0]
        wrenches[j, 1] += F[1]
        wrenches[j, 2] += F[2]
        wrenches[j, 3] += ry * F[2] - rz * F[1]
        wrenches[j, 4] += rz * F[0] - rx * F[2]
        wrenches[j, 5] += rx * F[1] - ry * F[0]
        k = to_ends(out, k, ends, w, F, n, tc.vp[i], (cs, cd, visc), with_jacobian)
    for i in range(cnt):
        for s in range(3):
            p = tc.ends[i, s]
            if p >= 0:
                tc.share[p] = 0.0
                if stick:
                    _keep(parts, tc.part[i], p, clock)
    return k


@njit(cache=True, inline="always")
def _gather(parts, j, ends, w, clock, spring):
    """A contact's tangential spring (m) into ``spring``: the mean of its ends' stretches on
    part j, weighted w (ends < 0 unused), over the ends held at the previous call
    (an edge sliding in under a foot takes on the stretch of its end already there: counted
    as none, it would pull the contact's spring down at every edge that comes in, and the
    foot creep); none held: no stretch."""
    for r in range(3):
        spring[r] = 0.0
    held = 0.0
    for s in range(3):
        p = ends[s]
        if p >= 0 and parts.stamp[j, p] == clock - 1:
            held += w[s]
            for r in range(3):
                spring[r] += w[s] * parts.stretch[j, p, r]
    if held > 0.0:
        for r in range(3):
            spring[r] /= held


@njit(cache=True, inline="always")
def _keep(parts, j, p, clock):
    """Point p's stretch on part j: the weighted mean of this call's contacts' springs."""
    w = parts.weights[j, p]
    if w > 0.0:
        for r in range(3):
            parts.stretch[j, p, r] = parts.sums[j, p, r] / w
            parts.sums[j, p, r] = 0.0
        parts.weights[j, p] = 0.0
        parts.stamp[j, p] = clock
