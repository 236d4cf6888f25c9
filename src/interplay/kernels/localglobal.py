"""Local/global integration of spring networks: backward Euler as a minimization (Liu et al.
2013), solved by L-BFGS with the constant local/global matrix as its initial Hessian (Liu,
Bouaziz & Kavan 2017).

A backward-Euler step of h seconds is the minimizer of
    Phi(x) = 1/2 |x - y|^2_M' - ... = 1/2 x.D x - base.x
             + sum_s h^2 k_s/2 (|d_s| - l0_s)^2 + h beta k_s/2 (u_s . (d_s - d_s,n))^2,
d_s = x_a - x_b, y = x_n + h v_n + h^2 M^-1 f, D = M (1 + h alpha) (+ anchors), so that
grad Phi = 0 is M (x - y) / h^2 = spring forces - alpha M v - along-spring damping. The damping
is the explicit network's: mass-proportional -alpha m v, and stiffness-proportional beta k
along each spring, whose direction u_s is taken at the step's start (lagged: the term is then
quadratic). Slack tension-only cords (shorter than l0) pull nothing; at the step's start they
also damp nothing.

Each spring term equals min over |p_s| = l0_s of k_s/2 |d_s - p_s|^2 (the *local* projection),
and with p held the objective is quadratic with the constant matrix
A = M (1 + h alpha) + (h^2 + h beta) L + h^2 K_anchor + h C_anchor,
L = sum_s k_s (e_a - e_b)(e_a - e_b)^T (the *global* solve): x - A^-1 grad Phi is one plain
local/global iteration. A bounds the damping's Hessian (u u^T <= I), does not depend on the
state, and is factored once or given a multigrid hierarchy (kernels/global_matrix.py). L-BFGS builds on A^-1 the curvature the projections leave out, with an Armijo
line search (the objective never rises). With memory 0 it is plain local/global.

Fixed points are not unknowns. External forces (aero, contacts, attachments) enter y
explicitly; their Jacobians are ignored, so very stiff penalty couplings need a small step here
(or the explicit/implicit integrators). Sub-cycled colliders (moving spheres, ``subcycle``) act
on the points after each step through the contact law integrated by backward Euler for each
point alone (``contact_law.backward_euler_normal``: a stiff law is then the projection onto
the surface, with the position and velocity of the point consistent), with the law's friction;
the momentum the network loses is returned as the collider's impulse.
"""
from typing import NamedTuple

import numpy as np
from numba import njit

from .contact import DAMPING, EPS, FRICTION, STIFFNESS, THICKNESS, Sphere
from .contact_law import backward_euler_normal, sliding_friction
from .global_matrix import apply_inverse
from .springs import Points, SpringSet


class History(NamedTuple):
    """L-BFGS memory: S, Y (mem + 1, nf, 3) a ring of position and gradient changes, rho their
    1 / s.y, count (1,) the pairs stored so far. It survives from step to step."""
    S: np.ndarray
    Y: np.ndarray
    rho: np.ndarray
    count: np.ndarray


class Objective(NamedTuple):
    """Backward Euler's objective for one step: fid, the springs, u (ns,3) and cn (ns,) each
    spring's unit direction and u . d at the step's start, diag (nf,) and base (nf,3) its
    quadratic and linear parts, hh = h^2 and hb = h beta (s^2)."""
    fid: np.ndarray
    springs: SpringSet
    u: np.ndarray
    cn: np.ndarray
    diag: np.ndarray
    base: np.ndarray
    hh: float
    hb: float


class Settings(NamedTuple):
    """beta (s): stiffness-proportional damping; iters: most L-BFGS iterations a step; tol:
    stop when an iteration moves no point by more than tol times the first one did."""
    beta: float
    iters: int
    tol: float


