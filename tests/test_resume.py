"""A run never silently corrupts and a long run survives being killed (issue 21): resume from a
checkpoint repeats the uninterrupted run bit for bit; SIGKILL at random moments leaves either
the previous complete run or one clearly incomplete; results are bit-identical across
processes and thread counts; a blow-up stops the run with what happened."""
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from interplay.coupling.checkpoint import Checkpointer, read
from interplay.scenes import MODULES, spec

SRC = Path(__file__).resolve().parents[1] / "src"
QUICK = ["--quiet", "--no-video", "--no-usd", "--no-report"]


class _Stop(Exception):
    pass


class _Died(BaseException):
    """Not an Exception: nothing in Interplay catches it, as nothing survives a SIGKILL."""


def _killed_after(ck: Checkpointer, saves: int):
    """The checkpointer, made to stop the run (like a kill) right after its n-th save."""
    save = ck.save

    def stop(*a, **k):
        save(*a, **k)
        if ck.saved == saves:
            raise _Stop
    ck.save = stop
    return ck


def same_result(a, b):
    for name, fr in a.frames.items():
        for key, arr in fr.items():
            assert np.array_equal(arr, b.frames[name][key], equal_nan=True), (name, key)
    for name, tr in a.tracks.items():
        for key in ("t", "x", "xdot"):
            assert np.array_equal(getattr(tr, key), getattr(b.tracks[name], key)), (name, key)
    for name, log in a.logs.items():
        for key in ("t", "force", "torque", "active", "peak"):
            assert np.array_equal(getattr(log, key), getattr(b.logs[name], key)), (name, key)
    assert a.warnings == b.warnings
    assert a.diagnostics == b.diagnostics


# a two-pass coupling where the scene has one (so a checkpoint falls in either pass)
CASES = {"basketball": ("hybrid", 0.3), "bungee": ("two-way", 0.4), "flags": ("one-way", 0.2),
         "leaves": ("one-way", 0.2), "pond": ("two-way", 0.2), "puddle": ("one-way", 0.2),
         "diver": ("hybrid", 0.3), "kites": ("two-way", 0.2), "stunt_kite": ("two-way", 0.2),
         "trampoline": ("two-way", 0.6), "owl_creek": ("two-way", 0.3),
         "runner": ("one-way", 0.2), "mat": ("hybrid", 0.3), "swing": ("one-way", 0.2)}


@pytest.mark.parametrize("name", MODULES)
@pytest.mark.parametrize("saves", [1, 2])
def test_resume_repeats_the_uninterrupted_run_bit_for_bit(name, saves, tmp_path):
    mode, duration = CASES[name]
    sp = spec(name)
    reference = sp.build(mode, duration=duration).simulate()
    ck = _killed_after(Checkpointer(tmp_path / "checkpoint.npz", every_s=duration / 3,
                                    every_wall_s=None), saves)
    with pytest.raises(_Stop):
        sp.build(mode, duration=duration).simulate(checkpointer=ck)
    resumed = sp.build(mode, duration=duration).simulate(resume=read(tmp_path /
                                                                     "checkpoint.npz"))
    same_result(reference, resumed)


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["two-way", "hybrid"])
def test_resume_mid_landing_keeps_the_sticking_friction(mode, tmp_path):
    """The mat's friction keeps state between steps (the contact's springs per touched point,
    the stand-in's anchors): a run saved at 0.85 s, 0.08 s after her feet touch down, and
    resumed repeats the uninterrupted one bit for bit, in two-way (the contact's springs) and
    in hybrid (the save falls in her pass, on the anchored stand-in)."""
    sp = spec("mat")
    reference = sp.build(mode, duration=0.95).simulate()
    ck = _killed_after(Checkpointer(tmp_path / "checkpoint.npz", every_s=0.85,
                                    every_wall_s=None), 1)
    with pytest.raises(_Stop):
        sp.build(mode, duration=0.95).simulate(checkpointer=ck)
    resumed = sp.build(mode, duration=0.95).simulate(resume=read(tmp_path / "checkpoint.npz"))
    same_result(reference, resumed)


