"""Spring-mass network kernels: forces, the explicit (symplectic Euler) step, and the implicit
backward-Euler step with one Newton iteration solved by preconditioned conjugate gradients
(Baraff & Witkin 1998).

Notation (SI): x, v (n,3) positions m and velocities m/s; m (n,) kg; springs (si, sj) with rest
length l0 (m), stiffness k (N/m), along-spring damping kd (N s/m), tension_only flags; anchors
are zero-rest-length springs from a point to a world position (k N/m, c N s/m); alpha (1/s) is
the mass-proportional Rayleigh coefficient (force -alpha m v). ``fixed`` points never move: the
implicit solve filters them out of the system (constraint filter), the explicit step skips them.
"""
from typing import NamedTuple

import numpy as np
from numba import njit


class Points(NamedTuple):
    """A network's point state: x, v (n,3) m and m/s, m (n,) kg, fixed (n,) bool."""
    x: np.ndarray
    v: np.ndarray
    m: np.ndarray
    fixed: np.ndarray


class SpringSet(NamedTuple):
    """Springs from point i to point j: rest length (m), stiffness k (N/m), along-spring
    damping kd (N s/m), tension_only (cords that go slack)."""
    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    kd: np.ndarray
    tension_only: np.ndarray


class Anchors(NamedTuple):
    """Zero-rest-length springs from points idx to world positions pos (a,3) m, stiffness
    k (N/m) and damping c (N s/m)."""
    idx: np.ndarray
    pos: np.ndarray
    k: np.ndarray
    c: np.ndarray


class Network(NamedTuple):
    """Everything the network kernels read: points, springs, anchors, mass damping alpha (1/s)
    and gravity (3,) m/s^2."""
    pts: Points
    springs: SpringSet
    anchors: Anchors
    alpha: float
    gravity: np.ndarray


class Load(NamedTuple):
    """The external forces held over a step: f (n,3) N and their Jacobian blocks kext = df/dx
    (n,3,3) N/m, dext = df/dv (n,3,3) N s/m, and kvref (n,3) the sum of kext v_ref over the
    forces relative to another body moving at v_ref (N/s)."""
    f: np.ndarray
    kext: np.ndarray
    dext: np.ndarray
    kvref: np.ndarray


# Copies are loops, not slice assignments: an array assigned into a slice makes Numba compile
# its shape-mismatch error message (string formatting) into the kernel, 1-2 s of a first run
# for a message no correct call can raise (docs/first-run.md).
@njit(cache=True, inline="always")
def copy_rows(src, dst):
    """dst[i, r] = src[i, r] for every point i of (n,3) arrays."""
    for i in range(src.shape[0]):
        for r in range(3):
            dst[i, r] = src[i, r]


@njit(cache=True, inline="always")
def copy_load(src, dst):
    """Every array of the Load ``src`` into the Load ``dst`` of the same shapes."""
    copy_rows(src.f, dst.f)
    copy_rows(src.kvref, dst.kvref)
    for i in range(src.kext.shape[0]):
        for a in range(3):
            for b in range(3):
                dst.kext[i, a, b] = src.kext[i, a, b]
                dst.dext[i, a, b] = src.dext[i, a, b]


class Scheme(NamedTuple):
    """How a network steps: implicit (else symplectic Euler); theta (the theta-method's
    weight) or bdf2; tol and max_iter of the CG solve; xp, vp (n,3) the previous step's state
    (BDF2's history)."""
    implicit: bool
    theta: float
    bdf2: bool
    tol: float
    max_iter: int
    xp: np.ndarray
    vp: np.ndarray


class PointForces(NamedTuple):
    """Forces on points, as a contact writes them: idx (c,) point indices, f (c,3) N, their
    Jacobians dfdx (c,3,3) N/m and dfdv (c,3,3) N s/m, and vref (c,3) m/s the velocity of
    the body each force is relative to."""
    idx: np.ndarray
    f: np.ndarray
    dfdx: np.ndarray
    dfdv: np.ndarray
    vref: np.ndarray