@njit(cache=True)
def _sphere_contacts(pts, xn, ball, law, h, imp):
    """The contact law on the points inside a sphere (a contact.Sphere: centre and velocity at
    the step's end) after a step of h (s): each point's normal velocity changes by the law's
    backward-Euler response and its position with it (x += h dv n, so x - x_n = h v still
    holds), then the law's sliding friction acts on its slip relative to the sphere. A point
    that crossed the centre since the step's start xn goes back out on that side. Adds the
    impulse and the angular impulse about the centre the points exert on the sphere (N s,
    N m s) to imp[0:6]; returns the impulse magnitude."""
    x, v, m, fixed = pts
    c, vc = ball.c, ball.v
    reach = ball.radius + law[THICKNESS]
    cs, cd, mu, eps = law[STIFFNESS], law[DAMPING], law[FRICTION], law[EPS]
    J0 = 0.0
    J1 = 0.0
    J2 = 0.0
    for i in range(x.shape[0]):
        if fixed[i]:
            continue
        r0 = x[i, 0] - c[0]
        r1 = x[i, 1] - c[1]
        r2 = x[i, 2] - c[2]
        dist = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        if dist >= reach:
            continue
        s0 = xn[i, 0] - c[0]
        s1 = xn[i, 1] - c[1]
        s2 = xn[i, 2] - c[2]
        if r0 * s0 + r1 * s1 + r2 * s2 <= 0.0:
            sd = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
            if sd <= 0.0:
                continue
            n0, n1, n2 = s0 / sd, s1 / sd, s2 / sd
            dist = r0 * n0 + r1 * n1 + r2 * n2  # <= 0: it is past the centre along n
        elif dist > 0.0:
            n0, n1, n2 = r0 / dist, r1 / dist, r2 / dist
        else:
            continue
        u0 = v[i, 0] - vc[0]
        u1 = v[i, 1] - vc[1]
        u2 = v[i, 2] - vc[2]
        un = u0 * n0 + u1 * n1 + u2 * n2
        dvn = backward_euler_normal(reach - dist, un, m[i], h, cs, cd)
        if dvn <= 0.0:
            continue
        t0 = u0 - un * n0
        t1 = u1 - un * n1
        t2 = u2 - un * n2
        ut = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        slow = 0.0  # the slip's change of speed (m/s) from friction over the step
        if ut > 0.0:
            slow = sliding_friction(m[i] * dvn / h, ut, mu, eps, 1.0 / m[i], h) * h / m[i]
        keep = 0.0 if ut <= 0.0 else 1.0 - slow / ut
        dv0 = dvn * n0 + (keep - 1.0) * t0
        dv1 = dvn * n1 + (keep - 1.0) * t1
        dv2 = dvn * n2 + (keep - 1.0) * t2
        v[i, 0] += dv0
        v[i, 1] += dv1
        v[i, 2] += dv2
        x[i, 0] += h * dvn * n0
        x[i, 1] += h * dvn * n1
        x[i, 2] += h * dvn * n2
        j0 = -m[i] * dv0
        j1 = -m[i] * dv1
        j2 = -m[i] * dv2
        J0 += j0
        J1 += j1
        J2 += j2
        # torque about the centre from a push at the surface point reach * n
        imp[3] += reach * (n1 * j2 - n2 * j1)
        imp[4] += reach * (n2 * j0 - n0 * j2)
        imp[5] += reach * (n0 * j1 - n1 * j0)
    imp[0] += J0
    imp[1] += J1
    imp[2] += J2
    return np.sqrt(J0 * J0 + J1 * J1 + J2 * J2)


@njit(cache=True)
def _energy_gradient(x, obj, g):
    """Phi (J s^2, up to a constant) of the Objective at x (all points, fixed ones at their
    places) and its gradient g over the unknowns (N s^2). A slack or degenerate spring has
    u = 0 (it damps nothing)."""
    fid, diag, base = obj.fid, obj.diag, obj.base
    phi = 0.0
    for i in range(x.shape[0]):
        p = fid[i]
        if p < 0:
            continue
        for r in range(3):
            g[p, r] = diag[p] * x[i, r] - base[p, r]
            phi += 0.5 * diag[p] * x[i, r] * x[i, r] - base[p, r] * x[i, r]
    return phi + _spring_terms(x, obj, g)