def test_a_checkpoint_of_another_scene_is_refused(tmp_path):
    from interplay.errors import OutputError
    ck = _killed_after(Checkpointer(tmp_path / "c.npz", every_s=0.05, every_wall_s=None), 1)
    with pytest.raises(_Stop):
        spec("flags").build("one-way", duration=0.2).simulate(checkpointer=ck)
    with pytest.raises(OutputError, match="another scene layout"):
        spec("leaves").build("one-way", duration=0.2).simulate(resume=read(tmp_path / "c.npz"))


# --- whole processes -------------------------------------------------------------------------
def _env(**extra):
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_THREADING_LAYER="workqueue",
               OPENBLAS_NUM_THREADS="1", **extra)
    return env


def _cli(*argv, env=None, cwd=None):
    return subprocess.Popen([sys.executable, "-m", "interplay.cli.command", *argv],
                            env=env or _env(), cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


def arrays(path):
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files if k != "run_id"}


def test_cli_resume_after_sigkill_is_bit_identical(tmp_path):
    args = ["run", "basketball", "--duration", "0.3", *QUICK, "--no-obj"]
    ref = tmp_path / "ref"
    p = _cli(*args, "--out", str(ref))
    assert p.wait(600) == 0, p.stderr.read()
    out = tmp_path / "killed"
    p = _cli(*args, "--out", str(out), "--checkpoint-every", "0.05")
    deadline = time.monotonic() + 600
    while not (out / "checkpoint.npz").exists() and p.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert (out / "checkpoint.npz").exists() and not (out / "summary.json").exists()
    p = _cli("run", "basketball", "--resume", "--out", str(out), *QUICK, "--no-obj")
    assert p.wait(600) == 0, p.stderr.read()
    a, b = arrays(ref / "tracks.npz"), arrays(out / "tracks.npz")
    assert a.keys() == b.keys()
    for key in a:
        assert np.array_equal(a[key], b[key]), key
    assert not (out / "checkpoint.npz").exists()
    s = json.loads((out / "summary.json").read_text())
    m = json.loads((out / "manifest.json").read_text())
    assert m["complete"] and s["run_id"] == m["run_id"]


def check_folder(out: Path):
    """What a kill may leave: a complete run (manifest complete, every file listed present
    with its size, the ids agree), or an incomplete one the manifest says is incomplete and
    whose files are all of one run; nothing else visible but the checkpoint."""
    from interplay.outputs.runfolder import KNOWN, listing
    visible = {p.name for p in out.iterdir() if not p.name.startswith(".")}
    visible -= {"checkpoint.npz"}
    mpath = out / "manifest.json"
    if not mpath.exists():
        assert not visible & set(KNOWN), f"output files without a manifest: {visible}"
        return "empty"
    m = json.loads(mpath.read_text())
    if m["complete"]:
        files = listing(out)
        for rel, info in m["files"].items():
            assert files[rel] == info, rel
        assert {r.split("/")[0] for r in files} - {"checkpoint.npz", "manifest.json"} == \
            {r.split("/")[0] for r in m["files"]}
        ids = {json.loads((out / "summary.json").read_text())["run_id"],
               json.loads((out / "scene.json").read_text())["run_id"],
               str(np.load(out / "tracks.npz")["run_id"])}
        assert ids == {m["run_id"]}
        return "complete"
    # incomplete: every id-carrying file present is of one run
    ids = set()
    for name in ("summary.json", "scene.json"):
        if (out / name).exists():
            ids.add(json.loads((out / name).read_text())["run_id"])
    if (out / "tracks.npz").exists():
        ids.add(str(np.load(out / "tracks.npz")["run_id"]))
    assert len(ids) <= 1, f"files of two runs: {ids}"
    return "incomplete"


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sigkill_at_random_moments_leaves_one_run_or_a_marked_incomplete_one(tmp_path, seed):
    rng = random.Random(seed)
    out = tmp_path / "out"
    args = ["run", "basketball", "--duration", "0.2", "--quiet", "--no-video", "--no-report",
            "--out", str(out)]
    p = _cli(*args)
    assert p.wait(600) == 0, p.stderr.read()
    assert check_folder(out) == "complete"
    t0 = time.monotonic()
    p = _cli(*args)
    assert p.wait(600) == 0
    full = time.monotonic() - t0
    seen = []
    for _ in range(4):
        p = _cli(*args, cwd=tmp_path)
        time.sleep(rng.uniform(0.0, full))
        p.send_signal(signal.SIGKILL if rng.random() < 0.7 else signal.SIGTERM)
        p.wait()
        seen.append(check_folder(out))
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
    p = _cli(*args)
    assert p.wait(600) == 0
    assert check_folder(out) == "complete"
    assert not list(out.rglob(".*.part")) and not list(out.glob(".staging-*"))


