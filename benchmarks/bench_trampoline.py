"""Benchmark of the trampoline scene (issue 15). Writes DIR/bench_trampoline.json; nothing
passes or fails on time.

* ``two_way``: the default scene two-way (gymnast + bed, the contact sub-cycled in the bed's
  8 substeps per 1 ms coupling step), simulated seconds per wall second; target >= 1 (real
  time). Split into the seconds with the gymnast on the bed and in the air (the contact
  costs only while she touches it).
* ``hybrid_primary``: the hybrid primary pass (the gymnast on the bed's stand-in), what
  the animator waits for while tuning; ``figure_alone``: the same figure with no bed at all
  (one-way primary pass), the floor of what any coupling can cost.
* ``search``: wall time of one search trial (``control/bounce_search.trial`` scored, the
  default controller, two-way and hybrid; their ratio is how much faster the stand-in tunes),
  and the shipped search's own wall time as recorded in its tune.json (``--search FILE``,
  written by ``interplay tune trampoline``), against the 30 min target.

Medians of --repeats runs (>= 3) after an untimed warm-up that compiles the kernels; the
JSON records the load average before and after (the machine is shared).

    .venv/bin/python benchmarks/bench_trampoline.py --out out/bench [--repeats 3] [--quick]
        [--search out/trampoline-tune/tune.json]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import json  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from interplay.control.bounce_search import score, trial  # noqa: E402
from interplay.scenes import trampoline as T  # noqa: E402


def bench_run(coupling: str, duration: float, repeats: int) -> dict:
    T.build(coupling, duration=0.05).simulate(primary_only=coupling != "two-way")  # compile
    walls, contact = [], None
    for _ in range(repeats):
        scene = T.build(coupling, duration=duration)
        t0 = time.perf_counter()
        r = scene.simulate(primary_only=coupling != "two-way")
        walls.append(time.perf_counter() - t0)
        log = r.logs[r.main] if coupling == "two-way" else r.logs[r.main].standin
        contact = float(log.active.mean()) if log is not None and len(log.t) else 0.0
    med = statistics.median(walls)
    return {"duration_s": duration, "wall_s": stats(walls), "sim_s_per_wall_s": duration / med,
            "share_in_contact": contact}


def bench_trial(coupling: str, repeats: int) -> dict:
    trial(T.TrampolineParams(), coupling, 0.5)  # compile
    walls, loss = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        loss, metrics = score(trial(T.TrampolineParams(), coupling, 14.0))
        walls.append(time.perf_counter() - t0)
    return {"wall_s": stats(walls), "loss": loss, "bounces": metrics["bounces"]}


def main():
    a, repeats = parse_args(__doc__, lambda ap: ap.add_argument(
        "--search", default=None, help="a tune.json whose search wall time to report"))
    import mujoco
    duration = 4.0 if a.quick else 20.0
    result = {"machine": machine(mujoco=mujoco.__version__), "repeats": repeats,
              "two_way": bench_run("two-way", duration, repeats),
              "hybrid_primary": bench_run("hybrid", duration, repeats),
              "figure_alone": bench_run("one-way", duration, repeats),
              "trial_two_way": bench_trial("two-way", repeats),
              "trial_hybrid": bench_trial("hybrid", repeats)}
    if a.search:
        doc = json.loads(Path(a.search).read_text())
        result["search"] = {k: doc[k] for k in ("coupling", "seed", "chains", "budget",
                                                "evaluations", "loss", "wall_s", "executor")}
    # the same simulated time two-way and on the stand-in (a trial stops early once she has
    # fallen, so trials compare the controller's luck as well as the cost)
    ratio = (result["hybrid_primary"]["sim_s_per_wall_s"]
             / result["two_way"]["sim_s_per_wall_s"])
    result["two_way_over_hybrid"] = ratio
    result["targets"] = {"two_way": 1.0, "search_wall_s": 1800.0}
    out = write_json(a.out, "bench_trampoline.json", result)
    for key, label in (("two_way", "two-way (gymnast + bed)"),
                       ("hybrid_primary", "hybrid primary pass (stand-in)"),
                       ("figure_alone", "figure alone (one-way primary)")):
        r = result[key]
        print(f"{label:34s} {r['sim_s_per_wall_s']:6.2f} simulated s per wall s "
              f"({100 * r['share_in_contact']:.0f}% of steps in contact)")
    for key in ("trial_two_way", "trial_hybrid"):
        r = result[key]
        print(f"{key:34s} {r['wall_s']['median']:6.2f} s a trial ({r['bounces']} bounces)")
    print(f"two-way costs {ratio:.1f}x the hybrid primary pass per simulated second")
    if "search" in result:
        s = result["search"]
        print(f"shipped search: {s['evaluations']} evaluations, {s['wall_s']:.0f} s "
              f"({s['coupling']}, {s['chains']} chains, {s['executor']['workers']} workers)")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
