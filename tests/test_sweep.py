"""`interplay sweep`: a wedge on the local pool is the same runs as `interplay run`, bit for bit;
an interrupted sweep finishes only what is missing; bad variants stop it before any run; a
failed variant is reported and the rest go on. The wedge itself: grids, samples, ids."""
import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import interplay
from interplay.batch import variants as V
from interplay.batch.executor import Failure, LocalPool
from interplay.batch.sweep import run_sweep
from interplay.cli.command import main
from interplay.scenes import all_specs, spec

QUICK = ["--duration", "0.5", "--no-video", "--no-obj", "--no-usd", "--no-report"]
WEDGE = ["--vary", "net.cord_ea=150,300", "--vary", "contact.friction=0.2,0.6"]
SRC = str(Path(interplay.__file__).resolve().parents[1])


def cli(*argv):
    try:
        return main(list(argv))
    except SystemExit as e:  # argparse's own errors
        return e.code


def same_run(a: Path, b: Path):
    """Two run folders hold the same results: every array of tracks.npz bit for bit, and
    summary.json but for each run's own id and wall times (timings, and the advice's sentence
    quoting the run's wall time, which changes with machine load)."""
    with np.load(a / "tracks.npz") as x, np.load(b / "tracks.npz") as y:
        assert sorted(x.files) == sorted(y.files)
        for k in set(x.files) - {"run_id"}:
            assert np.array_equal(x[k], y[k]), k
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    for s in (sa, sb):
        s.pop("timings")
        s.pop("run_id")
        s["advice"].pop("two_way_wall_s")
        s["advice"]["reasons"] = [r for r in s["advice"]["reasons"] if "wall time" not in r]
    assert sa == sb


def test_wedge_matches_separate_runs(tmp_path, capsys):
    """A 2x2 wedge on two single-threaded workers: each variant is the run `interplay run`
    makes with the same --set, bit for bit; the table has every variant, its Table I row and
    its worker; the contact sheet shows a still of each."""
    out = tmp_path / "sweep"
    assert cli("sweep", "basketball", *WEDGE, *QUICK, "--workers", "2", "--out", str(out)) == 0
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["counts"] == {"ok": 4, "error": 0, "pending": 0}
    assert doc["keys"] == ["net.cord_ea", "contact.friction"]
    assert doc["executor"] == {"kind": "local", "address": None, "workers": 2}
    assert [r["values"] for r in doc["variants"]] == [
        {"net.cord_ea": a, "contact.friction": f} for a in ("150", "300") for f in ("0.2", "0.6")]
    for r in doc["variants"]:
        assert r["status"] == "ok" and r["exit"] == 0 and r["ran"] == "this sweep"
        assert r["worker"]["numba_threads"] == 1
        t = r["table"]
        assert (t["name"], t["primary"], t["secondary"]) == ("ball-net", "ball", "net")
        # the effective acceleration is the force over the primary's mass (Table I)
        assert t["acceleration_m_s2"]["max"] == pytest.approx(t["force_N"]["max"] / t["primary_kg"])
        run = tmp_path / r["id"]
        sets = [f"--set={k}={v}" for k, v in r["values"].items()]
        assert cli("run", "basketball", *sets, *QUICK, "--quiet", "--out", str(run)) == 0
        same_run(out / r["id"], run)
    # softer cords stretch more: the wedge's figures move the way the physics says
    strain = {(r["values"]["net.cord_ea"], r["values"]["contact.friction"]):
              r["diagnostics"]["net"]["max_strain"] for r in doc["variants"]}
    assert strain["150", "0.2"] > strain["300", "0.2"] and strain["150", "0.6"] > strain["300", "0.6"]
    rows = list(csv.DictReader((out / "sweep.csv").open()))
    assert [r["id"] for r in rows] == [r["id"] for r in doc["variants"]]
    assert {"net.cord_ea", "contact.friction", "force_max_N", "accel_mean_m_s2",
            "net.max_strain", "simulate_s", "warnings", "exit"} <= set(rows[0])
    sheet = (out / "contact_sheet.html").read_text()
    for r in doc["variants"]:
        assert (out / "stills" / f"{r['id']}.png").is_file()
        assert f'src="stills/{r["id"]}.png"' in sheet
    assert not list(out.glob(".*part*"))


def _finished(out: Path) -> list:
    return sorted(p.parent.name for p in out.glob("v*/variant.json"))


