"""Kernels against plain NumPy references (slow but obviously right)."""
import numpy as np
import pytest

from interplay.kernels import springs as K
from interplay.kernels.contact import sphere_segments
from interplay.kernels.subcycle import substep_with_spheres


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


NO_ANCHORS = (np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0), np.zeros(0))


def test_network_forces_match_numpy():
    x, v, m, si, sj, l0, k, kd, tonly = random_network()
    g = np.array([0, 0, -9.81])
    fext = np.random.default_rng(1).normal(size=x.shape)
    f = np.zeros_like(x)
    K.network_forces(x, v, m, si, sj, l0, k, kd, tonly, *NO_ANCHORS, 0.3, g, fext, f)
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
    K.implicit_step(x1, v1, m, fixed, si, sj, l0, k, kd, tonly, *NO_ANCHORS, 0.2, g, fext, kext,
                    dext, np.zeros_like(x), np.zeros_like(x), h, theta, False, False,
                    np.zeros_like(x), np.zeros_like(x), 1e-12, 500)
    # CG to a 1e-12 relative residual: dv agrees to ~1e-10 relative to its size
    np.testing.assert_allclose(v1 - v, dv_ref, atol=1e-9 * np.abs(dv_ref).max())
    np.testing.assert_allclose(x1, x + h * (v + theta * dv_ref), atol=1e-9)
    assert np.all(x1[fixed] == x[fixed])


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
    K.implicit_step(x1, v1, m, fixed, si, sj, l0, k, kd, tonly, *NO_ANCHORS, 0.0, g, z3, z33, z33,
                    z3, np.zeros_like(x), h, 1.0, True, False, xp, vp, 1e-13, 500)
    np.testing.assert_array_equal(xp, x)  # the first step is backward Euler and records x, v
    # the dense BDF2 step from (x1, v1) with previous state (x, v)
    hs = 2 * h / 3
    f, Kd, Dd = dense_jacobians(x1, v1, m, si, sj, l0, k, kd, tonly, 0.0, g, z3, z33, z33)
    A = np.diag(np.repeat(m, 3)) - hs * Dd - hs * hs * Kd
    y = ((x1 - x) / 3 + hs * v1).ravel()
    rhs = np.repeat(m, 3) * (v1 - v).ravel() / 3 + hs * (f + Kd @ y)
    dv_ref = solve_free(A, rhs, fixed)
    x2, v2 = x1.copy(), v1.copy()
    K.implicit_step(x2, v2, m, fixed, si, sj, l0, k, kd, tonly, *NO_ANCHORS, 0.0, g, z3, z33, z33,
                    z3, np.zeros_like(x), h, 1.0, True, True, xp, vp, 1e-13, 500)
    np.testing.assert_allclose(v2 - v1, dv_ref, atol=1e-8 * np.abs(dv_ref).max())
    np.testing.assert_allclose(x2, x1 + (x1 - x) / 3 + hs * (v1 + dv_ref), atol=1e-10)


def brute_closest(c, a, b, samples=200001):
    t = np.linspace(0, 1, samples)
    p = a[None] + t[:, None] * (b - a)[None]
    d = np.linalg.norm(p - c, axis=1)
    i = np.argmin(d)
    return t[i], d[i]


def test_sphere_segments_against_brute_force():
    rng = np.random.default_rng(7)
    n = 30
    x = rng.uniform(-0.3, 0.3, size=(n, 3))
    seg = np.array([(i, (i + 1) % n) for i in range(n)], dtype=np.int64)
    c = np.zeros(3)
    R, th, cs = 0.2, 0.01, 1000.0
    ns = len(seg)
    idx = np.zeros(2 * ns, np.int64)
    f = np.zeros((2 * ns, 3))
    kx = np.zeros((2 * ns, 3, 3))
    dx = np.zeros((2 * ns, 3, 3))
    vr = np.zeros((2 * ns, 3))
    wrench = np.zeros(6)
    zeros = np.zeros((n, 3))
    cnt = sphere_segments(c, np.zeros(3), np.zeros(3), R, 1.0, np.zeros(3), x, zeros,
                          np.ones(n), zeros, seg, th, cs, 0.0, 0.0, 0.05, False, -1.0, idx, f, kx, dx,
                          vr, wrench)
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


def test_subcycled_contact_conserves_momentum():
    # a free net (no gravity, anchors or damping) hit by a moving sphere: the net's momentum
    # gain equals the impulse the sphere receives, with opposite sign, to round-off
    from interplay.geometry.net import NetParams, net_knots
    x, pairs = net_knots(NetParams())
    n = len(x)
    l0 = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    k = 300.0 / l0
    m = np.full(n, 0.03 / n)
    v = np.zeros_like(x)
    p0 = (m[:, None] * v).sum(axis=0)
    centres = np.array([[0.05, 0.0, 3.05]])
    vel = np.array([[0.3, 0.0, -4.0]])
    imp = np.zeros((1, 7))
    params = np.array([[0.003, 2e3, 0.5, 1.0, 0.05, 1.0]])
    z3 = np.zeros((n, 3))
    z33 = np.zeros((n, 3, 3))
    total = np.zeros(3)
    for _ in range(100):
        substep_with_spheres(x, v, m, np.zeros(n, bool), pairs[:, 0].copy(), pairs[:, 1].copy(),
                             l0, k, 2e-4 * k, np.ones(len(l0), bool), *NO_ANCHORS, 0.0,
                             np.zeros(3), z3, z33, z33, z3, np.zeros_like(x), 1e-3, 20, False,
                             1.0, False, False, z3, z3, 1e-8, 100, pairs, centres, vel, np.zeros((1, 3)),
                             np.array([0.12]), np.array([0.68]), np.zeros((1, 3)), params, imp)
        total += imp[0, :3]
        centres += vel * 1e-3
    p1 = (m[:, None] * v).sum(axis=0)
    assert np.linalg.norm(total) > 1e-3  # the sphere really hit the net
    np.testing.assert_allclose(p1 - p0, -total, atol=1e-12)