@njit(cache=True)
def _energy_gradient_along(x0, q, t, x, obj, g):
    """``_energy_gradient`` at x = x0 - t q (q over the unknowns; fixed points stay), which
    is written to x: the line search's trial point in the same pass."""
    fid, diag, base = obj.fid, obj.diag, obj.base
    phi = 0.0
    for i in range(x.shape[0]):
        p = fid[i]
        if p < 0:
            for r in range(3):
                x[i, r] = x0[i, r]
            continue
        for r in range(3):
            xi = x0[i, r] - t * q[p, r] if t != 0.0 else x0[i, r]  # q may be unset at t = 0
            x[i, r] = xi
            g[p, r] = diag[p] * xi - base[p, r]
            phi += 0.5 * diag[p] * xi * xi - base[p, r] * xi
    return phi + _spring_terms(x, obj, g)


@njit(cache=True)
def _spring_terms(x, obj, g):
    """The springs' part of Phi at x (stretch energy and lagged along-spring damping), their
    gradient added to g."""
    fid, u, cn, hh, hb = obj.fid, obj.u, obj.cn, obj.hh, obj.hb
    si, sj, l0, k, tension_only = (obj.springs.i, obj.springs.j, obj.springs.rest,
                                   obj.springs.k, obj.springs.tension_only)
    phi = 0.0
    for s in range(si.shape[0]):
        a = si[s]
        b = sj[s]
        d0 = x[a, 0] - x[b, 0]
        d1 = x[a, 1] - x[b, 1]
        d2 = x[a, 2] - x[b, 2]
        ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        e = ln - l0[s]
        sc = 0.0
        if ln > 0.0 and not (tension_only[s] and e < 0.0):
            phi += 0.5 * hh * k[s] * e * e
            sc = hh * k[s] * e / ln
        # damping: h beta k (u . d - u . d_n) along the start direction u
        c = u[s, 0] * d0 + u[s, 1] * d1 + u[s, 2] * d2 - cn[s]
        phi += 0.5 * hb * k[s] * c * c
        cd = hb * k[s] * c
        f0 = sc * d0 + cd * u[s, 0]
        f1 = sc * d1 + cd * u[s, 1]
        f2 = sc * d2 + cd * u[s, 2]
        pa = fid[a]
        pb = fid[b]
        if pa >= 0:
            g[pa, 0] += f0
            g[pa, 1] += f1
            g[pa, 2] += f2
        if pb >= 0:
            g[pb, 0] -= f0
            g[pb, 1] -= f1
            g[pb, 2] -= f2
    return phi


@njit(cache=True)
def _axpy_dot(q, a, y, s):
    """q -= a y, then return s . q, in one pass (s may be None-like: zero rows)."""
    acc = 0.0
    for p in range(q.shape[0]):
        for r in range(3):
            v = q[p, r] - a * y[p, r]
            q[p, r] = v
            acc += s[p, r] * v
    return acc