def test_killed_sweep_resumes_with_only_the_missing_variants(tmp_path):
    """Kill -9 a sweep (and its worker) after its first variant: every folder named by an id
    is complete, and the same command again runs only the variants that had not finished."""
    out = tmp_path / "sweep"
    argv = ["sweep", "basketball", *WEDGE, *QUICK, "--workers", "1", "--no-stills", "--quiet",
            "--out", str(out)]
    env = dict(os.environ, PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen([sys.executable, "-m", "interplay.cli.command", *argv], env=env,
                            start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    deadline = time.time() + 300
    while not _finished(out) and proc.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)  # the sweep's own process group: driver and worker
    proc.wait()
    done = _finished(out)
    assert 1 <= len(done) < 4, proc.stderr.read()
    for d in out.glob("v*"):
        assert (d / "variant.json").is_file()  # an id's folder is complete or absent
    before = {d: (out / d / "variant.json").stat().st_mtime_ns for d in done}
    assert cli(*argv) == 0
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["counts"]["ok"] == 4
    ran = {r["id"]: r["ran"] for r in doc["variants"]}
    assert {k for k, v in ran.items() if v == "earlier"} == set(done)
    for d, mtime in before.items():
        assert (out / d / "variant.json").stat().st_mtime_ns == mtime  # not run again
    assert not list(out.glob(".*part*"))  # what the kill left in flight was cleared


def test_failed_variant_is_reported_and_the_sweep_goes_on(tmp_path):
    """A variant that raises in its worker gets its row (status, exit 2, the error) and its
    error.txt; the others run."""
    base = V.RunRequest("basketball", duration=0.3)
    good = V.plan(base, [{"net.cord_ea": "200"}, {"net.cord_ea": "250"}])
    bad = V.Variant("vbadbadbadbad", {"net.cord_ea": "-5"},
                    base.with_values({"net.cord_ea": "-5"}))  # not planned: never checked
    from interplay.outputs.writer import OutputOptions
    opts = OutputOptions(usd=False, obj=False, video=False, report=False, quiet=True)
    doc = run_sweep([good[0], bad, good[1]], tmp_path, opts, LocalPool(2),
                    {"scene": "basketball", "keys": ["net.cord_ea"]}, log=lambda m: None)
    assert [r["status"] for r in doc["variants"]] == ["ok", "error", "ok"]
    row = doc["variants"][1]
    assert row["exit"] == 2 and "net.cord_ea must be a finite number >= 0.001" in row["error"]
    assert "Traceback" in (tmp_path / bad.id / "error.txt").read_text()
    assert doc["counts"] == {"ok": 2, "error": 1, "pending": 0}
    # a rerun keeps the failure (it is finished) unless asked to retry it
    again = run_sweep([good[0], bad, good[1]], tmp_path, opts, LocalPool(1),
                      {"scene": "basketball", "keys": ["net.cord_ea"]}, log=lambda m: None)
    assert [r["ran"] for r in again["variants"]] == ["earlier"] * 3


BAD = [
    (["--vary", "net.colour=red,blue"], "--vary net.colour: unknown parameter; valid keys"),
    (["--vary", "ball.mass=0.6,-1"], "variant ball.mass=-1: "),
    (["--vary", "ball.mass=0.6,0.6"], "a value is listed twice"),
    (["--vary", "net.cord_ea=100:300:x"], "'x' is not a number"),
    (["--vary", "net.loops=8:12:4"], "net.loops takes whole numbers"),
    (["--vary", "coupling=two-way,sideways"], "unknown coupling"),
    (["--sample", "ball.mass=0.5:0.7"], "--sample needs --samples N"),
    (["--sample", "ball.mass=0.7:0.5", "--samples", "4"], "LO must be below HI"),
    (["--sample", "net.integrator=0:1", "--samples", "4"], "net.integrator is not a number"),
    (["--vary", "ball.mass=0.6,0.7", "--vary", "ball.mass=0.8"], "ball.mass: varied twice"),
    ([], "nothing to vary"),
    (["--sample", "ball.mass=0.5:0.7", "--samples", "4", "--design", "sobol"],
     "--design sobol: choose lhs or random"),
    (["--vary", "ball.mass=0.6,0.7", "--workers", "0"], "--workers 0: need a whole number"),
    (["--vary", "ball.mass=0.6,0.7", "--still-at", "9"], "--still-at 9: choose a time"),
    (["--vary", "ball.mass=0.6,0.7", "--workers", "2", "--ray"], "leave out one of --workers"),
]


@pytest.mark.parametrize("extra,message", BAD, ids=[" ".join(a) or "none" for a, _ in BAD])
def test_bad_wedge_stops_with_one_line_before_any_run(extra, message, tmp_path, capsys):
    code = cli("sweep", "basketball", *extra, *QUICK, "--out", str(tmp_path), "--quiet")
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("interplay: error:"), err
    assert message in err[0]
    assert not list(tmp_path.glob("v*"))  # nothing ran


def test_grid_samples_and_ids():
    p = spec("basketball").params()
    assert V.parse_vary("net.cord_ea=100:300:5", p) == ("net.cord_ea",
                                                        ["100", "150", "200", "250", "300"])
    assert V.parse_vary("net.loops=8:12:3", p) == ("net.loops", ["8", "10", "12"])
    assert V.parse_vary("ball.velocity=0,0,-5/0.5,0,-8", p) == ("ball.velocity",
                                                                ["0,0,-5", "0.5,0,-8"])
    grid = V.design(p, ["net.cord_ea=1,2,3", "coupling=two-way,one-way"])
    assert len(grid) == 6 and grid[1] == {"net.cord_ea": "1", "coupling": "one-way"}
    # Latin hypercube: each key's range in N strata, each stratum drawn exactly once
    pts = V.design(p, samples=["ball.mass=0.5:0.9", "net.loops=6:13"], n=8, seed=3)
    mass = np.array([float(x["ball.mass"]) for x in pts])
    assert sorted(np.floor((mass - 0.5) / 0.05).astype(int)) == list(range(8))
    assert sorted(int(x["net.loops"]) for x in pts) == list(range(6, 14))
    assert V.design(p, samples=["ball.mass=0.5:0.9"], n=8, seed=3) != V.design(
        p, samples=["ball.mass=0.5:0.9"], n=8, seed=4)
    # the id is the run's: the same parameters written differently give the same id; a
    # different duration, coupling or value another
    base = V.RunRequest("basketball", duration=0.5)
    same = V.plan(base, [{"net.cord_ea": "300"}])[0].id
    assert V.plan(base, [{"net.cord_ea": "300.0"}])[0].id == same
    assert V.plan(V.RunRequest("basketball", duration=0.6), [{"net.cord_ea": "300"}])[0].id != same
    assert V.plan(base, [{"coupling": "one-way", "net.cord_ea": "300"}])[0].id != same
    with pytest.raises(interplay.ParameterError, match="are the same run"):
        V.plan(base, [{"net.cord_ea": "300"}, {"net.cord_ea": "3e2"}])


def _task(x):
    if x == "die":
        os.kill(os.getpid(), signal.SIGKILL)  # a crash in native code, as the pool sees it
    if x == "raise":
        raise ValueError("bad item")
    return x * 2


def test_local_pool_survives_a_dead_worker():
    """A worker killed mid-task is reported for its task (found by rerunning the tasks in
    flight one at a time); a task that raises comes back as its error; every other task's
    result arrives."""
    with LocalPool(2) as pool:
        got = dict(pool.map_unordered(_task, [1, "die", 3, "raise", 5, 6]))
    assert {i: got[i] for i in (0, 2, 4, 5)} == {0: 2, 2: 6, 4: 10, 5: 12}
    assert isinstance(got[1], Failure) and got[1].kind == "worker"
    assert isinstance(got[3], Failure) and got[3].message == "ValueError: bad item"


@pytest.mark.slow
def test_contact_sheet_shows_every_still_and_sorts_in_chromium(tmp_path):
    from test_outputs_browser import Browser
    out = tmp_path / "sweep"
    assert cli("sweep", "basketball", *WEDGE, *QUICK, "--quiet", "--out", str(out)) == 0
    b = Browser()
    try:
        b.call("Page.navigate", url=(out / "contact_sheet.html").as_uri())
        assert b.wait_for("document.readyState === 'complete'")
        assert b.wait_for("document.images.length === 4 && [...document.images].every("
                          "i => i.complete && i.naturalWidth === 480)"), "a still did not load"
        col = b.eval("[...document.querySelectorAll('#sheet th')].findIndex("
                     "th => th.textContent === 'force max (N)')")
        column = (f"[...document.querySelectorAll('#sheet tbody tr')].map("
                  f"r => parseFloat(r.cells[{col}].dataset.v))")
        b.eval(f"document.querySelectorAll('#sheet th')[{col}].click()")
        up = b.eval(column)
        b.eval(f"document.querySelectorAll('#sheet th')[{col}].click()")
        down = b.eval(column)
        assert up == sorted(up) and down == sorted(up, reverse=True) and up != down
        b.pump(0.5)
        assert b.errors() == []
    finally:
        b.close()


@pytest.mark.parametrize("name", [s.name for s in all_specs()])
def test_results_are_data_that_cross_a_process_boundary(name):
    """A Result pickles (what an executor's task may return) and its copy analyses the same."""
    import pickle
    s = spec(name)
    r = s.build(s.default_coupling, duration=0.1, fps=s.fps, params=s.params()).simulate()
    copy = pickle.loads(pickle.dumps(r))
    assert copy.summary()["interactions"] == r.summary()["interactions"]
    assert copy.summary()["diagnostics"] == r.summary()["diagnostics"]


def test_help_params_lists_what_a_wedge_may_vary(capsys):
    """`interplay sweep SCENE --help-params json` is the scene's parameter schema, nothing run."""
    assert cli("sweep", "basketball", "--help-params", "json") == 0
    schema = json.loads(capsys.readouterr().out)
    assert schema["properties"]["net"]["properties"]["cord_ea"]["x-unit"] == "N"
