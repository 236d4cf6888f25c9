"""`interplay warm` fills Numba's cache so that a first run compiles nothing (issue 22 item 1;
docs/first-run.md). Each step in its own process, as a user's would be, on an empty cache
folder of the test's own (NUMBA_CACHE_DIR)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[1] / "src")


def interplay(*argv, cache):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=SRC)
    return subprocess.run([sys.executable, "-m", "interplay.cli.command", *argv], env=env,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.parametrize("scene, coupling, run_for", [
    ("flags", "one-way", ["--duration", "0.05"]),
    # the whole default run: the net's contact kernel is first called at 0.23 s, which two
    # warm frames did not reach (its warm_time does)
    ("basketball", "two-way", []),
])
def test_a_warmed_scene_runs_without_compiling(tmp_path, scene, coupling, run_for):
    cache = tmp_path / "numba-cache"
    warm = interplay("warm", scene, "--workers", "1", cache=cache)
    assert warm.returncode == 0, warm.stderr
    line = next(ln for ln in warm.stdout.splitlines() if ln.startswith(f"{scene} {coupling}:"))
    assert int(line.split(":")[1].split()[0]) > 0  # an empty cache: it compiled
    run = interplay("run", scene, *run_for, "--no-video", "--quiet", "--out",
                    str(tmp_path / "run"), cache=cache)
    assert run.returncode == 0, run.stderr
    assert "compiling kernels" not in run.stderr
    timings = json.loads((tmp_path / "run" / "summary.json").read_text())["timings"]
    # loading the cached kernels takes the compiler lock too, for milliseconds each
    assert timings["compile_s"] < 1.0


def test_an_unknown_scene_is_one_line_before_any_worker_starts(tmp_path):
    r = interplay("warm", "flgas", cache=tmp_path)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "flgas" in r.stderr


def test_the_cache_folder_is_keyed_by_every_kernels_source(tmp_path):
    """A caller's cached machine code has its callees compiled in, and Numba checks a cached
    kernel against its own file only: so every kernel's cache lives in the folder named after
    all kernel sources, and an edit of any one of them (here a callee's copy) names a new one."""
    import shutil

    import interplay.kernels as K
    from interplay.kernels import contact_law, springs
    folder = K._cache_folder()
    for kernel in (springs.implicit_step, contact_law.normal_force):
        assert Path(kernel._cache._cache_path).is_relative_to(folder)
    copy = tmp_path / "kernels"
    shutil.copytree(K._HERE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = K._source_hash(copy)
    with open(copy / "contact_law.py", "a") as f:
        f.write("\n# an edit\n")
    assert K._source_hash(copy) != before
    assert before == K._source_hash()
