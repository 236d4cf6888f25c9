"""Spring-mass networks: closed-form oscillation, damping rates, energy, the elastic catenary."""
import numpy as np
import pytest
from scipy.optimize import brentq

from interplay.errors import ParameterError, SceneError, StabilityError
from interplay.systems.springmass import SpringNetwork, Springs


def oscillator(k=100.0, m=0.5, integrator="explicit", dt=1e-4, alpha=0.0, beta=0.0, x0=0.01,
               scheme="theta"):
    """One free point on a spring to a fixed point, no gravity, displaced by x0 along x."""
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    springs = Springs.from_ratio(x, [(0, 1)], k * 1.0)  # k = ratio / l0 with l0 = 1 m
    net = SpringNetwork("osc", x, [1.0, m], springs, dt=dt, integrator=integrator,
                        mass_damping=alpha, stiffness_damping=beta, fixed=[0],
                        gravity=(0, 0, 0), scheme=scheme)
    net.x[1, 0] += x0
    return net


def run(net, seconds, h):
    xs, ts = [], []
    for i in range(int(round(seconds / h))):
        net.clear_forces()
        net.advance(h)
        xs.append(net.x[1, 0] - 1.0)
        ts.append((i + 1) * h)
    return np.array(ts), np.array(xs)


def period(ts, xs):
    """Mean period from upward zero crossings (linear interpolation between samples)."""
    i = np.flatnonzero((xs[:-1] < 0) & (xs[1:] >= 0))
    tc = ts[i] - xs[i] * (ts[i + 1] - ts[i]) / (xs[i + 1] - xs[i])
    return np.mean(np.diff(tc))


@pytest.mark.parametrize("integrator", ["explicit", "implicit"])
def test_mass_on_spring_period(integrator):
    k, m = 100.0, 0.5
    T = 2 * np.pi * np.sqrt(m / k)
    h = T / 2000
    net = oscillator(k, m, integrator, dt=h)
    ts, xs = run(net, 5 * T, h)
    # phase error of symplectic and backward Euler is O((w h)^2) = (2 pi / 2000)^2 ~ 1e-5;
    # the crossing interpolation adds O(h^2 / T^2): 1e-4 relative is a safe bound for both.
    assert period(ts, xs) == pytest.approx(T, rel=1e-4)


def test_bdf2_keeps_the_amplitude_backward_euler_damps():
    # per step, backward Euler multiplies a mode's amplitude by ~1 - (w h)^2 / 2 and BDF2 by
    # ~1 - (w h)^4 / 4: at w h = 2 pi / 1000 over 4 periods (4000 steps) that is a 7.6% loss
    # for backward Euler and ~1e-6 for BDF2
    k, m = 100.0, 0.5
    T = 2 * np.pi * np.sqrt(m / k)
    h = T / 1000
    amp = {}
    for scheme in ("theta", "bdf2"):
        ts, xs = run(oscillator(k, m, "implicit", dt=h, scheme=scheme), 5 * T, h)
        amp[scheme] = np.max(np.abs(xs[ts > 4 * T])) / 0.01
        assert period(ts, xs) == pytest.approx(T, rel=2e-4)
    # the largest |x| of the last period is at its start, after 4000 steps
    assert amp["theta"] == pytest.approx(np.exp(-0.5 * (2 * np.pi / 1000) ** 2 * 4000), rel=5e-3)
    assert amp["bdf2"] == pytest.approx(1.0, abs=2e-3)


def test_energy_conserved_without_damping():
    k, m = 100.0, 0.5
    T = 2 * np.pi * np.sqrt(m / k)
    h = T / 1000
    net = oscillator(k, m, "explicit", dt=h)
    ts, xs = run(net, 10 * T, h)
    e0 = 0.5 * k * 0.01 ** 2
    e = net.kinetic_energy() + 0.5 * k * (net.x[1, 0] - 1.0) ** 2
    # symplectic Euler conserves a shadow energy: the true energy oscillates by O(w h) ~ 0.6%
    assert e == pytest.approx(e0, rel=1e-2)
    assert np.max(np.abs(xs)) == pytest.approx(0.01, rel=1e-2)


