"""Bad input never crashes (issue 21): a seeded property-based fuzz over every scene's
parameter schema, hostile BVH and mesh files, and damaged saved-run folders. Each either gives
one line naming what is wrong, or runs to finite outputs. (The thousands-of-cases version is
benchmarks/fuzz.py; docs/robustness.md has its figures.)"""
import dataclasses
import json
import math
import shutil

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from interplay import params as P
from interplay.cli.command import main
from interplay.errors import InterplayError, ParameterError
from interplay.io.motion_file import BVHError, read_bvh
from interplay.scenes import MODULES, all_specs, spec

SHORT = ["--duration", "0.02", "--quiet", "--no-video", "--no-usd", "--no-obj", "--no-report"]
FUZZ = settings(max_examples=12, deadline=None, derandomize=True, database=None,
                suppress_health_check=list(HealthCheck))


def values(d: P.Domain):
    """Hostile and ordinary texts for a parameter of domain d."""
    num = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                    st.integers(-10 ** 30, 10 ** 30), st.sampled_from([0, -1, 1e-308, 1e308]))
    text = num.map(lambda v: repr(v) if isinstance(v, float) else str(v))
    if d.kind == "vector":
        return st.lists(text, max_size=8).map(",".join)
    if d.kind == "bool":
        return st.sampled_from(["true", "false", "maybe", "", "1"])
    if d.kind == "str":
        return st.one_of(st.sampled_from(list(d.choices or ()) + ["", "nonsense"]),
                         st.text(max_size=30))
    return st.one_of(text, st.sampled_from(["abc", "", "1,2"]))


def one_line_or_finite(code, err, out):
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    if code != 0:
        assert code == 2, err
        assert len(lines) == 1 and lines[0].startswith("interplay: error:"), err
        return lines[0]
    summary = json.loads((out / "summary.json").read_text(),
                         parse_constant=lambda c: pytest.fail(f"{c} in summary.json"))
    assert summary["run_id"]
    with np.load(out / "tracks.npz", allow_pickle=False) as z:
        for key in z.files:
            a = z[key]
            if a.dtype.kind == "f":
                ok = np.isfinite(a)
                if key.endswith("/particles"):  # absent spray: whole NaN rows
                    ok = ok.all(-1) | np.isnan(a).all(-1)
                elif key.endswith("/particle_radius"):  # NaN past the particle count
                    ok = ok | np.isnan(a)
                assert ok.all(), key
    return None


@pytest.mark.parametrize("name", [pytest.param(m, marks=pytest.mark.slow) if spec(m).heavy
                                  else m for m in MODULES])
def test_fuzz_every_parameter_of_every_scene(name, tmp_path_factory, capsys):
    sp = spec(name)
    domains = P.domains(sp.params())

    @FUZZ
    @given(data=st.data())
    def check(data):
        d = data.draw(st.sampled_from(domains))
        text = data.draw(values(d))
        out = tmp_path_factory.mktemp("fuzz")
        code = main(["run", name, "--set", f"{d.key}={text}", *SHORT, "--out", str(out)])
        line = one_line_or_finite(code, capsys.readouterr().err, out)
        if line is not None and "budget" not in line:
            assert d.key in line  # the rejection names the key

    check()