@njit(cache=True)
def _lbfgs(x, obj, pre, hist, work, iters, tol, phis):
    """Minimize the Objective's Phi by L-BFGS with A as the initial Hessian (Liu, Bouaziz &
    Kavan 2017; its inverse applied by ``global_matrix.apply_inverse`` with the Factors
    ``pre``) and a
    backtracking Armijo line search. hist: the History ring; the last min(count, mem) pairs
    are live, and the slot after them is where the next pair is written (kept only if its
    curvature s.y is positive). work: (g, gn, q, z, xt) scratch. Stops after ``iters``
    iterations or when an iteration moves no point by more than tol times the first
    iteration's largest move. Returns the iterations taken; phis[0], phis[1] receive Phi at
    the first guess and at the end. Vector passes are fused: this is memory-bound."""
    S, Y, rho, count = hist
    g, gn, q, z, xt = work
    fid = obj.fid
    slots = S.shape[0]
    mem = slots - 1
    alpha = np.empty(slots)
    cur, trial = x, xt
    gc, gt = g, gn
    swapped = False  # cur is xt
    phi = _energy_gradient_along(x, q, 0.0, trial, obj, gc)
    phis[0] = phi
    phis[1] = phi
    stored = count[0]
    first = 0.0
    taken = iters
    for it in range(iters):
        # two-loop recursion: r = H g, H the L-BFGS inverse Hessian on top of A^-1
        live = min(stored, mem)
        acc = 0.0
        c = (stored - 1) % slots
        for p in range(q.shape[0]):  # q = g, and the newest pair's s . g
            for r in range(3):
                q[p, r] = gc[p, r]
                acc += S[c, p, r] * gc[p, r]
        for j in range(live):
            c = (stored - 1 - j) % slots
            alpha[c] = rho[c] * acc
            older = (stored - 2 - j) % slots  # the next pair's s . q, fused (unused at the end)
            acc = _axpy_dot(q, alpha[c], Y[c], S[older] if j + 1 < live else Y[c])
        apply_inverse(pre, q, z)
        acc = 0.0
        if live > 0:
            acc = _dot(Y[(stored - live) % slots], q)
        for j in range(live):
            c = (stored - live + j) % slots
            beta = rho[c] * acc
            nxt = Y[(c + 1) % slots] if j + 1 < live else gc  # last: the slope's g . r
            acc = _axpy_dot(q, beta - alpha[c], S[c], nxt)
        slope = -(acc if live > 0 else _dot(gc, q))
        if slope >= 0.0:  # not a descent direction (round-off near the minimum): done
            taken = it
            break
        t = 1.0
        for _ in range(12):
            phin = _energy_gradient_along(cur, q, t, trial, obj, gt)
            # Armijo, with room for round-off in Phi's large constant parts
            if phin <= phi + 1e-4 * t * slope + 1e-13 * abs(phi):
                break
            t *= 0.5
        # the pair goes to the free slot; it becomes live only with positive curvature (Phi
        # is not convex where springs are compressed): H stays positive definite
        c = stored % slots
        sy = 0.0
        move = 0.0
        for i in range(x.shape[0]):
            p = fid[i]
            if p >= 0:
                for r in range(3):
                    d = trial[i, r] - cur[i, r]
                    e = gt[p, r] - gc[p, r]
                    S[c, p, r] = d
                    Y[c, p, r] = e
                    sy += d * e
                    move = max(move, abs(d))
        cur, trial = trial, cur
        gc, gt = gt, gc
        swapped = not swapped
        phi = phin
        phis[1] = phi
        if sy > 0.0:
            rho[c] = 1.0 / sy
            stored += 1
        if it == 0:
            first = move
        elif move <= tol * first:
            taken = it + 1
            break
    count[0] = stored
    if swapped:
        for i in range(x.shape[0]):
            for r in range(3):
                x[i, r] = cur[i, r]
    return taken


@njit(cache=True)
def _dot(a, b):
    s = 0.0
    for p in range(a.shape[0]):
        s += a[p, 0] * b[p, 0] + a[p, 1] * b[p, 1] + a[p, 2] * b[p, 2]
    return s


#: the most extra rounds of iterations (each of Settings.iters) a step gets when it would add
#: energy, before its velocities are scaled back instead
GUARD_ROUNDS = 3


