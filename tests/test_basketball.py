"""The basketball through a net: the paper's Figure 2 and Table I row, in all three modes."""
import dataclasses

import numpy as np
import pytest

from interplay.analysis.fitting import fit_standin
from interplay.scenes import basketball as B

CHECK = B.CHECKPOINTS


@pytest.fixture(scope="module")
def runs():
    return {mode: B.build(mode).simulate() for mode in ("two-way", "one-way", "hybrid")}


@pytest.fixture(scope="module")
def reference():
    """The explicit net at the paper's 1e-5 s, in strict lock step with the ball."""
    p = dataclasses.replace(B.BasketballParams(), coupling_dt=1e-5)
    return B.build("two-way", dt=1e-5, params=p).simulate()


def speed(result, t):
    return np.linalg.norm(result.state_at("ball", t)[1][:3])


def free_speed(t):
    v0 = np.array(B.BasketballParams().ball.velocity)
    return np.linalg.norm(v0 + np.array([0, 0, -9.81]) * t)


def test_two_way_ball_slows_in_the_net(runs):
    r = runs["two-way"]
    assert speed(r, B.FIT_TIME) < 0.9 * free_speed(B.FIT_TIME)


def test_table_one_row_is_reproduced_in_magnitude(runs):
    # paper: max 59.9 N, mean over contact 15.7 N on the 0.68 kg ball
    s = next(s for s in runs["two-way"].interaction_stats() if s["name"] == "ball-net")
    assert 30.0 <= s["force_N"]["max"] <= 120.0
    assert 8.0 <= s["force_N"]["mean"] <= 32.0
    assert s["acceleration_m_s2"]["mean"] == pytest.approx(s["force_N"]["mean"] / 0.68)


def test_one_way_strains_the_net_more(runs):
    strain = {m: r.diagnostics["net"]["max_strain"] for m, r in runs.items()}
    assert strain["one-way"] > strain["two-way"]


def test_default_hybrid_field_matches_two_way_exit_speed(runs):
    # the default field coefficients were fitted to this two-way run
    assert speed(runs["hybrid"], B.FIT_TIME) == pytest.approx(speed(runs["two-way"], B.FIT_TIME),
                                                               rel=0.10)


def test_hybrid_primary_pass_is_the_cheap_part(runs):
    r = runs["hybrid"]
    assert r.passes[0]["systems"] == ["ball"] and r.passes[0]["steps"] == 1500


def test_subcycled_default_follows_the_lock_step_reference(runs, reference):
    # the net sub-cycles the contact at 1e-5 s inside 1e-3 s coupling steps; the reference
    # runs net and ball in lock step at 1e-5 s. The ball's predicted path inside a step is
    # off by the change of its own acceleration, ~ (100 m/s^2) h^2 / 2 = 0.05 mm per step,
    # and the contact is chaotic (stick-slip on the cords), so allow the 1 cm.
    for t in CHECK:
        d = np.linalg.norm(runs["two-way"].state_at("ball", t)[0][:3]
                           - reference.state_at("ball", t)[0][:3])
        assert d < 0.01, f"t={t}: {d:.4f} m from the reference"


def _linearised_radius(net, h):
    """The spectral radius of a network's symplectic Euler step of h (s), linearised at its
    current (taut) state: x'' = -M^-1 (K x + D x'), K the springs' and anchors' stiffness,
    D their damping along each taut spring plus alpha M; free points only."""
    free = np.flatnonzero(~net.fixed)
    slot = np.full(len(net.x), -1)
    slot[free] = np.arange(len(free))
    n = 3 * len(free)
    K, D = np.zeros((n, n)), np.zeros((n, n))
    d = net.x[net.si] - net.x[net.sj]
    ln = np.linalg.norm(d, axis=1)
    for s, (a, b) in enumerate(zip(net.si, net.sj)):
        if net.tension_only[s] and ln[s] <= net.l0[s]:
            continue
        u = d[s] / ln[s]
        uu = np.outer(u, u)
        kb = net.k[s] * (uu + (1 - net.l0[s] / ln[s]) * (np.eye(3) - uu))
        for p, q, sign in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
            if slot[p] >= 0 and slot[q] >= 0:
                K[3 * slot[p]:3 * slot[p] + 3, 3 * slot[q]:3 * slot[q] + 3] += sign * kb
                D[3 * slot[p]:3 * slot[p] + 3, 3 * slot[q]:3 * slot[q] + 3] += \
                    sign * net.kd[s] * uu
    for p, ka in zip(net.a_idx, net.a_k):
        if slot[p] >= 0:
            K[3 * slot[p]:3 * slot[p] + 3, 3 * slot[p]:3 * slot[p] + 3] += ka * np.eye(3)
    m = np.repeat(net.m[free], 3)
    D += np.diag(net.alpha * m)
    mk, md, eye = K / m[:, None], D / m[:, None], np.eye(n)
    step = np.block([[eye - h * h * mk, h * (eye - h * md)], [-h * mk, eye - h * md]])
    return float(np.abs(np.linalg.eigvals(step)).max())