def test_mass_proportional_damping_rate():
    # f = -alpha m v: amplitude decays as exp(-alpha t / 2)
    k, m, alpha = 100.0, 0.5, 0.4
    T = 2 * np.pi * np.sqrt(m / k)
    h = T / 2000
    ts, xs = run(oscillator(k, m, "explicit", dt=h, alpha=alpha), 20 * T, h)
    peaks = [np.max(np.abs(xs[(ts >= a) & (ts < a + T)])) for a in (0.0, 19 * T)]
    rate = np.log(peaks[0] / peaks[1]) / (19 * T)
    # the envelope rate is exact to O(zeta^2) = (alpha / 2w)^2 ~ 2e-4 and peak sampling to O(h)
    assert rate == pytest.approx(alpha / 2, rel=1e-2)


def test_stiffness_proportional_damping_rate():
    # kd = beta k along the spring: zeta w = beta k / (2 m), amplitude ~ exp(-beta k t / 2m)
    k, m, beta = 100.0, 0.5, 2e-3
    T = 2 * np.pi * np.sqrt(m / k)
    h = T / 2000
    ts, xs = run(oscillator(k, m, "explicit", dt=h, beta=beta), 20 * T, h)
    peaks = [np.max(np.abs(xs[(ts >= a) & (ts < a + T)])) for a in (0.0, 19 * T)]
    rate = np.log(peaks[0] / peaks[1]) / (19 * T)
    assert rate == pytest.approx(beta * k / (2 * m), rel=1e-2)


def _two_springs(kd, dt=1e-4, integrator="explicit", **kw):
    """A free point between two fixed ones along x, the first spring with its own damping
    kd (N s/m), the second with none; no gravity."""
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    springs = Springs.from_ratio(x, [(0, 1), (1, 2)], 50.0)  # k = 50 N/m each
    return SpringNetwork("two", x, [1.0, 0.5, 1.0], springs, dt=dt, integrator=integrator,
                         spring_damping=[kd, 0.0], fixed=[0, 2], gravity=(0, 0, 0), **kw)


def test_a_refused_step_advises_one_that_passes_every_criterion():
    """The point between the springs: m = 0.5 kg, sum k = 100 N/m, c = kd / m = 40 1/s at
    kd = 20 N s/m. The criteria in closed form: undamped h < sqrt(2 m / sum k) = 0.1 s,
    damping h < 2 / c = 0.05 s, a share of 2.5: 200 h^2 + 80 h <= 2.5, h = 0.02913 s. Each
    criterion refuses its own range and every message advises the smallest bound (rounded
    down), at which the network builds: following the advice is never refused again."""
    share = (np.sqrt(80.0 ** 2 + 4 * 200 * 2.5) - 80.0) / 400.0
    net = _two_springs(20.0, dt=1e-3, stability_share=2.5)
    b = net.explicit_bounds()
    assert b["stiffness"] == pytest.approx(0.1, rel=1e-12)
    assert b["damping"] == pytest.approx(0.05, rel=1e-12)
    assert b["share"] == pytest.approx(share, rel=1e-12)
    for dt, what in ((0.2, "explicit stability bound"), (0.06, "damping rate"),
                     (0.03, "stability number")):
        with pytest.raises(StabilityError, match=f"{what}.*use step < 0.0291 s, or less k"):
            _two_springs(20.0, dt=dt, stability_share=2.5, dt_key="step", step_cure="less k")
    _two_springs(20.0, dt=0.0291, stability_share=2.5)