@njit(cache=True)
def network_energy(net) -> float:
    """(J) the network's kinetic energy, its springs' stretch energy (slack cords none), its
    anchors' springs' and the gravitational energy (zero at z = 0 for gravity along -z)."""
    x, v, m, fixed = net.pts
    si, sj, l0, k, tension_only = (net.springs.i, net.springs.j, net.springs.rest,
                                   net.springs.k, net.springs.tension_only)
    a_idx, a_pos, a_k, _ = net.anchors
    e = 0.0
    for i in range(x.shape[0]):
        if not fixed[i]:
            e += m[i] * (0.5 * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
                         - net.gravity[0] * x[i, 0] - net.gravity[1] * x[i, 1]
                         - net.gravity[2] * x[i, 2])
    for s in range(si.shape[0]):
        d = np.sqrt((x[si[s], 0] - x[sj[s], 0]) ** 2 + (x[si[s], 1] - x[sj[s], 1]) ** 2
                    + (x[si[s], 2] - x[sj[s], 2]) ** 2) - l0[s]
        if not (tension_only[s] and d < 0.0):
            e += 0.5 * k[s] * d * d
    for j in range(a_idx.shape[0]):
        i = a_idx[j]
        e += 0.5 * a_k[j] * ((x[i, 0] - a_pos[j, 0]) ** 2 + (x[i, 1] - a_pos[j, 1]) ** 2
                             + (x[i, 2] - a_pos[j, 2]) ** 2)
    return e


@njit(cache=True)
def _held_work(x, xn, fext, fid) -> float:
    """(J) the work of the held external forces over the step from xn to x."""
    w = 0.0
    for i in range(x.shape[0]):
        if fid[i] >= 0:
            for r in range(3):
                w += fext[i, r] * (x[i, r] - xn[i, r])
    return w


