"""Benchmark: every scene's first ``interplay run`` on an empty Numba cache against its warm
run, and where the first run's compile time goes; writes DIR/bench_first_run.json.

Each scene runs twice in a fresh process, as a new user types it (``interplay run SCENE
--no-video --quiet``: the preview's rendering is the same on both runs and is timed by
bench_scenes.py), both with ``NUMBA_CACHE_DIR`` pointing at a folder this benchmark empties
first, so the user's own cache is untouched: the first run compiles every kernel the scene
uses, the second loads them. Per run: the process's wall time, the summary's ``compile_s``
(time compiling or loading kernels during the simulation, coupling/compilation.py) and the
whole process's (building the scene too), its primary debug-cycle time and ``total_s``; for the first run the kernels compiled, slowest first. Ratios: first over
warm (the issue's target: at most 2), and the first run's overhead in seconds (target: at
most 5 s for the basketball). Wall clock on a shared 2-core machine: the load average and
the calibration kernel's time are kept; never a pass/fail test.
Run: ``.venv/bin/python benchmarks/bench_first_run.py --out out/bench [--scenes a,b]``.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from common import machine, write_json  # noqa: E402

CHILD = """
import json, sys
from interplay.cli.command import main
from interplay.coupling import compilation
code = main(sys.argv[2:])
json.dump({"code": code, "log": compilation.compile_log(), "seconds": compilation.seconds()},
          open(sys.argv[1], "w"))
"""


def run(scene: str, cache: Path, out: Path) -> dict:
    """One ``interplay run`` in a fresh process with the given Numba cache folder."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    log = out / "compile_log.json"
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", CHILD, str(log), "run", scene, "--no-video",
                        "--quiet", "--out", str(out / "run")], env=env, capture_output=True,
                       text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        return {"error": (p.stderr.strip().splitlines() or ["?"])[-1], "wall_s": wall}
    child = json.loads(log.read_text())
    t = json.loads((out / "run" / "summary.json").read_text())["timings"]
    top = sorted((e for e in child["log"] if e[1] == 0), key=lambda e: -e[2])
    return {"wall_s": wall, "process_compile_s": child["seconds"], "compile_s": t["compile_s"],
            "primary_pass_s": t["primary_pass_s"], "total_s": t["total_s"],
            "kernels_compiled": len(child["log"]),
            "slowest_kernels": [{"name": n, "s": s} for n, _, s in top[:8]]}


def main():
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--scenes", default=None, help="comma-separated (default: every scene)")
    a = ap.parse_args()
    from interplay.scenes import all_specs
    names = a.scenes.split(",") if a.scenes else [s.name for s in all_specs()]
    result = {"benchmark": "first_run", "machine": machine(), "scenes": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            cache = Path(tmp) / f"cache-{name}"
            shutil.rmtree(cache, ignore_errors=True)
            first = run(name, cache, Path(tmp) / name / "first")
            warm = run(name, cache, Path(tmp) / name / "warm")
            row = {"first": first, "warm": warm, "load_1min": os.getloadavg()[0]}
            if "error" not in first and "error" not in warm:
                row["first_over_warm"] = first["wall_s"] / warm["wall_s"]
                row["overhead_s"] = first["wall_s"] - warm["wall_s"]
            result["scenes"][name] = row
            print(f"{name:11s} first {first['wall_s']:6.1f} s  warm {warm['wall_s']:6.1f} s  "
                  f"compile {first.get('process_compile_s', float('nan')):5.1f} s  "
                  f"{first.get('kernels_compiled', 0):3d} kernels  "
                  f"ratio {row.get('first_over_warm', float('nan')):4.1f}", flush=True)
    print(f"wrote {write_json(a.out, 'bench_first_run.json', result)}")


if __name__ == "__main__":
    main()