def test_a_springs_own_damping_rate():
    # one spring of two damped by its own kd (no beta): zeta w = kd / (2 m) on the point
    # between them (k = 100 N/m in all, m = 0.5 kg), amplitude ~ exp(-kd t / 2m); the
    # envelope is exact to O(zeta^2) ~ 1e-4 and peak sampling to O(h): 1%, as for beta
    kd, m = 0.2, 0.5
    T = 2 * np.pi * np.sqrt(m / 100.0)
    h = T / 2000
    net = _two_springs(kd, dt=h)
    assert net.kd.tolist() == [kd, 0.0]  # beta k (0 here) plus each spring's own
    net.x[1, 0] += 0.01
    ts, xs = run(net, 20 * T, h)
    peaks = [np.max(np.abs(xs[(ts >= a) & (ts < a + T)])) for a in (0.0, 19 * T)]
    rate = np.log(peaks[0] / peaks[1]) / (19 * T)
    assert rate == pytest.approx(kd / (2 * m), rel=1e-2)


def test_a_springs_own_damping_past_the_explicit_bound_is_refused():
    # h sum(kd) / m >= 2 takes more than twice a point's velocity away per step: refused,
    # naming the rate and the largest step; the implicit step takes it; local/global,
    # whose constant matrix damps with beta alone, refuses springs' own damping
    with pytest.raises(StabilityError, match=r"damping rate 2e\+03 1/s .* use dt < 0.001 s"):
        _two_springs(1000.0, dt=1e-3)
    _two_springs(1000.0, dt=1e-3, integrator="implicit")
    with pytest.raises(ParameterError, match="own damping need the explicit or implicit"):
        _two_springs(1.0, integrator="localglobal")
    with pytest.raises(ParameterError, match="own damping must be finite and >= 0"):
        _two_springs(-1.0)


def elastic_catenary(span, L0, w, EA, s):
    """Irvine's elastic catenary between supports at equal height, by unstretched arc length s.

    w: weight per unstretched length (N/m); returns (x(s), z(s)) with the left support at 0.
    The horizontal tension H is found with a root finder so that x(L0) = span.
    """
    V = w * L0 / 2

    def x_of(H, s):
        return H * s / EA + H / w * (np.arcsinh(V / H) - np.arcsinh((V - w * s) / H))

    H = brentq(lambda H: x_of(H, L0) - span, 1e-6, 1e6)
    z = (w * s / EA) * (V / w - s / 2) + H / w * (np.sqrt(1 + (V / H) ** 2)
                                                  - np.sqrt(1 + ((V - w * s) / H) ** 2))
    return x_of(H, s), -z


def test_chain_rests_on_the_elastic_catenary():
    N, span, L0, rho, EA = 40, 1.0, 1.3, 0.2, 50.0  # springs, m, m, kg/m, N
    g = 9.81
    s = np.linspace(0, L0, N + 1)
    # start on a parabola-ish sag so the springs begin near their rest lengths
    x0 = np.stack([s * span / L0, 0 * s, -0.3 * np.sin(np.pi * s / L0)], axis=1)
    pairs = [(i, i + 1) for i in range(N)]
    springs = Springs.from_ratio(x0, pairs, EA)
    springs = Springs(springs.i, springs.j, np.full(N, L0 / N), np.full(N, EA / (L0 / N)),
                      springs.tension_only)
    m = np.full(N + 1, rho * L0 / N)
    m[[0, -1]] /= 2
    net = SpringNetwork("chain", x0, m, springs, integrator="implicit", dt=1e-3, fixed=[0, N])
    net.settle()
    xc, zc = elastic_catenary(span, L0, rho * g, EA, s)
    sag = -zc.min()
    # lumping the weight at N nodes changes the shape by O((L0/N)^2 / L0^2) ~ 1e-3 of the sag
    np.testing.assert_allclose(net.x[:, 2], zc, atol=2e-3 * sag)
    np.testing.assert_allclose(net.x[:, 0], xc, atol=2e-3 * sag)


