"""Benchmark: every scene's warm ``interplay run`` with its default outputs, the wall time
split into the simulation and each output, against the target of 1.5x the simulation;
writes DIR/bench_scenes.json.

Each scene runs in a fresh process, as the command line does, after an untimed short run
that leaves Numba's cache warm: interpreter start and imports, the preflight (which forks the
preview renderer and checks GL in it), building the scene, the simulation (``Result.total_s``)
and ``write_outputs`` with each output's own time (``OutputOptions.timings``: save_s for
summary, tracks and scene.json; usd_s; plots_s; video_render_s and video_encode_s spent in
the renderer's process while the others are written; video_wait_s, how long the writer then
still waited for it; report_s). Ratios: the whole process and the simulation plus outputs,
each over the simulation. Wall-clock on a shared 2-core machine: the load average is kept
beside every row; orders of magnitude, never a pass/fail test.
Run: ``.venv/bin/python benchmarks/bench_scenes.py --out out/bench [--scenes pond,flags]``.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGET = 1.5


def one(name: str, out_dir: str, size: str, obj: bool) -> dict:
    """Run one scene as ``interplay run`` would and return its timings (in this process)."""
    t0 = time.perf_counter()
    from interplay.cli.command import scene_summary
    from interplay.outputs.writer import OutputOptions, preflight, write_outputs
    from interplay.scenes import spec
    s = spec(name)
    w, h = (int(v) for v in size.split("x"))
    options = OutputOptions(quiet=True, camera=s.camera, size=(w, h), obj=obj)
    t1 = time.perf_counter()
    preflight(out_dir, options)
    t2 = time.perf_counter()
    scene = s.build(s.default_coupling, duration=s.duration, fps=s.fps, params=s.params())
    t3 = time.perf_counter()
    result = scene.simulate()
    t4 = time.perf_counter()
    write_outputs(result, out_dir, options, scene_summary(s, result))
    t5 = time.perf_counter()
    return {"imports_s": t1 - t0, "preflight_s": t2 - t1, "build_s": t3 - t2,
            "simulate_s": t4 - t3, "simulation_total_s": result.total_s,
            "outputs_s": t5 - t4, "outputs": dict(options.timings),
            "output_frames": len(next(iter(result.frames.values()))["t"])}


def main():
    import argparse
    import platform
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--scenes", default=None, help="comma-separated (default: every scene)")
    ap.add_argument("--size", default="960x540", help="preview size, WxH")
    ap.add_argument("--obj", action="store_true", help="also time the OBJ sequences")
    ap.add_argument("--keep", default=None, help="keep each scene's outputs in KEEP/SCENE")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--dir", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(a.one, a.dir, a.size, a.obj)))
        return
    from interplay.scenes import all_specs
    names = a.scenes.split(",") if a.scenes else [s.name for s in all_specs()]
    py, cli = sys.executable, [sys.executable, "-m", "interplay.cli.command"]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        keep = Path(a.keep) if a.keep else Path(tmp)
        for name in names:
            # untimed: a short run leaves every kernel compiled in Numba's cache
            subprocess.run(cli + ["run", name, "--duration", "0.1", "--out", f"{tmp}/warm",
                                  "--no-video", "--no-report", "--no-usd", "--quiet"],
                           check=True, capture_output=True)
            load = list(os.getloadavg())
            t0 = time.perf_counter()
            done = subprocess.run([py, __file__, "--one", name, "--dir", str(keep / name),
                                   "--size", a.size] + (["--obj"] if a.obj else []),
                                  check=True, capture_output=True, text=True)
            wall = time.perf_counter() - t0
            r = json.loads(done.stdout.strip().splitlines()[-1])
            sim = r["simulate_s"]
            r.update(process_s=wall, load_average_before=load,
                     load_average_after=list(os.getloadavg()),
                     ratio_process=wall / sim, ratio_sim_plus_outputs=(sim + r["outputs_s"]) / sim,
                     within_target=(sim + r["outputs_s"]) / sim <= TARGET)
            rows[name] = r
            o = r["outputs"]
            print(f"{name:10s} sim {sim:6.2f} s  outputs {r['outputs_s']:6.2f} s "
                  f"(usd {o.get('usd_s', 0):.2f}, plots {o.get('plots_s', 0):.2f}, video "
                  f"{o.get('video_render_s', 0) + o.get('video_encode_s', 0):.2f} beside, "
                  f"waited {o.get('video_wait_s', 0):.2f}, report {o.get('report_s', 0):.2f})  "
                  f"(sim+outputs)/sim {r['ratio_sim_plus_outputs']:.2f}  process/sim "
                  f"{r['ratio_process']:.2f}  load {load[0]:.1f}", flush=True)
    import common  # noqa: F401  (only for the JSON writer and machine facts)
    out = common.write_json(a.out, "bench_scenes.json", {
        "what": "warm `interplay run` per scene: simulation and each output, wall clock",
        "target_ratio": TARGET, "preview_size": a.size, "obj": a.obj,
        "machine": common.machine(python_executable=py, platform_=platform.platform()),
        "scenes": rows})
    print(f"wrote {out}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))
    main()
