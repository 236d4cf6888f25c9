"""The pond and puddle scenes run end to end in every mode, with the water's diagnostics."""
import json

import numpy as np
import pytest

from interplay import params as P
from interplay.cli.command import main
from interplay.errors import ParameterError
from interplay.scenes import spec

SMALL_POND = {"basin.cells": "40", "balls.count": "3"}


def small(name, **sets):
    m = spec(name)
    return m, P.apply(m.params(), sets)


@pytest.mark.parametrize("mode", ["two-way", "one-way", "hybrid"])
def test_pond_runs_in_every_mode(mode):
    m, params = small("pond", **SMALL_POND)
    scene = m.build(mode, duration=0.6, fps=20, params=params)
    res = scene.simulate()
    d = res.summary()["diagnostics"]["water"]
    # columns plus airborne spray: round-off only (see test_water)
    assert d["volume_drift_rel"] < 1e-12 and d["min_depth_m"] >= 0.0
    assert d["peak_particles"] >= 0
    stats = {s["name"]: s for s in res.interaction_stats()}
    assert stats["ball0-water"]["force_N"]["max"] > 0  # logged in every mode
    frames = res.frames["water"]
    assert frames["heights"].shape[1:] == scene.systems[0].shape
    if mode == "hybrid":
        assert "standin" in stats["ball0-water"]


def test_pond_light_balls_float_and_the_dense_one_sinks():
    m, params = small("pond", **{"basin.cells": "64"})
    scene = m.build("two-way", duration=2.0, fps=10, params=params)
    res = scene.simulate()
    z = {s.name: s.x[2] for s in scene.systems if s.name.startswith("ball")}
    level = params.basin.depth
    for k in range(4):  # densities 300-850: afloat, centre within a radius of the surface
        assert abs(z[f"ball{k}"] - level) < params.balls.radius[k]
    assert z["ball4"] == pytest.approx(params.balls.radius[4], abs=0.01)  # on the bed
    assert res.summary()["diagnostics"]["water"]["peak_particles"] > 0  # the splash


def test_pond_ball_count_must_match_the_lists():
    # a check of the parameters themselves: refused before anything is built
    with pytest.raises(ParameterError, match=r"balls.count=7: count=7 but radius lists 5 values"):
        small("pond", **{"balls.count": "7"})


def test_pond_refuses_an_integrator():
    with pytest.raises(ParameterError, match="--integrator implicit does not apply"):
        spec("pond").check_integrator("implicit")


def test_puddle_splashes_one_way():
    # the keyframed running step (no clip): it lands at 0.2 s
    m, params = small("puddle", **{"basin.cells": "80", "clip": ""})
    scene = m.build("one-way", duration=0.6, fps=20, params=params)
    res = scene.simulate()
    assert ["+".join(p["systems"]) for p in res.passes] == ["foot", "water"]
    d = res.summary()["diagnostics"]["water"]
    assert d["peak_particles"] > 0 and d["volume_drift_rel"] < 1e-12
    foot = scene.primary
    np.testing.assert_allclose(res.state_at("foot", 0.4)[0], foot._path(0.4), atol=1e-12)


def test_the_runners_foot_splashes_the_puddle():
    from interplay.scenes.puddle import STANCE
    from interplay.systems.mocap import clip_path
    if not clip_path("cmu_02_03_run.bvh").exists():
        pytest.skip("the CMU clips (../shared/data/mocap) are not here")
    m, params = small("puddle", **{"basin.cells": "80"})
    scene = m.build("one-way", duration=1.2, fps=20, params=params)
    res = scene.simulate()
    assert ["+".join(p["systems"]) for p in res.passes] == ["runner", "foot", "water"]
    runner = next(s for s in scene.systems if s.name == "runner")
    names = [s.name for s in runner.plan]
    # the foot follows the midpoint of the clip's right ankle and toes, shifted with the runner
    # (and lowered or lifted by one constant so the shoe's bottom touches the bed in stance)
    foot = []
    for t in (STANCE[0], 0.5 * sum(STANCE), STANCE[1]):
        runner.set_time(t)
        seg = runner.segment_positions()
        mid = 0.5 * (seg[names.index("r_foot")] + seg[names.index("r_toes")])
        foot.append(res.state_at("foot", t)[0][:3] - mid)
    # PCHIP between 120 Hz keys: within (v dt)^2 / L-ish of the clip; 1 mm is ample in stance
    np.testing.assert_allclose(np.array(foot)[:, :2], 0.0, atol=1e-3)
    np.testing.assert_allclose(np.array(foot)[:, 2], foot[0][2], atol=1e-3)
    d = res.summary()["diagnostics"]["water"]
    assert d["peak_particles"] > 0 and d["volume_drift_rel"] < 1e-12


def test_cli_runs_pond_and_writes_the_water_diagnostics(tmp_path, capsys):
    code = main(["run", "pond", "--duration", "0.3", "--set", "basin.cells=48", "--set",
                 "balls.count=2", "--out", str(tmp_path), "--quiet", "--no-usd", "--no-obj",
                 "--no-video", "--no-report"])
    assert code == 0, capsys.readouterr().err
    s = json.loads((tmp_path / "summary.json").read_text())
    assert {"volume_drift_rel", "peak_particles", "min_depth_m"} <= set(s["diagnostics"]["water"])
    assert {i["name"] for i in s["interactions"]} >= {"ball0-water", "ball1-water"}


def test_cli_reports_an_unstable_water_step_on_one_line(tmp_path, capsys):
    code = main(["run", "puddle", "--dt", "0.5", "--out", str(tmp_path), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "wave-speed limit" in err and len(err.strip().splitlines()) == 1