def test_a_remembered_sag_is_the_sag_of_that_network_only():
    # settle remembers its result per network (compare's builds settle once): the same
    # network again gets the same positions, bit for bit, and one spring stiffer a new sag
    def chain(ea):
        x0 = np.stack([np.linspace(0, 1, 11), np.zeros(11), np.zeros(11)], axis=1)
        sp = Springs.from_ratio(x0, [(i, i + 1) for i in range(10)], ea)
        net = SpringNetwork("chain", x0, np.full(11, 0.01), sp, integrator="implicit",
                            dt=1e-3, fixed=[0, 10])
        net.settle()
        return net.x.copy()
    first, again, stiffer = chain(20.0), chain(20.0), chain(40.0)
    np.testing.assert_array_equal(first, again)
    # the softer chain sags further: by about twice as much for this elastic sag
    assert first[:, 2].min() < stiffer[:, 2].min() - 1e-3


def test_the_settled_basketball_net_rests_where_a_long_relaxation_ends():
    # settle is the minimum of the potential energy (Newton on the stiffness): at it every
    # knot's springs balance its weight, and 20 s of heavily damped backward Euler (the
    # slow reference: the net's slowest sag mode decays as exp(-omega^2 t / alpha)) ends
    # there too. Tolerance: the relaxation's last residual force r over the cords' stiffness
    # near the bottom (k ~ 10 N/m per cord at 0.2 g knots) is < 0.1 mm; 0.5 mm stated.
    from interplay.scenes.basketball import BasketballParams, basketball_net
    from interplay.systems.relaxation import relax

    net = basketball_net(BasketballParams().net)
    start = net.x.copy()
    net.settle()
    settled = net.x.copy()
    weight = net.m.max() * 9.81
    net.fext[:] = 0.0
    assert np.abs(net.internal_forces()[~net.fixed]).max() < 1e-6 * weight
    assert start[:, 2].min() - settled[:, 2].min() > 0.05  # it sags: ~13 cm at the bottom
    net.x[:] = start
    relax(net, 20.0, 5e-3, 5.0)
    assert np.abs(net.x - settled).max() < 5e-4


def test_a_point_on_no_taut_spring_has_no_rest():
    # a free point joined by a slack cord only and to nothing below it falls for ever: the
    # settle says which network and what to fix, rather than returning a shape mid-fall
    x = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -0.5]])
    sp = Springs(np.array([0]), np.array([1]), np.array([1.0]), np.array([10.0]),
                 np.array([False]))
    net = SpringNetwork("loose", x, np.array([0.1, 0.1]), sp, integrator="implicit", dt=1e-3,
                        fixed=[])
    with pytest.raises(SceneError, match="'loose'.*no rest under gravity.*anchor"):
        net.settle()


def test_explicit_step_above_bound_is_refused():
    with pytest.raises(StabilityError, match=r"explicit stability bound .* --integrator implicit"):
        oscillator(k=1e6, m=1e-3, integrator="explicit", dt=1e-3)


def test_bad_network_input():
    x = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    sp = Springs.from_ratio(x, [(0, 1)], 10.0)
    with pytest.raises(ParameterError, match="mass of point 1"):
        SpringNetwork("n", x, [1.0, -2.0], sp)
    with pytest.raises(ParameterError, match="point 0 is not finite"):
        SpringNetwork("n", np.array([[np.nan, 0, 0], [1, 0, 0]]), 1.0, sp)
    with pytest.raises(ParameterError, match="zero rest length"):
        SpringNetwork("n", np.array([[0.0, 0, 0], [0, 0, 0]]), 1.0,
                      Springs.from_ratio(np.zeros((2, 3)), [(0, 1)], 10.0))
    with pytest.raises(ParameterError, match="non-positive stiffness"):
        SpringNetwork("n", x, 1.0, Springs.from_ratio(x, [(0, 1)], 0.0))
    with pytest.raises(ParameterError, match="unknown integrator"):
        SpringNetwork("n", x, 1.0, sp, integrator="rk4")