def point_forces(capacity: int) -> PointForces:
    """An empty PointForces buffer for up to ``capacity`` entries."""
    return PointForces(np.zeros(capacity, np.int64), np.zeros((capacity, 3)),
                       np.zeros((capacity, 3, 3)), np.zeros((capacity, 3, 3)),
                       np.zeros((capacity, 3)))


class Bodies(NamedTuple):
    """Free rigid bodies solved in one implicit step together with the network: their
    translation (a ball in a net), so a stiff contact is implicit on both sides, not a force
    the body receives a step late. mass (k,) kg (not finite or <= 0: prescribed, its path
    given, not solved); v (k,3) m/s at the step's start; acc (k,3) m/s^2 its acceleration
    from every other force, held. ``links``: the contacts that couple them to the points, as
    PointForces entries (the force on point idx[e] from body owner[e], its Jacobians relative
    to that body), ``count`` of them. Receives dv (k,3) m/s, each body's velocity change over
    the step (h acc for one that touches no point), and flin (c,3) N, each entry's force
    linearised at the step's end: the force the point integrated with, so the body's share
    is -flin."""
    mass: np.ndarray
    v: np.ndarray
    acc: np.ndarray
    owner: np.ndarray
    links: PointForces
    count: int
    dv: np.ndarray
    flin: np.ndarray


@njit(cache=True, inline="always")
def _spring_vector(x, a, b):
    """(d0, d1, d2, length) of x[a] - x[b]."""
    d0 = x[a, 0] - x[b, 0]
    d1 = x[a, 1] - x[b, 1]
    d2 = x[a, 2] - x[b, 2]
    return d0, d1, d2, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit(cache=True, inline="always")
def spring_pull(x, v, a, b, rest, k, kd, tension_only):
    """(pulls, mag, d0, d1, d2): the force of spring a-b (rest length m, stiffness N/m,
    along-spring damping N s/m) on point a is mag * (d0, d1, d2) = mag * (x_a - x_b), minus it
    on b; pulls is False for a slack cord or a zero-length spring (no force)."""
    d0 = x[a, 0] - x[b, 0]
    d1 = x[a, 1] - x[b, 1]
    d2 = x[a, 2] - x[b, 2]
    l2 = d0 * d0 + d1 * d1 + d2 * d2
    # slack cords are skipped on the squared length: no square root for them
    if l2 <= 0.0 or (tension_only and l2 < rest * rest):
        return False, 0.0, d0, d1, d2
    inv = 1.0 / np.sqrt(l2)
    vr = ((v[a, 0] - v[b, 0]) * d0 + (v[a, 1] - v[b, 1]) * d1 + (v[a, 2] - v[b, 2]) * d2) * inv
    return True, (-k * (l2 * inv - rest) - kd * vr) * inv, d0, d1, d2  # times d = times u l


@njit(cache=True)
def network_forces(net, fext, f):
    """Total force (N) on each point: springs, anchors, Rayleigh mass damping, gravity, external."""
    x, v, m, _ = net.pts
    si, sj, l0, k, kd, tension_only = net.springs
    a_idx, a_pos, a_k, a_c = net.anchors
    alpha, gravity = net.alpha, net.gravity
    n = x.shape[0]
    for p in range(n):
        for c in range(3):
            f[p, c] = fext[p, c] + m[p] * (gravity[c] - alpha * v[p, c])
    for s in range(si.shape[0]):
        a = si[s]
        b = sj[s]
        pulls, mag, d0, d1, d2 = spring_pull(x, v, a, b, l0[s], k[s], kd[s], tension_only[s])
        if not pulls:
            continue
        f[a, 0] += mag * d0
        f[a, 1] += mag * d1
        f[a, 2] += mag * d2
        f[b, 0] -= mag * d0
        f[b, 1] -= mag * d1
        f[b, 2] -= mag * d2
    for r in range(a_idx.shape[0]):
        p = a_idx[r]
        for c in range(3):
            f[p, c] += -a_k[r] * (x[p, c] - a_pos[r, c]) - a_c[r] * v[p, c]


