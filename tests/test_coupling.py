"""Coupling invariants: the scheduler's passes, equal and opposite forces, one-way and hybrid."""
import dataclasses

import numpy as np
import pytest

from interplay.coupling.scheduler import plan
from interplay.errors import SceneError
from interplay.interactions.contact import SphereCordContact, SpherePlaneContact
from interplay.scene import Scene
from interplay.scenes import basketball as B
from interplay.systems.rigid import Sphere, SphereParams
from interplay.systems.static import StaticPlane
from interplay.coupling.track import Track


def short(params=None, **kw):
    return dataclasses.replace(params or B.BasketballParams(), **kw)


def test_two_way_forces_are_equal_and_opposite_every_step():
    # strict lock step (coupling step = the net's step): the contact is evaluated from the
    # current states and its forces applied to both sides in the same step
    scene = B.build("two-way", duration=0.45, params=short(coupling_dt=B.BasketballParams().net.dt))
    contact = next(it for it in scene.interactions if isinstance(it, SphereCordContact))
    checked = []
    original = contact.exchange

    def exchange(to_primary, to_secondary):
        f, tau, on = original(to_primary, to_secondary)
        idx, pf = contact.point_forces()
        if on:
            np.testing.assert_allclose(f, -pf.sum(axis=0), rtol=1e-12, atol=1e-12)
            checked.append(np.linalg.norm(f))
        return f, tau, on

    contact.exchange = exchange
    scene.simulate()
    assert len(checked) > 100 and max(checked) > 10.0  # many steps with real contact forces


def test_one_way_leaves_the_primary_as_run_alone():
    result = B.build("one-way", duration=1.0).simulate()
    alone = Scene("alone", duration=1.0, fps=60, coupling_dt=B.BasketballParams().coupling_dt)
    b = B.BasketballParams().ball
    ball = alone.add(Sphere("ball", SphereParams(b.radius, b.mass, b.shell, b.dt),
                            position=b.position, velocity=b.velocity))
    floor = alone.add(StaticPlane("floor"))
    alone.connect(SpherePlaneContact("ball-floor", ball, floor, B.BasketballParams().floor))
    free = alone.simulate()
    np.testing.assert_array_equal(result.tracks["ball"].x, free.tracks["ball"].x)
    np.testing.assert_array_equal(result.tracks["ball"].xdot, free.tracks["ball"].xdot)
    # and the net still felt the ball
    assert result.logs["ball-net"].active.any()


def test_hybrid_with_the_field_off_equals_one_way():
    off = short(field=dataclasses.replace(B.BasketballParams().field, enabled=False))
    one = B.build("one-way", duration=0.8, params=off).simulate()
    hyb = B.build("hybrid", duration=0.8, params=off).simulate()
    np.testing.assert_array_equal(one.tracks["ball"].x, hyb.tracks["ball"].x)
    np.testing.assert_array_equal(one.frames["net"]["points"], hyb.frames["net"]["points"])


def test_passes_are_ordered_primary_first():
    scene = B.build("hybrid", duration=0.1)
    passes = plan(scene.systems, scene.interactions)
    assert [[s.name for s in p.live] for p in passes] == [["ball"], ["net"]]
    assert [s.name for s in passes[1].played] == ["ball"]
    roles = {(it.name, role) for it, role in passes[0].actions}
    assert ("ball-net", "standin") in roles and ("ball-floor", "both") in roles
    two = B.build("two-way", duration=0.1)
    assert [[s.name for s in p.live] for p in plan(two.systems, two.interactions)] == [
        ["ball", "net"]]


def test_contradictory_couplings_are_refused():
    scene = B.build("two-way", duration=0.1)
    net = scene.systems[1]
    ball = scene.systems[0]
    # a second ball-net interaction in one-way mode inside the two-way group
    scene.connect(SphereCordContact("again", ball, net, mode="one-way"))
    with pytest.raises(SceneError, match="also coupled two-way"):
        plan(scene.systems, scene.interactions)


def test_one_way_cycle_is_refused():
    scene = B.build("one-way", duration=0.1)
    ball, net = scene.systems[0], scene.systems[1]

    class Reverse(SphereCordContact):
        pass

    it = Reverse("reverse", ball, net, mode="one-way")
    it.primary, it.secondary = net, ball
    scene.interactions.append(it)
    with pytest.raises(SceneError, match="cycle"):
        plan(scene.systems, scene.interactions)


def test_hybrid_needs_a_standin():
    scene = B.build("two-way", duration=0.1)
    floor = scene.interactions[1]
    with pytest.raises(SceneError, match="needs a stand-in"):
        floor.mode = "hybrid"


def test_hermite_playback_is_exact_for_cubics():
    t = np.linspace(0.0, 1.0, 11)
    f = lambda s: np.stack([s ** 3 - 2 * s, 4 * s ** 2], axis=-1)  # noqa: E731
    df = lambda s: np.stack([3 * s ** 2 - 2, 8 * s], axis=-1)  # noqa: E731
    tr = Track("p", t, f(t), df(t))
    for s in (0.0, 0.05, 0.333, 0.71, 1.0):
        x, xd = tr.sample(s)
        np.testing.assert_allclose(x, f(np.array(s)), atol=1e-14)
        np.testing.assert_allclose(xd, df(np.array(s)), atol=1e-12)


def test_an_unstable_pass_is_rerun_with_a_smaller_step_and_reported():
    # at 1e-4 s the explicit net passes the static bound but the ball's contact blows it up;
    # the scheduler must notice (strain past 100%), rerun the pass at 1e-5 s and say so
    scene = B.build("one-way", duration=0.45, dt=1e-4)
    result = scene.simulate()
    assert len(result.warnings) == 1
    w = result.warnings[0]
    assert w.startswith("net: strain") and "reran the pass with net dt=1e-05 s (was 0.0001 s)" in w
    assert result.diagnostics["net"]["instability"] == [w]
    # the pass ran at the smaller step; the net itself keeps its own (the scheduler changes
    # no system)
    assert result.passes[1]["substep_s"]["net"] == pytest.approx(1e-5)
    assert result.summary()["systems"][1]["dt_s"] == pytest.approx(1e-4)
    assert result.diagnostics["net"]["max_strain"] < 1.0  # the rerun is healthy


def test_without_refinement_the_blow_up_is_an_error():
    from interplay.errors import StabilityError
    scene = B.build("one-way", duration=0.45, dt=1e-4)
    with pytest.raises(StabilityError, match=r"net: strain .* nothing was written as a result; "
                       r"try --integrator implicit"):
        scene.simulate(refine_unstable=False)


def test_advisor_says_one_way_for_an_animated_primary():
    from interplay.analysis.advisor import advise

    animated = {"primary": "foot", "primary_role": "prescribed", "standin": None,
                "two_way_supported": True}
    stats = {"primary": "foot", "acceleration_m_s2": {"min": 0.0, "max": 900.0, "mean": 500.0}}
    verdict = advise(stats, animated)
    assert verdict["mode"] == "one-way" and "prescribed" in verdict["reasons"][0]