def test_the_net_out_of_the_balls_reach_takes_its_own_step(runs, monkeypatch):
    # while the ball cannot reach the net (before it arrives, after it left) the net steps at
    # its free_step (2.3e-5 s here) instead of the contact's 1e-5 s; the ball never notices:
    # before the ball the net rests (its forces balance), so the coarser steps change only
    # round-off; measured 4 um at 0.6 s, 0.1 mm allowed.
    from interplay.systems.explicit_stability import FREE_SHARE
    from interplay.systems.springmass import SpringNetwork
    net = next(s for s in B.build("two-way").systems if s.name == "net")
    w2 = np.zeros(len(net.x))
    np.add.at(w2, net.si, net.k)
    np.add.at(w2, net.sj, net.k)
    np.add.at(w2, net.a_idx, net.a_k)
    on = ~net.fixed
    h, c = net.free_step(), net.damping_rates()[on]
    # h^2 w^2 + 2 h c reaches FREE_SHARE at the worst point and stays under it at every other
    assert np.max(h * h * w2[on] / net.m[on] + 2 * h * c) == pytest.approx(FREE_SHARE,
                                                                           rel=1e-12)
    assert h > 2 * net.dt
    # and it is stable with a margin: the net's symplectic Euler step linearised at its rest
    # (stiffness and damping matrices; the slow check) has spectral radius <= 1 at 1.3 h
    assert _linearised_radius(net, 1.3 * h) <= 1.0 + 1e-9
    # the free steps are taken: until the ball comes within reach of the net's box (0.23 s)
    free_calls = []
    explicit = SpringNetwork._explicit
    monkeypatch.setattr(SpringNetwork, "_explicit",
                        lambda self, hs, n: free_calls.append(n) or explicit(self, hs, n))
    B.build("two-way", duration=0.3).simulate()
    assert len(free_calls) > 200 and max(free_calls) <= 44  # 1 ms steps of >= 2.3e-5 s
    monkeypatch.setattr(SpringNetwork, "_explicit", explicit)
    monkeypatch.setattr(SpringNetwork, "free_step", lambda self: 0.0)
    fine = B.build("two-way").simulate()
    for t in CHECK:
        d = np.linalg.norm(runs["two-way"].state_at("ball", t)[0][:3]
                           - fine.state_at("ball", t)[0][:3])
        assert d < 1e-4, f"t={t}: {d:.2e} m from the run at the contact's step throughout"


def implicit_errors(reference, dt, params=B.BasketballParams()):
    """The implicit net at step dt (s, the coupling step too): the ball's distance (m) from
    the reference at every checkpoint."""
    r = B.build("two-way", integrator="implicit", dt=dt,
                params=dataclasses.replace(params, coupling_dt=dt)).simulate(
                    refine_unstable=False)
    return np.array([np.linalg.norm(r.state_at("ball", t)[0][:3]
                                    - reference.state_at("ball", t)[0][:3]) for t in CHECK])


@pytest.mark.xfail(strict=True, reason="with friction 1.0 on the 0.2 g knots the implicit net at "
                   "1e-3 s ends 5-6 cm from the reference at t = 0.6 s (25 cm before the ball was "
                   "solved with the knots; frictionless 1.8 cm): docs/coupling.md")
def test_implicit_net_at_1ms_follows_the_reference(reference):
    assert implicit_errors(reference, 1e-3).max() < 0.01


@pytest.mark.slow
def test_frictionless_implicit_net_converges_to_first_order():
    # the ball solved with the knots, no friction: backward Euler is first order in the step,
    # so from 1e-3 s to 2e-4 s the largest checkpoint error falls ~5x; at least 3x asserted
    # (measured 1.76 cm -> 0.23 cm). Before, the ball received the contact a step late and
    # was 19 cm off at 1e-3 s.
    p = B.BasketballParams()
    p = dataclasses.replace(p, contact=dataclasses.replace(p.contact, friction=0.0))
    reference = B.build("two-way", dt=1e-5,
                        params=dataclasses.replace(p, coupling_dt=1e-5)).simulate()
    coarse, fine = implicit_errors(reference, 1e-3, p), implicit_errors(reference, 2e-4, p)
    assert coarse.max() < 0.025  # the issue asks 1 cm with friction; frictionless 1.76 cm
    assert fine.max() < coarse.max() / 3


def test_fit_standin_reproduces_the_default(runs):
    fit = fit_standin(B.SPEC, reference=runs["two-way"])
    assert fit["speed_error_rel"] < 1e-3
    assert fit["linear"] == pytest.approx(B.BasketballParams().field.linear, rel=0.02)


def test_checkpoints_and_summary(runs):
    s = runs["two-way"].summary()
    times = [c["t"] for c in s["primary_checkpoints"]]
    assert times == CHECK
    # before the net (t = 0.2 s) the ball is in free flight: closed form
    c = s["primary_checkpoints"][0]
    x0, v0 = np.array(B.BasketballParams().ball.position), np.array(B.BasketballParams().ball.velocity)
    g = np.array([0, 0, -9.81])
    np.testing.assert_allclose(c["position"], x0 + v0 * 0.2 + 0.5 * g * 0.04, atol=1e-9)
    assert s["advice"]["mode"] == "two-way"
    assert s["diagnostics"]["net"]["instability"] == []