@njit(cache=True, inline="always")
def symplectic_update(pts, f, h):
    """v += h f / m, then x += h v, for every free point."""
    x, v, m, fixed = pts
    for p in range(x.shape[0]):
        if fixed[p]:
            continue
        for c in range(3):
            v[p, c] += h * f[p, c] / m[p]
            x[p, c] += h * v[p, c]


@njit(cache=True)
def explicit_step(net, fext, f, h, nsteps):
    """nsteps symplectic-Euler steps of h seconds (v += h f/m, then x += h v), fext held."""
    for _ in range(nsteps):
        network_forces(net, fext, f)
        symplectic_update(net.pts, f, h)


@njit(cache=True)
def _spring_blocks(x, springs, h, C, Kblk):
    """Per-spring blocks: Kblk = d f_a / d x_a, C = h D_s + h^2 K_s (negative semidefinite).

    The transverse term k (1 - l0/l) is clamped at zero for compressed springs so the system
    stays positive definite (Baraff & Witkin's advice); slack tension-only cords contribute 0.
    """
    si, sj, l0, k, kd, tension_only = springs
    for s in range(si.shape[0]):
        a = si[s]
        b = sj[s]
        d0, d1, d2, ln = _spring_vector(x, a, b)
        for r in range(3):
            for c in range(3):
                C[s, r, c] = 0.0
                Kblk[s, r, c] = 0.0
        if ln <= 0.0 or (tension_only[s] and ln < l0[s]):
            continue
        u = (d0 / ln, d1 / ln, d2 / ln)
        t = 1.0 - l0[s] / ln
        if t < 0.0:
            t = 0.0
        for r in range(3):
            for c in range(3):
                uu = u[r] * u[c]
                eye = 1.0 if r == c else 0.0
                ks = -k[s] * (uu + t * (eye - uu))
                Kblk[s, r, c] = ks
                C[s, r, c] = h * (-kd[s] * uu) + h * h * ks


@njit(cache=True)
def _apply_A(p, diag, si, sj, C, fixed, links, Cl, out):
    """out = A p with A = blockdiag(diag) - sum over springs of the +-C couplings, plus each
    body link's coupling Cl between its point links[e, 0] and its body's row links[e, 1]
    (-1: none); fixed rows 0."""
    n = p.shape[0]
    for i in range(n):
        for r in range(3):
            out[i, r] = diag[i, r, 0] * p[i, 0] + diag[i, r, 1] * p[i, 1] + diag[i, r, 2] * p[i, 2]
    for s in range(si.shape[0]):
        a = si[s]
        b = sj[s]
        for r in range(3):
            y = 0.0
            for c in range(3):
                y += C[s, r, c] * (p[a, c] - p[b, c])
            out[a, r] -= y
            out[b, r] += y
    for e in range(links.shape[0]):
        i = links[e, 0]
        b = links[e, 1]
        if b < 0:
            continue
        for r in range(3):
            for c in range(3):
                out[i, r] += Cl[e, r, c] * p[b, c]
                out[b, r] += Cl[e, c, r] * p[i, c]
    for i in range(n):
        if fixed[i]:
            out[i, 0] = 0.0
            out[i, 1] = 0.0
            out[i, 2] = 0.0


@njit(cache=True)
def inv3(A, out):
    """Inverse of a 3x3 matrix by cofactors (LAPACK calls cost microseconds each here)."""
    a, b, c = A[0, 0], A[0, 1], A[0, 2]
    d, e, f = A[1, 0], A[1, 1], A[1, 2]
    g, h, i = A[2, 0], A[2, 1], A[2, 2]
    co0, co1, co2 = e * i - f * h, f * g - d * i, d * h - e * g
    inv_det = 1.0 / (a * co0 + b * co1 + c * co2)
    out[0, 0], out[0, 1], out[0, 2] = co0 * inv_det, (c * h - b * i) * inv_det, (b * f - c * e) * inv_det
    out[1, 0], out[1, 1], out[1, 2] = co1 * inv_det, (a * i - c * g) * inv_det, (c * d - a * f) * inv_det
    out[2, 0], out[2, 1], out[2, 2] = co2 * inv_det, (b * g - a * h) * inv_det, (a * e - b * d) * inv_det


