"""Kernels against plain NumPy references (slow but obviously right)."""
import numpy as np
import pytest

from interplay.kernels import springs as K
from interplay.kernels.contact import Colliders, Sphere, sphere_elements
from interplay.kernels.subcycle import advance_with_colliders


def random_network(n=12, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, 3))
    pairs = np.array([(i, j) for i in range(n) for j in range(i + 1, n) if rng.random() < 0.3])
    rest = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1) * rng.uniform(0.8, 1.2,
                                                                             len(pairs))
    k = rng.uniform(10, 100, len(pairs))
    kd = rng.uniform(0, 0.5, len(pairs))
    tonly = rng.random(len(pairs)) < 0.3
    v = rng.normal(size=(n, 3))
    m = rng.uniform(0.1, 1.0, n)
    return x, v, m, pairs[:, 0].copy(), pairs[:, 1].copy(), rest, k, kd, tonly


def numpy_forces(x, v, m, si, sj, l0, k, kd, tonly, alpha, g, fext):
    f = fext + m[:, None] * (g - alpha * v)
    for s in range(len(si)):
        d = x[si[s]] - x[sj[s]]
        ln = np.linalg.norm(d)
        if tonly[s] and ln < l0[s]:
            continue
        u = d / ln
        fa = -k[s] * (ln - l0[s]) * u - kd[s] * np.dot(v[si[s]] - v[sj[s]], u) * u
        f[si[s]] += fa
        f[sj[s]] -= fa
    return f


NO_ANCHORS = K.Anchors(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0), np.zeros(0))


def network(x, v, m, si, sj, l0, k, kd, tonly, alpha, g, fixed=None):
    """The kernels' bundle of a network without anchors."""
    fixed = np.zeros(len(x), bool) if fixed is None else fixed
    return K.Network(K.Points(x, v, m, fixed), K.SpringSet(si, sj, l0, k, kd, tonly),
                     NO_ANCHORS, alpha, g)


def scheme(theta, bdf2, xp, vp, tol):
    return K.Scheme(True, theta, bdf2, tol, 500, xp, vp)


def test_network_forces_match_numpy():
    x, v, m, si, sj, l0, k, kd, tonly = random_network()
    g = np.array([0, 0, -9.81])
    fext = np.random.default_rng(1).normal(size=x.shape)
    f = np.zeros_like(x)
    K.network_forces(network(x, v, m, si, sj, l0, k, kd, tonly, 0.3, g), fext, f)
    np.testing.assert_allclose(f, numpy_forces(x, v, m, si, sj, l0, k, kd, tonly, 0.3, g, fext),
                               rtol=1e-12, atol=1e-12)


def dense_jacobians(x, v, m, si, sj, l0, k, kd, tonly, alpha, g, fext, kext, dext):
    """Force f (3n,), stiffness K = df/dx and damping D = df/dv (3n, 3n), assembled densely."""
    n = len(x)
    f = numpy_forces(x, v, m, si, sj, l0, k, kd, tonly, alpha, g, fext).ravel()
    Kd = np.zeros((3 * n, 3 * n))
    Dd = np.zeros((3 * n, 3 * n))
    for i in range(n):
        Kd[3 * i:3 * i + 3, 3 * i:3 * i + 3] += kext[i]
        Dd[3 * i:3 * i + 3, 3 * i:3 * i + 3] += dext[i] - alpha * m[i] * np.eye(3)
    for s in range(len(si)):
        a, b = si[s], sj[s]
        d = x[a] - x[b]
        ln = np.linalg.norm(d)
        if tonly[s] and ln < l0[s]:
            continue
        u = np.outer(d, d) / ln ** 2
        blk = -k[s] * (u + max(0.0, 1 - l0[s] / ln) * (np.eye(3) - u))
        dblk = -kd[s] * u
        for (p, q, sign) in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
            Kd[3 * p:3 * p + 3, 3 * q:3 * q + 3] += sign * blk
            Dd[3 * p:3 * p + 3, 3 * q:3 * q + 3] += sign * dblk
    return f, Kd, Dd


def solve_free(A, rhs, fixed):
    """Solve A dv = rhs on the free points; fixed points get dv = 0."""
    free = np.repeat(~fixed, 3)
    dv = np.zeros(len(rhs))
    dv[free] = np.linalg.solve(A[np.ix_(free, free)], rhs[free])
    return dv.reshape(-1, 3)


