"""The diver scene: the dive's entry against free fall, the hybrid invariants (the primary pass
never reads the water; the stand-in off is one-way), volume conserved with spray in the water
pass, bad input; slow: the full runs, rip against flat, hybrid against two-way."""
import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("mujoco")

from interplay.cli.command import main  # noqa: E402
from interplay.errors import SceneError  # noqa: E402
from interplay.interactions.buoyancy import ResolutionWarning  # noqa: E402
from interplay.scenes import diver as D  # noqa: E402

G = 9.81
#: a coarse pool (81 columns across 16 m) for runs that need the water but not its detail
COARSE = replace(D.DiverParams(), pool=D.PoolParams(cells=81))


def _build(coupling="hybrid", duration=4.2, params=COARSE, fps=60.0):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResolutionWarning)  # the coarse pool's columns
        return D.build(coupling, duration=duration, fps=fps, params=params)


@pytest.fixture(scope="module")
def hybrid():
    scene = _build()
    return scene, scene.simulate()


def test_the_dive_enters_hands_first_near_vertical_at_free_fall_speed(hybrid):
    scene, res = hybrid
    fig = D.dive_figures(res)
    e = scene.meta["predicted"]
    assert e["leading_segment"] in ("l_hand", "r_hand")
    assert fig["entry angle from vertical (deg)"] < 10.0
    # energy: from the top of the flight the centre of mass falls to its entry height; air
    # drag (1/2 rho C A v^2 ~ 10 N at most on 630 N) takes at most ~1.5% of the speed
    com, t = res.frames["diver"]["com"], res.frames["diver"]["t"]
    vel = np.gradient(com, t, axis=0)
    top = int(np.argmax(com[:, 2]))
    z_in = float(np.interp(fig["entry time (s)"], t, com[:, 2]))
    v_top = np.linalg.norm(vel[top])
    free = math.sqrt(v_top ** 2 + 2 * G * (com[top, 2] - z_in))
    assert fig["entry speed (m/s)"] == pytest.approx(free, rel=0.02)
    assert fig["entry speed (m/s)"] < free
    assert 13.0 < fig["entry speed (m/s)"] < 15.0  # sqrt(2 g 10 m) = 14.0 m/s
    # the hybrid's entry is the check's: the same dive, flown the same way
    assert fig["entry time (s)"] == pytest.approx(e["entry_time_s"], abs=2 * D.DiverParams(
    ).coupling_dt)


def test_the_drag_field_slows_the_diver_in_the_primary_pass(hybrid):
    scene, res = hybrid
    fig = D.dive_figures(res)
    assert fig["speed 1 m under (m/s)"] < 0.9 * fig["entry speed (m/s)"]
    assert res.logs["diver-water"].standin.active.any()


# a basin left without water (as this test's is) is still drawn without an invalid divide
@pytest.mark.filterwarnings("error::RuntimeWarning")
def test_the_hybrid_primary_pass_does_not_read_the_water(hybrid):
    """Spoil the pool with NaN: the primary pass (the figure and its stand-in) comes out bit
    for bit the same, and the water is in a pass of its own."""
    _, res = hybrid
    scene = _build()
    water = next(s for s in scene.systems if s.name == "pool")
    water.V[:] = np.nan
    spoiled = scene.simulate(primary_only=True)
    assert [p["systems"] for p in res.passes] == [["diver"], ["pool"]]
    np.testing.assert_array_equal(spoiled.tracks["diver"].x, res.tracks["diver"].x)


def test_hybrid_with_the_field_off_is_one_way():
    off = replace(COARSE, field=replace(COARSE.field, enabled=False))
    h = _build("hybrid", 3.0, off).simulate(primary_only=True)
    o = _build("one-way", 3.0).simulate(primary_only=True)
    np.testing.assert_array_equal(h.tracks["diver"].x, o.tracks["diver"].x)


def test_the_water_pass_conserves_volume_with_spray(hybrid):
    _, res = hybrid
    d = res.diagnostics["pool"]
    assert d["spray_emitted_m3"] > 0.0 and d["peak_particles"] > 0
    # every pipe moves the same volume out of one column and into the other; each drop
    # carries its volume: only round-off remains (~1e-15 per step, 2,000 steps)
    assert d["volume_drift_rel"] < 1e-9


def test_a_dive_that_misses_the_pool_is_refused():
    far = replace(COARSE, platform=replace(COARSE.platform, overhang=-12.0))
    with pytest.raises(SceneError, match=r"the dive misses the pool: it enters the water's "
                                         r"plane at x=1\.\d\d m, .*pool spans x 12\.00\.\."):
        _build(params=far)


def test_a_pool_too_shallow_for_the_entry_is_refused():
    shallow = replace(COARSE, pool=replace(COARSE.pool, depth=1.5))
    with pytest.raises(SceneError, match=r"too shallow for this dive: it enters at 1\d\.\d m/s "
                                         r"and reaches .* pool\.depth is 1\.5 m; use pool\.depth"
                                         r" >= "):
        _build(params=shallow)


def test_the_cli_refuses_a_bad_entry_and_a_shallow_pool_on_one_line(tmp_path, capsys):
    for argv, says in ((["--set", "dive.entry=sideways"], "dive.entry='sideways': choose rip "
                                                          "or flat"),
                       (["--set", "pool.depth=1.5"], "too shallow for this dive")):
        code = main(["run", "diver", "--out", str(tmp_path), "--quiet", *argv])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1 and says in err, err


@pytest.mark.slow
def test_the_flat_entry_splashes_more_than_the_rip():
    """The paper-scale pool, both entries in hybrid: the belly-flop displaces the same body
    volume as the rip but all at once, so more of the surface rises past the spray
    threshold (measured: 2.9 times the volume, docs/diver.md)."""
    runs = {}
    for entry in ("rip", "flat"):
        p = replace(D.DiverParams(), dive=replace(D.DiverParams().dive, entry=entry))
        runs[entry] = D.dive_figures(D.build(params=p, fps=30.0).simulate())
    assert runs["rip"]["entry angle from vertical (deg)"] < 10.0
    assert 80.0 < runs["flat"]["entry angle from vertical (deg)"] < 110.0
    assert runs["flat"]["spray thrown (m^3)"] > 2.0 * runs["rip"]["spray thrown (m^3)"]


@pytest.mark.slow
def test_two_way_and_hybrid_agree_on_the_diver_under_water():
    """The same dive and the same drag law, against the moving pool (two-way) and against
    still water (hybrid): the speed 1 m under differs by what the field leaves out, the water
    moving down with the diver (two-way meets less relative speed, so it is faster)."""
    h = D.dive_figures(D.build("hybrid", fps=60.0).simulate(primary_only=True))
    t = D.dive_figures(D.build("two-way", duration=4.0, fps=60.0).simulate())
    assert t["entry speed (m/s)"] == pytest.approx(h["entry speed (m/s)"], rel=1e-3)
    assert h["speed 1 m under (m/s)"] < t["speed 1 m under (m/s)"]
    assert t["speed 1 m under (m/s)"] == pytest.approx(h["speed 1 m under (m/s)"], rel=0.15)