def test_every_rejection_names_key_value_range_and_unit(capsys, tmp_path):
    code = main(["run", "basketball", "--set", "ball.radius=1e308", *SHORT, "--out",
                 str(tmp_path)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.count("\n") == 0
    assert "ball.radius=1e308" in err and ">= 0.001 and <= 10 m" in err


# --- BVH -------------------------------------------------------------------------------------
SMALL = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.033333
0 90 0 0 0 0 0 0 0
1 90 0 10 0 0 5 0 0
2 90 0 20 0 0 10 0 0
"""


@FUZZ
@given(cut=st.integers(0, len(SMALL)), junk=st.text(max_size=12), at=st.integers(0, len(SMALL)))
def test_hostile_bvh_text_is_one_error_or_a_finite_motion(tmp_path_factory, cut, junk, at):
    p = tmp_path_factory.mktemp("bvh") / "clip.bvh"
    text = SMALL[:at] + junk + SMALL[at:]
    p.write_text(text[: max(cut, at + len(junk))])
    try:
        m = read_bvh(p)
    except BVHError as e:
        assert str(p) in str(e) and "\n" not in str(e)
        return
    assert np.isfinite(m.frames).all() and len(m.frames) >= 2
    assert 1e-4 <= m.frame_time <= 1.0


@pytest.mark.parametrize("edit,message", [
    (lambda s: s.replace("Frames: 3", "Frames: 0"), "a clip needs 2"),
    (lambda s: s.replace("Frames: 3", "Frames: 1"), "a clip needs 2"),
    (lambda s: s.replace("Frames: 3", "Frames: 2"), "but 3 motion lines follow"),
    (lambda s: s.replace("0.033333", "1e-300"), "Frame Time: 1e-300 s must be within"),
    (lambda s: s.replace("0.033333", "100"), "Frame Time: 100 s must be within"),
    (lambda s: s.replace("2 90 0 20", "2 90 nan 20"), "'nan' is not a finite number"),
])
def test_bvh_checks_name_the_problem(tmp_path, edit, message):
    p = tmp_path / "clip.bvh"
    p.write_text(edit(SMALL))
    with pytest.raises(BVHError, match=message):
        read_bvh(p)


def test_bvh_must_be_a_regular_file(tmp_path):
    import os
    fifo = tmp_path / "fifo.bvh"
    os.mkfifo(fifo)
    for path in (fifo, "/dev/zero", tmp_path):
        with pytest.raises(BVHError, match="not a regular file"):
            read_bvh(path)


def test_a_mistyped_clip_is_an_error_not_a_fallback(capsys, tmp_path):
    code = main(["run", "puddle", "--set", "clip=cmu_02_03_rnu.bvh", *SHORT, "--out",
                 str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "no clip 'cmu_02_03_rnu.bvh'" in err


# --- meshes ----------------------------------------------------------------------------------
@FUZZ
@given(n=st.integers(0, 12), data=st.data())
def test_hostile_meshes_are_one_error_or_a_finite_network(n, data):
    from interplay.geometry import mesh
    from interplay.systems.springmass import SpringNetwork
    coord = st.one_of(st.floats(-10, 10), st.sampled_from([math.nan, math.inf, 1e300, 0.0]))
    x = data.draw(st.lists(st.tuples(coord, coord, coord), min_size=n, max_size=n))
    t = data.draw(st.lists(st.tuples(*[st.integers(-2, n + 2)] * 3), max_size=20))
    try:
        x, t = mesh.validate(np.array(x, float).reshape(-1, 3), np.array(t, np.int64)
                             .reshape(-1, 3))
        net = SpringNetwork.from_mesh("cloth", x, t, 0.1, 10.0, 5.0, 0.1, dt=1e-3)
    except ParameterError as e:
        assert "\n" not in str(e)
        return
    for _ in range(3):
        net.advance(1e-3)
    assert np.isfinite(net.x).all()


def test_mesh_files_bounded_and_regular(tmp_path):
    from interplay.geometry import mesh
    with pytest.raises(ParameterError, match="not a regular file"):
        mesh.load("/dev/zero")
    p = tmp_path / "bad.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    with pytest.raises(ParameterError, match="non-finite"):
        mesh.load(p)


# --- saved-run folders -----------------------------------------------------------------------
@pytest.fixture(scope="module")
def saved_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("good")
    assert main(["run", "basketball", "--duration", "0.05", "--quiet", "--no-video",
                 "--no-usd", "--no-obj", "--no-report", "--out", str(out)]) == 0
    return out


def _damage(d, kind):
    if kind == "summary-truncated":
        p = d / "summary.json"
        p.write_text(p.read_text()[:40])
    elif kind == "scene-without-fps":
        doc = json.loads((d / "scene.json").read_text())
        del doc["fps"]
        (d / "scene.json").write_text(json.dumps(doc))
    elif kind == "tracks-truncated":
        p = d / "tracks.npz"
        p.write_bytes(p.read_bytes()[:500])
    else:
        with np.load(d / "tracks.npz") as z:
            arrays = {k: z[k] for k in z.files}
        if kind == "points-mismatch":
            arrays["net/points"] = arrays["net/points"][:, :10]
        elif kind == "pickled":
            arrays["net/points"] = np.array([{"os": "system"}], dtype=object)
        elif kind == "nan":
            arrays["ball/position"][3, 1] = np.nan
        elif kind == "other-run":
            arrays["run_id"] = np.array("0123456789abcdef")
        with open(d / "tracks.npz", "wb") as fh:
            np.savez(fh, **arrays)


@pytest.mark.parametrize("manifest", [True, False], ids=["manifest", "no-manifest"])
@pytest.mark.parametrize("kind", ["summary-truncated", "scene-without-fps", "tracks-truncated",
                                  "points-mismatch", "pickled", "nan", "other-run"])
def test_damaged_saved_runs_are_one_line(saved_run, tmp_path, kind, manifest):
    """With its manifest, any edit of a listed file is refused by size; without one (a folder
    of an older version, or a deleted manifest) the contents themselves are checked."""
    from interplay.outputs.rundata import load_run
    d = tmp_path / "run"
    shutil.copytree(saved_run, d)
    if not manifest:
        (d / "manifest.json").unlink()
    _damage(d, kind)
    with pytest.raises(InterplayError) as e:
        load_run(d)
    assert "\n" not in str(e.value) and str(d) in str(e.value)


def test_a_good_saved_run_loads(saved_run):
    from interplay.outputs.rundata import load_run
    run = load_run(saved_run)
    assert run.scene == "basketball" and len(run.times) == 4


# --- the parameter layer ---------------------------------------------------------------------
def test_plain_dataclasses_get_sensible_domains():
    @dataclasses.dataclass(frozen=True)
    class New:  # what a new scene might write: no declarations at all
        speed: float = 1.0
        where: tuple = (0.0, 0.0, 0.0)
        count: int = 3
        on: bool = True
    for key, text, why in [("speed", "nan", "not finite"), ("speed", "inf", "not finite"),
                           ("where", "1,2", "2 numbers given"),
                           ("where", "0,0,nan", "not finite"),
                           ("count", "2147483648", "out of range"),
                           ("count", "1.5", "not a whole number"),
                           ("on", "maybe", "not true or false")]:
        with pytest.raises(ParameterError, match=why) as e:
            P.apply(New(), {key: text})
        assert str(e.value).startswith(f"{key}={text}:")


def test_every_scene_has_a_schema_and_a_table():
    for sp in all_specs():
        schema = P.json_schema(sp.params(), sp.name)
        assert schema["$schema"].endswith("2020-12/schema")
        rows = P.table(sp.params())
        assert len(rows) == len(P.keys(sp.params()))
        # every declared float bound appears in the schema
        for d in P.domains(sp.params()):
            node = schema
            for part in d.key.split("."):
                node = node["properties"][part]
            if d.kind == "float" and d.lo is not None and not d.optional:
                assert node.get("minimum", node.get("exclusiveMinimum")) == d.lo


def test_cost_guard_names_the_estimate_and_force(capsys, tmp_path):
    code = main(["run", "flags", "--set", "cotton.nu=2000", "--set", "cotton.nv=2000", *SHORT,
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "4e+06 points" in err and "--force" in err
    code = main(["run", "basketball", "--dt", "1e-9", *SHORT[2:], "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "state values" in err and "--force" in err


def test_help_params_lists_every_key(capsys):
    assert main(["run", "basketball", "--help-params", "json"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert schema["properties"]["ball"]["properties"]["radius"]["x-unit"] == "m"


def test_a_missing_default_clip_warns_and_a_set_one_is_an_error(tmp_path, monkeypatch, capsys):
    """With no mocap folder (a fresh install) the puddle runs its keyframed foot and says so in
    its warnings; a clip the user names must exist."""
    monkeypatch.setenv("INTERPLAY_MOCAP_DIR", str(tmp_path / "empty"))
    out = tmp_path / "out"
    assert main(["run", "puddle", *SHORT, "--out", str(out)]) == 0
    warnings = json.loads((out / "summary.json").read_text())["warnings"]
    assert any("clip='cmu_02_03_run.bvh' (the default): no clip" in w for w in warnings)
    code = main(["run", "puddle", "--set", "clip=cmu_02_03_run.bvh", *SHORT, "--out", str(out)])
    assert code == 2 and "no clip 'cmu_02_03_run.bvh'" in capsys.readouterr().err