@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_implicit_step_matches_dense_solve(theta):
    x, v, m, si, sj, l0, k, kd, tonly = random_network(seed=3)
    n = len(x)
    rng = np.random.default_rng(4)
    fixed = np.zeros(n, dtype=bool)
    fixed[[0, 5]] = True
    v[fixed] = 0.0
    fext = rng.normal(size=(n, 3))
    kext = np.zeros((n, 3, 3))
    dext = np.zeros((n, 3, 3))
    nrm = rng.normal(size=3)
    nrm /= np.linalg.norm(nrm)
    kext[3] = -500.0 * np.outer(nrm, nrm)  # a contact-like stiff block on one point
    dext[3] = -2.0 * np.outer(nrm, nrm)
    g = np.array([0, 0, -9.81])
    h = 1e-2
    f, Kd, Dd = dense_jacobians(x, v, m, si, sj, l0, k, kd, tonly, 0.2, g, fext, kext, dext)
    A = np.diag(np.repeat(m, 3)) - theta * h * Dd - (theta * h) ** 2 * Kd
    dv_ref = solve_free(A, h * (f + theta * h * Kd @ v.ravel()), fixed)
    x1, v1 = x.copy(), v.copy()
    K.implicit_step(network(x1, v1, m, si, sj, l0, k, kd, tonly, 0.2, g, fixed),
                    K.Load(fext, kext, dext, np.zeros_like(x)), np.zeros_like(x), h,
                    scheme(theta, False, np.zeros_like(x), np.zeros_like(x), 1e-12), False)
    # CG to a 1e-12 relative residual: dv agrees to ~1e-10 relative to its size
    np.testing.assert_allclose(v1 - v, dv_ref, atol=1e-9 * np.abs(dv_ref).max())
    np.testing.assert_allclose(x1, x + h * (v + theta * dv_ref), atol=1e-9)
    assert np.all(x1[fixed] == x[fixed])


def test_implicit_step_with_a_body_matches_dense_solve():
    # a free body (a ball) touching two points: its velocity is an unknown of the same
    # backward Euler solve, each contact a coupling C = h D + h^2 K between point and body
    x, v, m, si, sj, l0, k, kd, tonly = random_network(seed=8)
    n = len(x)
    rng = np.random.default_rng(9)
    fixed = np.zeros(n, dtype=bool)
    fixed[0] = True
    v[fixed] = 0.0
    g = np.array([0, 0, -9.81])
    h, M, a_b = 1e-2, 0.7, g
    v_b = rng.normal(size=3)
    pts = np.array([3, 7])
    nrm = [u / np.linalg.norm(u) for u in rng.normal(size=(2, 3))]
    lf = K.PointForces(pts, rng.normal(size=(2, 3)),
                       np.array([-800.0 * np.outer(u, u) for u in nrm]),
                       np.array([-3.0 * np.outer(u, u) for u in nrm]),
                       np.array([v_b, v_b]))
    kext, dext = np.zeros((n, 3, 3)), np.zeros((n, 3, 3))
    fext, kvref = np.zeros((n, 3)), np.zeros((n, 3))
    for e, i in enumerate(pts):  # the contacts' share of the points' load, as a contact adds it
        fext[i] += lf.f[e]
        kext[i] += lf.dfdx[e]
        dext[i] += lf.dfdv[e]
        kvref[i] += lf.dfdx[e] @ lf.vref[e]
    f, Kd, Dd = dense_jacobians(x, v, m, si, sj, l0, k, kd, tonly, 0.2, g, fext, kext, dext)
    big = 3 * n + 3
    A = np.zeros((big, big))
    A[:3 * n, :3 * n] = np.diag(np.repeat(m, 3)) - h * Dd - h * h * Kd
    A[3 * n:, 3 * n:] = M * np.eye(3)
    rhs = np.zeros(big)
    rhs[:3 * n] = h * (f + h * Kd @ v.ravel() - h * kvref.ravel())
    rhs[3 * n:] = h * M * a_b
    for e, i in enumerate(pts):
        C = h * lf.dfdv[e] + h * h * lf.dfdx[e]
        A[3 * i:3 * i + 3, 3 * n:] += C
        A[3 * n:, 3 * i:3 * i + 3] += C.T
        A[3 * n:, 3 * n:] -= C
        rhs[3 * n:] -= h * (lf.f[e] + lf.dfdx[e] @ (h * v[i] - h * lf.vref[e]))
    dv_ref = solve_free(A, rhs, np.append(fixed, False))
    x1, v1 = x.copy(), v.copy()
    dv_b, flin = np.zeros((1, 3)), np.zeros((2, 3))
    K.implicit_step_with_bodies(
        network(x1, v1, m, si, sj, l0, k, kd, tonly, 0.2, g, fixed),
        K.Load(fext, kext, dext, kvref), np.zeros_like(x), h,
        scheme(1.0, False, np.zeros_like(x), np.zeros_like(x), 1e-13), False,
        K.Bodies(np.array([M]), v_b[None].copy(), a_b[None].copy(), np.zeros(2, np.int64), lf,
                 2, dv_b, flin))
    # CG to a 1e-13 relative residual: the velocities agree to ~1e-10 of their size
    scale = np.abs(dv_ref).max()
    np.testing.assert_allclose(v1 - v, dv_ref[:n], atol=1e-9 * scale)
    np.testing.assert_allclose(dv_b[0], dv_ref[n], atol=1e-9 * scale)
    # equal and opposite: the body's momentum change is gravity's impulse minus the points'
    # linearised contact forces, which are what the points integrated with
    np.testing.assert_allclose(M * dv_b[0], h * M * a_b - h * flin.sum(axis=0),
                               atol=1e-9 * M * scale)
    for e, i in enumerate(pts):
        want = lf.f[e] + lf.dfdx[e] @ (h * v1[i] - h * lf.vref[e] - h * dv_b[0]) \
            + lf.dfdv[e] @ (v1[i] - v[i] - dv_b[0])
        np.testing.assert_allclose(flin[e], want, atol=1e-9 * np.abs(want).max())