def test_bit_identical_across_processes_and_thread_counts(tmp_path):
    runs = []
    for k, threads in enumerate(("1", "2", "2")):
        out = tmp_path / f"run{k}"
        p = subprocess.run([sys.executable, "-m", "interplay.cli.command", "run", "flags",
                            "--duration", "0.2", *QUICK, "--no-obj", "--out", str(out)],
                           env=_env(NUMBA_NUM_THREADS=threads), capture_output=True, text=True)
        assert p.returncode == 0, p.stderr
        runs.append(arrays(out / "tracks.npz"))
    for other in runs[1:]:
        assert runs[0].keys() == other.keys()
        for key in runs[0]:
            assert np.array_equal(runs[0][key], other[key]), key


def test_the_advice_does_not_depend_on_machine_speed():
    result = spec("basketball").build("two-way", duration=0.3).simulate()
    fast = result.advice()
    result.total_s *= 1e6  # the same run on a machine a million times slower
    slow = result.advice()
    assert fast["mode"] == slow["mode"] and fast["reasons"] == slow["reasons"]
    assert slow["two_way_wall_s"] == pytest.approx(1e6 * fast["two_way_wall_s"])


def test_a_blow_up_smaller_steps_cannot_cure_is_called_physical():
    """A system that fails at the same simulated time whatever its step (a torn net) is not
    rerun again and again: the error says smaller steps did not help."""
    from interplay.errors import StabilityError
    from interplay.scene import Scene
    from interplay.systems.base import System

    class Tears(System):
        integrator = "explicit"
        mass = 1.0

        def step(self, h):
            pass

        def health(self):
            return [f"{self.name}: torn at t={self.time:.3f} s"] if self.time > 0.1 else []

        def generalized_state(self):
            return np.zeros(1), np.zeros(1)

        def set_generalized_state(self, x, xdot):
            pass

        def frame(self):
            return {}

    scene = Scene("tear", duration=0.3, fps=30.0)
    scene.add(Tears("cloth", 1e-3))
    with pytest.raises(StabilityError, match="smaller steps did not help, so the cause is "
                                             "physical"):
        scene.simulate()


def test_a_kill_at_every_step_of_publishing_leaves_a_consistent_folder(tmp_path, monkeypatch):
    """The publishing window is milliseconds, so random kills rarely land in it: here each of
    its renames in turn is made to fail (as if the process died there); the folder must pass
    check_folder, and the next run's claim() must finish the publication."""
    import interplay.outputs.runfolder as RF
    from interplay.cli.command import main
    out = tmp_path / "out"
    args = ["run", "basketball", "--duration", "0.05", "--quiet", "--no-video", "--no-report",
            "--no-usd", "--out", str(out)]
    assert main(args) == 0
    real = os.replace
    step = 0
    while True:
        step += 1
        calls = {"n": 0}

        def dying(a, b, calls=calls, stop=step):
            calls["n"] += 1
            if calls["n"] == stop:
                raise _Died  # the process "dies" here
            return real(a, b)
        monkeypatch.setattr(RF.os, "replace", dying)
        try:
            main(args)
            finished = True
        except _Died:
            finished = False
        monkeypatch.setattr(RF.os, "replace", real)
        check_folder(out)
        with RF.Lock(out):
            RF.claim(out)
        assert check_folder(out) == "complete"
        if finished:
            break
    assert step > 5  # the publication has that many renames, each was interrupted once