@njit(cache=True)
def localglobal_steps(net, fext, pre, hist, settings, h, nsteps, cols, phis, guard):
    """nsteps backward-Euler steps of h seconds of a springs.Network with fext (N) held;
    returns the iterations taken in all.

    pre: the Factors of A for step h; each step runs ``_lbfgs`` (Settings: at most ``iters``
    iterations, stopping early when an iteration moves no point by more than tol times the
    first one did) with the History ``hist``, kept from step to step and call to call (the
    stretch energy's curvature, which the pairs learn, depends on x only; the linear part and
    the damping directions change, so old pairs are a good, not an exact, model); memory 0
    gives plain local/global iterations. cols: sub-cycled contact.Colliders (none: zero rows),
    moving along c0 + v t + a t^2/2 over the nsteps and acting on the points after every step
    (``_sphere_contacts``); cols.impulses receives impulse, angular impulse and peak force (N).
    phis (2,) receives the objective (J s^2, up to a constant) at the last step's first guess
    and at its end, before any collider: how far the iterations got.

    The energy guard: a converged backward-Euler step never adds energy beyond the held
    forces' work (it is dissipative for convex spring energy), but a step cut short at
    ``iters`` can (a stiff chain, k h^2/m ~ 5e3, climbed from -1.5 J to -0.2 J over 10 s at
    10 iterations). A step whose network_energy exceeds the step start's plus the held forces'
    work gets up to GUARD_ROUNDS more rounds of ``iters`` iterations; if it still would, its
    velocities are scaled down to the allowed kinetic energy. guard (2,) counts the extra
    rounds and the scaled steps (added to).
    """
    x, v, m, _ = net.pts
    si, sj, l0, tension_only = (net.springs.i, net.springs.j, net.springs.rest,
                                net.springs.tension_only)
    a_idx, a_pos, a_k, a_c = net.anchors
    alpha, gravity = net.alpha, net.gravity
    beta, iters, tol = settings
    fid = pre.fid
    impulses = cols.impulses
    n = x.shape[0]
    nf = int(np.sum(fid >= 0))
    ns = si.shape[0]
    hh = h * h
    hb = h * beta
    xn = np.empty_like(x)
    xt = np.empty_like(x)
    base = np.empty((nf, 3))
    g = np.empty((nf, 3))
    gn = np.empty((nf, 3))
    q = np.empty((nf, 3))
    z = np.empty((nf, 3))
    u = np.zeros((ns, 3))
    cn = np.zeros(ns)
    diag = np.zeros(nf)
    for i in range(n):
        if fid[i] >= 0:
            diag[fid[i]] = m[i] * (1.0 + h * alpha)
    for j in range(a_idx.shape[0]):
        if fid[a_idx[j]] >= 0:
            diag[fid[a_idx[j]]] += hh * a_k[j] + h * a_c[j]
    c = np.empty(3)
    vc = np.empty(3)
    imp = np.zeros(6)
    pts = Points(x, v, m, fid < 0)
    total = 0
    for j in range(impulses.shape[0]):
        for r in range(7):
            impulses[j, r] = 0.0
    for step in range(nsteps):
        e_start = network_energy(net)
        # the linear part: M (y + h alpha x_n) + h^2 (f + m g) + the anchors' pull and damping;
        # the first guess is y = x_n + h v_n
        for i in range(n):
            for r in range(3):
                xn[i, r] = x[i, r]
            p = fid[i]
            if p < 0:
                continue
            for r in range(3):
                y = x[i, r] + h * v[i, r]
                base[p, r] = (m[i] * (y + h * alpha * x[i, r])
                              + hh * (fext[i, r] + m[i] * gravity[r]))
                x[i, r] = y
        for j in range(a_idx.shape[0]):
            p = fid[a_idx[j]]
            if p >= 0:
                for r in range(3):
                    base[p, r] += hh * a_k[j] * a_pos[j, r] + h * a_c[j] * xn[a_idx[j], r]
        # damping directions at the step's start (none for slack cords, as in the explicit
        # network)
        for s in range(ns):
            d0 = xn[si[s], 0] - xn[sj[s], 0]
            d1 = xn[si[s], 1] - xn[sj[s], 1]
            d2 = xn[si[s], 2] - xn[sj[s], 2]
            ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if ln > 0.0 and not (tension_only[s] and ln < l0[s]):
                u[s, 0] = d0 / ln
                u[s, 1] = d1 / ln
                u[s, 2] = d2 / ln
                cn[s] = ln
            else:
                u[s, 0] = 0.0
                u[s, 1] = 0.0
                u[s, 2] = 0.0
                cn[s] = 0.0
        obj = Objective(fid, net.springs, u, cn, diag, base, hh, hb)
        total += _lbfgs(x, obj, pre, hist, (g, gn, q, z, xt), iters, tol, phis)
        phi_guess = phis[0]
        for rounds in range(GUARD_ROUNDS + 1):
            for i in range(n):
                if fid[i] >= 0:
                    for r in range(3):
                        v[i, r] = (x[i, r] - xn[i, r]) / h
            allowed = e_start + _held_work(x, xn, fext, fid)
            excess = network_energy(net) - allowed
            # round-off: the sums' terms are of the size of |e_start|
            if excess <= 1e-10 * (abs(e_start) + abs(allowed)) + 1e-14:
                break
            if rounds < GUARD_ROUNDS:  # iterate on from where the step got to
                guard[0] += 1
                total += _lbfgs(x, obj, pre, hist, (g, gn, q, z, xt), iters, tol, phis)
                continue
            ke = 0.0
            for i in range(n):
                if fid[i] >= 0:
                    ke += 0.5 * m[i] * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
            scale = np.sqrt(max(ke - excess, 0.0) / ke) if ke > 0.0 else 0.0
            for i in range(n):
                if fid[i] >= 0:
                    for r in range(3):
                        v[i, r] *= scale
            guard[1] += 1
        phis[0] = phi_guess
        tau = (step + 1) * h
        for j in range(cols.centres.shape[0]):
            for r in range(3):
                c[r] = (cols.centres[j, r] + cols.velocities[j, r] * tau
                        + 0.5 * cols.accels[j, r] * tau * tau)
                vc[r] = cols.velocities[j, r] + cols.accels[j, r] * tau
                imp[r] = 0.0
                imp[r + 3] = 0.0
            ball = Sphere(c, vc, cols.spins[j], cols.radii[j], cols.masses[j], cols.accels[j])
            jm = _sphere_contacts(pts, xn, ball, cols.law[j], h, imp)
            for r in range(6):
                impulses[j, r] += imp[r]
            if jm / h > impulses[j, 6]:
                impulses[j, 6] = jm / h
    return total