def test_bdf2_step_matches_dense_solve():
    # BDF2 is the theta-type system with hs = 2h/3 and a right-hand side that remembers the
    # previous step: M (v - vp) / 3 + hs (f + K y), y = (x - xp) / 3 + hs v
    x, v, m, si, sj, l0, k, kd, tonly = random_network(seed=5)
    n = len(x)
    fixed = np.zeros(n, dtype=bool)
    g = np.array([0, 0, -9.81])
    z3, z33 = np.zeros((n, 3)), np.zeros((n, 3, 3))
    h = 5e-3
    xp, vp = np.zeros_like(x), np.zeros_like(x)
    x1, v1 = x.copy(), v.copy()
    K.implicit_step(network(x1, v1, m, si, sj, l0, k, kd, tonly, 0.0, g, fixed),
                    K.Load(z3, z33, z33, z3), np.zeros_like(x), h, scheme(1.0, True, xp, vp, 1e-13),
                    False)
    np.testing.assert_array_equal(xp, x)  # the first step is backward Euler and records x, v
    # the dense BDF2 step from (x1, v1) with previous state (x, v)
    hs = 2 * h / 3
    f, Kd, Dd = dense_jacobians(x1, v1, m, si, sj, l0, k, kd, tonly, 0.0, g, z3, z33, z33)
    A = np.diag(np.repeat(m, 3)) - hs * Dd - hs * hs * Kd
    y = ((x1 - x) / 3 + hs * v1).ravel()
    rhs = np.repeat(m, 3) * (v1 - v).ravel() / 3 + hs * (f + Kd @ y)
    dv_ref = solve_free(A, rhs, fixed)
    x2, v2 = x1.copy(), v1.copy()
    K.implicit_step(network(x2, v2, m, si, sj, l0, k, kd, tonly, 0.0, g, fixed),
                    K.Load(z3, z33, z33, z3), np.zeros_like(x), h, scheme(1.0, True, xp, vp, 1e-13),
                    True)
    np.testing.assert_allclose(v2 - v1, dv_ref, atol=1e-8 * np.abs(dv_ref).max())
    np.testing.assert_allclose(x2, x1 + (x1 - x) / 3 + hs * (v1 + dv_ref), atol=1e-10)


def brute_closest(c, a, b, samples=200001):
    t = np.linspace(0, 1, samples)
    p = a[None] + t[:, None] * (b - a)[None]
    d = np.linalg.norm(p - c, axis=1)
    i = np.argmin(d)
    return t[i], d[i]


