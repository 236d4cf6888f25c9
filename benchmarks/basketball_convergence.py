"""Convergence study of the two-way basketball's ball path against the net's step (issue 22,
item 2): is there a converged reference to measure a faster method against?

Runs the default scene's explicit net in strict lock step (coupling step = net step) and
sub-cycled (the default 1 ms coupling step) at each step given, records the ball at the
scene's checkpoints, and reports every run's distance (m) from each lock-step run finer than
1e-5 s, with its wall time. With friction the knots stick to the ball and slip again, so the
path after the ball enters the net has a spread over the steps rather than a limit
(docs/coupling.md, "Is there a converged reference?"). Writes DIR/basketball_convergence.json;
nothing passes or fails.

    python benchmarks/basketball_convergence.py [--out out/bench] [--quick]

(--quick: lock steps down to 5e-6 s only, ~1 min; the full study runs lock steps to 1.25e-6 s,
~5 min on an idle machine.)
"""
from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from common import machine, parse_args, write_json  # noqa: E402
from interplay.scenes import basketball as B  # noqa: E402

LOCK_STEPS = (1e-5, 5e-6, 2.5e-6, 1.25e-6)  # s, strict lock step
SUB_STEPS = (1.25e-6, 2.5e-6, 5e-6, 1e-5, 2e-5, 2.5e-5, 1 / 30000, 5e-5)  # s, sub-cycled


def ball_path(dt: float, lock: bool) -> tuple[dict, float]:
    """The ball's position (m) at each checkpoint, keyed by time (s), and the wall time (s)."""
    p = B.BasketballParams()
    if lock:
        p = dataclasses.replace(p, coupling_dt=dt)
    t0 = time.perf_counter()
    r = B.build("two-way", dt=dt, params=p).simulate()
    wall = time.perf_counter() - t0
    return {str(t): np.asarray(r.state_at("ball", t)[0][:3], float).tolist()
            for t in B.CHECKPOINTS}, wall


def main() -> Path:
    args, _ = parse_args(__doc__)
    lock_steps = [h for h in LOCK_STEPS if h >= 5e-6] if args.quick else list(LOCK_STEPS)
    info = machine()
    B.build("two-way").simulate()  # compile or load the kernels before timing
    runs = {}
    for lock, steps in ((True, lock_steps), (False, SUB_STEPS)):
        for h in steps:
            name = f"{'lock' if lock else 'sub'} {h:.3g}"
            path, wall = ball_path(h, lock)
            runs[name] = {"net_dt_s": h, "lock_step": lock, "wall_s": wall, "ball_path_m": path}
            print(f"{name:12s} wall {wall:7.2f} s", flush=True)
    refs = [n for n, r in runs.items() if r["lock_step"] and r["net_dt_s"] < 1e-5]
    for r in runs.values():
        r["distance_from_m"] = {
            ref: {t: float(np.linalg.norm(np.subtract(r["ball_path_m"][t],
                                                      runs[ref]["ball_path_m"][t])))
                  for t in r["ball_path_m"]} for ref in refs}
    print("distance (cm) at the checkpoints " + ", ".join(map(str, B.CHECKPOINTS)) + " s from:")
    for ref in refs:
        print(f"  {ref}")
        for name, r in runs.items():
            d = r["distance_from_m"][ref]
            print(f"    {name:12s} " + " ".join(f"{100 * d[t]:5.2f}" for t in d))
    return write_json(args.out, "basketball_convergence.json",
                      {"benchmark": "basketball_convergence", "machine": info, "runs": runs})


if __name__ == "__main__":
    print("wrote", main())