@njit(cache=True)
def _precondition(Pinv, r, z):
    for i in range(r.shape[0]):
        for a in range(3):
            z[i, a] = Pinv[i, a, 0] * r[i, 0] + Pinv[i, a, 1] * r[i, 1] + Pinv[i, a, 2] * r[i, 2]


@njit(cache=True)
def _dot(a, b):
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i, 0] * b[i, 0] + a[i, 1] * b[i, 1] + a[i, 2] * b[i, 2]
    return s


@njit(cache=True)
def implicit_step(net, load, f, h, scheme, has_prev):
    """One implicit step of the network alone (``implicit_step_with_bodies`` without bodies).
    Returns the CG iterations."""
    e3 = np.zeros((0, 3))
    none = PointForces(np.zeros(0, np.int64), e3, np.zeros((0, 3, 3)), np.zeros((0, 3, 3)), e3)
    return implicit_step_with_bodies(net, load, f, h, scheme, has_prev,
                                     Bodies(np.zeros(0), e3, e3, np.zeros(0, np.int64), none, 0,
                                            e3, e3))


@njit(cache=True)
def implicit_step_with_bodies(net, load, f, h, scheme, has_prev, bodies):
    """One implicit step with one Newton iteration, of the theta-method or of BDF2.

    theta-method: (M - theta h D - theta^2 h^2 K) dv = h (f + theta h K v),
                  x += h (v + theta dv). theta = 1 is backward Euler (Baraff & Witkin): it damps
                  a mode of frequency w by ~ (w h)^2 / 2 per step, which at h = 1e-3 s triples the
                  damping of a stiff cord; theta = 1/2 is the trapezoidal rule (none).
    BDF2 (bdf2=True; xp, vp the previous step's state, updated here):
                  (M - hs D - hs^2 K) dv = M (v - vp) / 3 + hs (f + K y), hs = 2h/3,
                  y = (x - xp) / 3 + hs v, x_new = x + (x - xp) / 3 + hs (v + dv).
                  Second order, numerical damping O((w h)^4) on resolved modes, and it still
                  damps the unresolved stiff ones (Choi & Ko 2002). Without a previous state
                  (has_prev False) the step is backward Euler and records xp, vp.

    kext, dext (n,3,3) are the external forces' own Jacobians d f / d x and d f / d v (diagonal
    blocks, e.g. from penalty contacts), so stiff couplings stay stable at large h. An external
    force that depends on the point's position *relative to another body* moving at v_ref
    (a contact) enters as kext (v - v_ref): kvref (n,3) holds the sum of kext v_ref, so the
    point follows the other body through the step instead of lagging a step behind.

    ``bodies`` (a Bodies) adds free rigid bodies' velocities to the unknowns: a contact entry
    e between point i and body b couples them by C_e = hs D_e + hs^2 K_e (K_e, D_e its dfdx,
    dfdv), the body's row being M_b dv_b = cf (M_b a_b - sum_e f_e,lin), so the contact is
    implicit on both sides and the exchange equal and opposite. A BDF2 network steps by
    backward Euler while a body is coupled (the bodies keep no history); BDF2 resumes after.
    Solved by block-Jacobi preconditioned CG to a relative residual ``tol``. Returns the CG
    iterations.
    """
    x, v, m, fixed = net.pts
    si, sj = net.springs.i, net.springs.j
    a_idx, a_k, a_c = net.anchors.idx, net.anchors.k, net.anchors.c
    alpha = net.alpha
    fext, kext, dext, kvref = load
    _, theta, bdf2, tol, max_iter, xp, vp = scheme
    n = x.shape[0]
    ns = si.shape[0]
    nb = bodies.mass.shape[0]
    big = n + nb  # unknowns: the points' velocity changes, then the coupled free bodies'
    fixed_all = np.ones(big, np.bool_)  # a body's row is solved only while it touches
    for i in range(n):
        fixed_all[i] = fixed[i]
    nl = bodies.count
    links = np.full((nl, 2), -1, np.int64)  # (point, body row) of each coupling
    coupled = False
    for e in range(nl):
        links[e, 0] = bodies.links.idx[e]
        q = bodies.owner[e]
        if np.isfinite(bodies.mass[q]) and bodies.mass[q] > 0.0:
            links[e, 1] = n + q
            fixed_all[n + q] = False
            coupled = True
    network_forces(net, fext, f)
    C = np.empty((ns, 3, 3))
    Kblk = np.empty((ns, 3, 3))
    first = bdf2 and (not has_prev or coupled)
    if bdf2 and not first:
        hs, cf, wref, cprev = 2.0 * h / 3.0, 2.0 * h / 3.0, h, 1.0 / 3.0
    else:
        th = 1.0 if first else theta
        hs, cf, wref, cprev = th * h, h, th * h, 0.0
        bdf2 = False
    # y: the displacement over the step that the Jacobian K acts on
    y = np.empty((n, 3))
    for i in range(n):
        for r in range(3):
            # fixed points never move (and their xp is never recorded): y = 0 there
            y[i, r] = 0.0 if fixed[i] else (
                hs * v[i, r] + (cprev * (x[i, r] - xp[i, r]) if bdf2 else 0.0))
    _spring_blocks(x, net.springs, hs, C, Kblk)
    # diagonal blocks of A not coming from springs: M - h D_diag - h^2 K_diag
    diag = np.zeros((big, 3, 3))
    for i in range(n):
        for r in range(3):
            for c in range(3):
                diag[i, r, c] = -hs * dext[i, r, c] - hs * hs * kext[i, r, c]
            diag[i, r, r] += m[i] * (1.0 + hs * alpha)
    for q in range(a_idx.shape[0]):
        i = a_idx[q]
        for r in range(3):
            diag[i, r, r] += hs * a_c[q] + hs * hs * a_k[q]
    # right-hand side b = cprev M (v - vp) + cf (f + K y); external stiffness acts on the
    # displacement relative to the other body, y - wref v_ref
    b = np.zeros((big, 3))
    for i in range(n):
        for r in range(3):
            kv = 0.0
            for c in range(3):
                kv += kext[i, r, c] * y[i, c]
            b[i, r] = cf * (f[i, r] + kv - wref * kvref[i, r])
            if bdf2:
                b[i, r] += cprev * m[i] * (v[i, r] - vp[i, r])
    for q in range(a_idx.shape[0]):
        i = a_idx[q]
        for r in range(3):
            b[i, r] += cf * (-a_k[q] * y[i, r])
    for s in range(ns):
        a = si[s]
        bb = sj[s]
        for r in range(3):
            kv = 0.0
            for c in range(3):
                kv += Kblk[s, r, c] * (y[a, c] - y[bb, c])
            b[a, r] += cf * kv
            b[bb, r] -= cf * kv
    # the free bodies' rows: M_b - sum C_e on the diagonal, C_e to each touching point, and
    # cf (M_b a_b - sum (f_e + K_e (y_i - wref v_ref))) on the right
    lf = bodies.links
    Cl = np.zeros((nl, 3, 3))
    for q in range(nb):
        if not fixed_all[n + q]:
            for r in range(3):
                diag[n + q, r, r] = bodies.mass[q]
                b[n + q, r] = cf * bodies.mass[q] * bodies.acc[q, r]
    for e in range(nl):
        bq = links[e, 1]
        if bq < 0:
            continue
        i = links[e, 0]
        for r in range(3):
            kv = lf.f[e, r]
            for c in range(3):
                Cl[e, r, c] = hs * lf.dfdv[e, r, c] + hs * hs * lf.dfdx[e, r, c]
                diag[bq, r, c] -= Cl[e, r, c]
                kv += lf.dfdx[e, r, c] * (y[i, c] - wref * lf.vref[e, c])
            b[bq, r] -= cf * kv
    # block-Jacobi preconditioner: inverse of each row's full diagonal block
    P = diag.copy()
    for s in range(ns):
        for r in range(3):
            for c in range(3):
                P[si[s], r, c] -= C[s, r, c]
                P[sj[s], r, c] -= C[s, r, c]
    Pinv = np.empty((big, 3, 3))
    for i in range(big):
        if fixed_all[i]:
            Pinv[i] = 0.0
            continue
        inv3(P[i], Pinv[i])
    for i in range(big):
        if fixed_all[i]:
            b[i, 0] = 0.0
            b[i, 1] = 0.0
            b[i, 2] = 0.0
    # preconditioned conjugate gradients with the constraint filter
    dv = np.zeros((big, 3))
    r_ = b.copy()
    z = np.empty((big, 3))
    _precondition(Pinv, r_, z)
    pdir = z.copy()
    Ap = np.empty((big, 3))
    rz = _dot(r_, z)
    bnorm = np.sqrt(_dot(b, b))
    it = 0
    if bnorm > 0.0:
        while it < max_iter:
            _apply_A(pdir, diag, si, sj, C, fixed_all, links, Cl, Ap)
            alpha_cg = rz / _dot(pdir, Ap)
            for i in range(big):
                for a in range(3):
                    dv[i, a] += alpha_cg * pdir[i, a]
                    r_[i, a] -= alpha_cg * Ap[i, a]
            it += 1
            if np.sqrt(_dot(r_, r_)) <= tol * bnorm:
                break
            _precondition(Pinv, r_, z)
            rz_new = _dot(r_, z)
            beta = rz_new / rz
            for i in range(big):
                for a in range(3):
                    pdir[i, a] = z[i, a] + beta * pdir[i, a]
            rz = rz_new
    for i in range(n):
        if fixed[i]:
            continue
        for c in range(3):
            if bdf2:
                xn = x[i, c] + cprev * (x[i, c] - xp[i, c]) + hs * (v[i, c] + dv[i, c])
                xp[i, c] = x[i, c]
                vp[i, c] = v[i, c]
                x[i, c] = xn
            else:
                if first:
                    xp[i, c] = x[i, c]
                    vp[i, c] = v[i, c]
                x[i, c] += h * v[i, c] + hs * dv[i, c]
            v[i, c] += dv[i, c]
    for q in range(nb):  # a body touching nothing falls freely over the step
        for c in range(3):
            bodies.dv[q, c] = h * bodies.acc[q, c] if fixed_all[n + q] else dv[n + q, c]
    # each link's force as the point integrated it: f + K (y + hs dv - wref v_ref - hs dv_b)
    # + D (dv - dv_b), y and dv the point's (0 for a fixed one), dv_b the body's (0: prescribed)
    for e in range(nl):
        i = links[e, 0]
        bq = links[e, 1]
        for r in range(3):
            fl = lf.f[e, r]
            for c in range(3):
                dvb = dv[bq, c] if bq >= 0 else 0.0
                fl += (lf.dfdx[e, r, c] * (y[i, c] + hs * (dv[i, c] - dvb) - wref * lf.vref[e, c])
                       + lf.dfdv[e, r, c] * (dv[i, c] - dvb))
            bodies.flin[e, r] = fl
    return it


@njit(cache=True)
def max_strain(x, springs):
    """Largest (l - l0) / l0 over all springs (preloaded ones, l0 < 0, have no strain)."""
    si, sj, l0 = springs.i, springs.j, springs.rest
    best = -1.0
    for s in range(si.shape[0]):
        if l0[s] <= 0.0:
            continue
        e = _spring_vector(x, si[s], sj[s])[3] / l0[s] - 1.0
        if e > best:
            best = e
    return best


@njit(cache=True)
def scatter_forces(forces, count, load, with_jacobian):
    """Accumulate the first ``count`` point forces (a PointForces), with their 3x3 Jacobian
    blocks and kext v_ref when ``with_jacobian``, into the held load."""
    idx, forces, dfdx, dfdv, vref = forces
    fext, kext, dext, kvref = load
    for r in range(count):
        p = idx[r]
        for c in range(3):
            fext[p, c] += forces[r, c]
        if with_jacobian:
            for a in range(3):
                kv = 0.0
                for c in range(3):
                    kext[p, a, c] += dfdx[r, a, c]
                    dext[p, a, c] += dfdv[r, a, c]
                    kv += dfdx[r, a, c] * vref[r, c]
                kvref[p, a] += kv