def test_sphere_elements_against_brute_force():
    rng = np.random.default_rng(7)
    n = 30
    x = rng.uniform(-0.3, 0.3, size=(n, 3))
    seg = np.array([(i, (i + 1) % n) for i in range(n)], dtype=np.int64)
    c = np.zeros(3)
    R, th, cs = 0.2, 0.01, 1000.0
    out = K.point_forces(2 * len(seg))
    wrench = np.zeros(6)
    zeros = np.zeros((n, 3))
    ball = Sphere(c, np.zeros(3), np.zeros(3), R, 1.0, np.zeros(3))
    pts = K.Points(x, zeros, np.ones(n), np.zeros(n, bool))
    law = np.array([th, cs, 0.0, 0.0, 0.05, 0.0])
    cnt = sphere_elements(ball, pts, zeros, seg, law, -1.0, out, True, wrench)
    f = out.f
    expected = np.zeros(3)
    touching = 0
    for a, b in seg:
        t, d = brute_closest(c, x[a], x[b])
        if d < R + th:
            touching += 1
            q = x[a] + t * (x[b] - x[a])
            expected += cs * (R + th - d) * (c - q) / d
    assert cnt == 2 * touching
    # brute-force sampling resolves t to 5e-6 of a ~0.5 m segment: ~3e-6 m of distance
    np.testing.assert_allclose(wrench[:3], expected, atol=cs * 1e-5 * max(touching, 1))
    # equal and opposite: the forces on the points sum to minus the force on the sphere
    np.testing.assert_allclose(f[:cnt].sum(axis=0), -wrench[:3], atol=1e-12)


def free_net_and_ball():
    """The basketball's net free in space (no gravity, anchors or damping: its momentum changes
    only by the contact) and a 0.68 kg ball flying into it: (net bundle, its v (n,3), its
    masses, cord pairs, the ball as Colliders, zero (n,3) and (n,3,3) arrays)."""
    from interplay.geometry.net import NetParams, net_knots
    x, pairs = net_knots(NetParams())
    n = len(x)
    l0 = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    k = 300.0 / l0
    m = np.full(n, 0.03 / n)
    v = np.zeros_like(x)
    cols = Colliders(np.array([[0.05, 0.0, 3.05]]), np.array([[0.3, 0.0, -4.0]]),
                     np.zeros((1, 3)), np.zeros((1, 3)), np.array([0.12]), np.array([0.68]),
                     np.array([[0.003, 2e3, 0.5, 1.0, 0.05, 1.0]]), np.zeros((1, 7)))
    net = network(x, v, m, pairs[:, 0].copy(), pairs[:, 1].copy(), l0, k, 2e-4 * k,
                  np.ones(len(l0), bool), 0.0, np.zeros(3))
    return net, v, m, pairs, cols, np.zeros((n, 3)), np.zeros((n, 3, 3))


def test_subcycled_contact_conserves_momentum():
    # the explicit net's momentum gain equals the impulse the sphere receives, with opposite
    # sign, to round-off
    net, v, m, pairs, cols, z3, z33 = free_net_and_ball()
    explicit = K.Scheme(False, 1.0, False, 1e-8, 100, z3, z3)
    total = np.zeros(3)
    for _ in range(100):
        advance_with_colliders(net, K.Load(z3, z33, z33, z3), np.zeros_like(z3), 1e-3, 20,
                               explicit, False, cols, pairs)
        total += cols.impulses[0, :3]
        cols.centres[:] += cols.velocities * 1e-3
    assert np.linalg.norm(total) > 1e-3  # the sphere really hit the net
    np.testing.assert_allclose((m[:, None] * v).sum(axis=0), -total, atol=1e-12)


@pytest.mark.parametrize("nsub", [1, 4])
def test_implicit_subcycled_contact_with_a_free_ball_conserves_momentum(nsub):
    # the implicit net solves the ball's velocity with its knots and hands it minus the
    # forces the knots integrated with: the net's momentum gain equals minus the ball's
    # impulse to the CG's 1e-12 residual
    net, v, m, pairs, cols, z3, z33 = free_net_and_ball()
    implicit = K.Scheme(True, 1.0, False, 1e-12, 2000, z3.copy(), z3.copy())
    total = np.zeros(3)
    h = 1e-3
    for _ in range(100):
        advance_with_colliders(net, K.Load(z3, z33, z33, z3), np.zeros_like(z3), h, nsub,
                               implicit, False, cols, pairs)
        total += cols.impulses[0, :3]
        # the ball as its rigid step moves it: the step's mean force, held
        dv = cols.impulses[0, :3] / 0.68
        cols.centres[:] += h * (cols.velocities + 0.5 * dv)
        cols.velocities[:] += dv
    assert np.linalg.norm(total) > 1e-3  # the ball really hit the net
    np.testing.assert_allclose((m[:, None] * v).sum(axis=0), -total,
                               atol=1e-9 * np.linalg.norm(total))
