"""Benchmark of the diver scene (SPEC 4): the paper-scale pool (241 x 241 = 58,081 columns over
256 m^2, 5 m deep) with spray, wall time per simulated second of each pass. Writes
DIR/bench_diver.json; nothing passes or fails on time.

* ``hybrid``: the default dive (5.5 s). The primary pass (the figure with its drag-field
  stand-in) and the water pass (the pool driven by the recorded figure) separately, and the
  water pass's rate while the diver is in the water (from the scheduler's progress reports,
  every 500 coupling steps, after the entry). Target: the water pass at >= 0.25x real time.
* ``two-way``: the figure and the pool in lock step (one pass), for the primary debug-cycle
  time it costs against the hybrid primary pass.

    .venv/bin/python benchmarks/bench_diver.py --out out/bench [--repeats 3] [--quick]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import statistics  # noqa: E402
import time  # noqa: E402

from interplay.scenes import diver  # noqa: E402


def run(coupling, duration):
    """One run: (Result, progress samples {pass label: [(sim t, wall s)]})."""
    scene = diver.build(coupling, duration=duration)
    samples = {}

    def progress(p, t, wall, done=False):
        samples.setdefault(p.label, []).append((t, wall))
    result = scene.simulate(progress=progress)
    return result, samples


def rate_after(samples, t0):
    """Simulated s per wall s between the first progress report after t0 (s) and the last."""
    late = [(t, w) for t, w in samples if t >= t0]
    if len(late) < 2:
        return None
    (ta, wa), (tb, wb) = late[0], late[-1]
    return (tb - ta) / (wb - wa) if wb > wa else None


def bench(coupling, repeats, duration):
    diver.build(coupling, duration=0.1).simulate()  # warm-up: compile the kernels
    rows = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res, samples = run(coupling, duration)
        wall = time.perf_counter() - t0
        figures = diver.dive_figures(res)
        entry = figures.get("entry time (s)")
        passes = {"+".join(p["systems"]): p["wall_s"] for p in res.passes}
        in_water = {label: rate_after(s, entry) for label, s in samples.items()} if entry else {}
        rows.append({"wall_s": wall, "passes": passes, "in_water_sim_s_per_wall_s": in_water,
                     "primary_cycle_s": res.primary_cycle_s, "entry_s": entry,
                     "figures": figures,
                     "water": res.diagnostics.get("pool", {})})
    labels = rows[0]["passes"]
    out = {"duration_s": duration, "runs": rows}
    for label in labels:
        med = statistics.median(r["passes"][label] for r in rows)
        out[label] = {"wall_s": stats([r["passes"][label] for r in rows]),
                      "wall_s_per_sim_s": med / duration, "sim_s_per_wall_s": duration / med}
        rates = [r["in_water_sim_s_per_wall_s"].get(label) for r in rows]
        rates = [x for x in rates if x]
        if rates:
            out[label]["in_water_sim_s_per_wall_s"] = statistics.median(rates)
    out["primary_cycle_s"] = stats([r["primary_cycle_s"] for r in rows])
    return out


def main():
    a, repeats = parse_args(__doc__)
    duration = 4.5 if a.quick else diver.SPEC.duration
    grid = diver.DiverParams().pool
    result = {"machine": machine(), "repeats": repeats,
              "pool": {"columns": grid.cells ** 2, "side_m": grid.size, "depth_m": grid.depth},
              "hybrid": bench("hybrid", repeats, duration),
              "two-way": bench("two-way", repeats, duration)}
    h, t = result["hybrid"], result["two-way"]
    result["two_way_total_over_hybrid_primary"] = (
        t["primary_cycle_s"]["median"] / h["primary_cycle_s"]["median"])
    out = write_json(a.out, "bench_diver.json", result)
    for mode in ("hybrid", "two-way"):
        for label, row in result[mode].items():
            if isinstance(row, dict) and "sim_s_per_wall_s" in row:
                extra = row.get("in_water_sim_s_per_wall_s")
                print(f"{mode:8s} pass {label:12s}: {row['sim_s_per_wall_s']:.2f}x real time"
                      + (f" ({extra:.2f}x with the diver in the water)" if extra else ""))
    print(f"primary debug cycle: hybrid {h['primary_cycle_s']['median']:.2f} s, two-way "
          f"{t['primary_cycle_s']['median']:.2f} s "
          f"({result['two_way_total_over_hybrid_primary']:.1f}x)")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
