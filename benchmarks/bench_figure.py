"""Benchmark of the active figure (SPEC 2.3) and the bungee scene (SPEC 4). Writes
DIR/bench_figure.json; nothing passes or fails on time.

* ``figure``: the bungee jumper alone (``cord.enabled=false``: stand, crouch, tip, leap, fall)
  under his state machine, simulated seconds per wall second of ``scene.simulate()``; target
  >= 20. ``figure_advance``: the same 3 s as ``Figure.advance(1 ms)`` calls without the
  scheduler (what the figure itself costs; the rest is the scheduler's per-step recording and
  monitoring). ``mujoco_only``: the same model stepped by ``mj_step`` with fixed controls (no
  Python at all), the ceiling.
* ``bungee``: the two-way scene (jumper + 23-point cord, coupled every 1 ms); target >= 1.

Medians of --repeats runs (>= 3) after an untimed warm-up that compiles the Numba kernels.

    .venv/bin/python benchmarks/bench_figure.py --out out/bench [--repeats 3] [--quick]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import statistics  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402

from interplay.scenes import bungee  # noqa: E402


def _params(cord: bool):
    p = bungee.BungeeParams()
    return replace(p, cord=replace(p.cord, enabled=cord))


def bench_scene(cord: bool, duration: float, repeats: int) -> dict:
    bungee.build(duration=0.05, params=_params(cord)).simulate()  # warm-up: compile
    walls = []
    for _ in range(repeats):
        scene = bungee.build(duration=duration, params=_params(cord))
        t0 = time.perf_counter()
        scene.simulate()
        walls.append(time.perf_counter() - t0)
    med = statistics.median(walls)
    return {"duration_s": duration, "wall_s": stats(walls), "sim_s_per_wall_s": duration / med,
            "systems": [s.name for s in scene.systems]}


def bench_figure_advance(duration: float, repeats: int) -> dict:
    walls = []
    for _ in range(repeats):
        fig = bungee.jumper(bungee.JumperParams())
        n = int(round(duration / fig.dt))
        t0 = time.perf_counter()
        for _ in range(n):
            fig.advance(fig.dt)
        walls.append(time.perf_counter() - t0)
    med = statistics.median(walls)
    return {"duration_s": duration, "wall_s": stats(walls), "sim_s_per_wall_s": duration / med,
            "us_per_step": 1e6 * med / n}


def bench_mujoco_only(duration: float, repeats: int) -> dict:
    import mujoco
    walls = []
    for _ in range(repeats):
        fig = bungee.jumper(bungee.JumperParams())
        n = int(round(duration / fig.dt))
        t0 = time.perf_counter()
        mujoco.mj_step(fig.model, fig.data, nstep=n)
        walls.append(time.perf_counter() - t0)
    med = statistics.median(walls)
    return {"duration_s": duration, "wall_s": stats(walls), "sim_s_per_wall_s": duration / med,
            "us_per_step": 1e6 * med / n}


def main():
    a, repeats = parse_args(__doc__)
    import mujoco
    result = {"machine": machine(mujoco=mujoco.__version__),
              "repeats": repeats,
              "figure": bench_scene(False, 1.0 if a.quick else 3.0, repeats),
              "figure_advance": bench_figure_advance(1.0 if a.quick else 3.0, repeats),
              "mujoco_only": bench_mujoco_only(1.0 if a.quick else 3.0, repeats),
              "bungee": bench_scene(True, 2.0 if a.quick else 8.0, repeats)}
    result["targets"] = {"figure": 20.0, "bungee": 1.0}
    out = write_json(a.out, "bench_figure.json", result)
    for key, label in (("figure", "figure alone with its controller"),
                       ("figure_advance", "  the same, Figure.advance only"),
                       ("mujoco_only", "MuJoCo mj_step only (no control)"),
                       ("bungee", "two-way bungee (jumper + cord)")):
        r = result[key]
        print(f"{label:36s} {r['sim_s_per_wall_s']:7.2f} simulated s per wall s "
              f"(median of {repeats}, {r['duration_s']:.0f} s runs)")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
