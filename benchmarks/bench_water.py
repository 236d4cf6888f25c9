"""Benchmark of the water (SPEC 2.4): the pond scene's speed, and the volume model's cost per
step against the number of columns. Writes DIR/bench_water.json; nothing passes or fails on
time.

* ``pond``: the default pond (128 x 128 columns, 5 balls, spray on, two-way), simulated
  seconds per wall second of ``scene.simulate()`` (medians of --repeats runs after an untimed
  warm-up that compiles the kernels), with the peak spray count and the volume drift.
* ``scaling``: one coupling step (2 ms) of a still-free Gaussian-bump tank with no bodies, at
  64^2 ... 512^2 columns, time per *substep* (the step count grows with resolution through
  the wave-speed limit, so the per-substep cost is the figure that should be linear), and the
  least-squares slope of log(time) against log(columns): 1.0 is linear.

    .venv/bin/python benchmarks/bench_water.py --out out/bench [--repeats 3] [--quick]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from interplay.geometry.basin import BasinParams, basin  # noqa: E402
from interplay.scenes import pond  # noqa: E402
from interplay.systems.water import Water, WaterParams  # noqa: E402


def bench_pond(repeats, duration):
    pond.build(duration=0.1).simulate()  # warm-up: compile
    walls, last = [], None
    for _ in range(repeats):
        scene = pond.build(duration=duration)
        t0 = time.perf_counter()
        last = scene.simulate()
        walls.append(time.perf_counter() - t0)
    d = last.diagnostics["water"]
    med = statistics.median(walls)
    return {"grid": list(scene.systems[0].shape), "balls": pond.PondParams().balls.count,
            "duration_s": duration, "wall_s": stats(walls),
            "sim_s_per_wall_s": duration / med, "peak_particles": d["peak_particles"],
            "volume_drift_rel": d["volume_drift_rel"], "steps": last.passes[0]["steps"]}


def _tank(cells):
    b = basin(BasinParams(size_x=2.0, size_y=2.0, cells=cells, depth=0.3, shore=0.3))
    X = b.origin[0] + np.arange(cells) * b.spacing
    XX, YY = np.meshgrid(X, X, indexing="ij")
    depth = b.depth + np.where(b.fluid, 0.02 * np.exp(-(XX**2 + YY**2) / 0.02), 0.0)
    return Water("water", b.bed, b.fluid, depth, b.spacing, b.origin, WaterParams())


def bench_scaling(sizes, repeats, steps):
    rows = []
    _tank(32).advance(2e-3)  # compile
    for n in sizes:
        per_sub = []
        for _ in range(repeats):
            w = _tank(n)
            subs = 0
            t0 = time.perf_counter()
            for _ in range(steps):
                w.clear_forces()
                w.advance(2e-3)
            wall = time.perf_counter() - t0
            subs = steps * max(1, int(np.ceil(2e-3 / min(w.dt, 2e-3) - 1e-9)))
            per_sub.append(wall / subs)
        rows.append({"columns": n * n, "grid": [n, n], "s_per_substep": stats(per_sub),
                     "dt_s": w.dt})
    x = np.log([r["columns"] for r in rows])
    y = np.log([r["s_per_substep"]["median"] for r in rows])
    slope = float(np.polyfit(x, y, 1)[0])
    return {"rows": rows, "loglog_slope": slope}


def main():
    a, repeats = parse_args(__doc__)
    result = {"machine": machine(),
              "repeats": repeats,
              "pond": bench_pond(repeats, 0.5 if a.quick else 3.0),
              "scaling": bench_scaling([64, 128, 256, 512], repeats, 5 if a.quick else 50)}
    out = write_json(a.out, "bench_water.json", result)
    p = result["pond"]
    print(f"pond {p['grid'][0]}x{p['grid'][1]}, {p['balls']} balls, spray: "
          f"{p['sim_s_per_wall_s']:.2f} simulated s per wall s (median of {repeats}); peak "
          f"{p['peak_particles']} particles; volume drift {p['volume_drift_rel']:.1e}")
    for r in result["scaling"]["rows"]:
        print(f"  {r['grid'][0]:4d}^2 columns: {1e3 * r['s_per_substep']['median']:.3f} ms "
              "per substep")
    print(f"log-log slope of cost per substep vs columns: "
          f"{result['scaling']['loglog_slope']:.2f}  (1 = linear)")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
