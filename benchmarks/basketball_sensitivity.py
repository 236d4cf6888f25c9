"""How sensitive is the two-way basketball's ball path to its start (issue 22, items 2 and 3)?

The issue asks for a fast method within 1 cm of "the converged lock-step reference" at every
checkpoint. The convergence study (basketball_convergence.py) found the fine lock steps
themselves 0.5-1.4 cm apart at t = 0.6 s. This measures why: the default scene in strict
lock step at a fine net step, its ball started ``delta`` m further along x (1e-9 to 1e-7 m,
far below any step's error), with the default friction 1.0 and frictionless; it reports
each perturbed run's distance (m) from the unperturbed one at the checkpoints, and the
amplification (distance / delta) at the last. Writes DIR/basketball_sensitivity.json;
nothing passes or fails.

    python benchmarks/basketball_sensitivity.py [--out out/bench] [--quick]

(--quick: delta 1e-7 m only, 4 runs of ~30 s; the full study 8 runs.)
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

STEP = 5e-6  # s: the net's step and the coupling step (strict lock step)
DELTAS = (1e-9, 1e-8, 1e-7)  # m: how much further along x the ball starts
FRICTIONS = (1.0, 0.0)  # the default, and none


def ball_path(friction: float, delta: float) -> tuple[np.ndarray, float]:
    """The ball's positions (m) at the checkpoints, started ``delta`` m further along x, and
    the wall time (s)."""
    p = B.BasketballParams()
    x, y, z = p.ball.position
    p = dataclasses.replace(p, coupling_dt=STEP,
                            contact=dataclasses.replace(p.contact, friction=friction),
                            ball=dataclasses.replace(p.ball, position=(x + delta, y, z)))
    t0 = time.perf_counter()
    r = B.build("two-way", dt=STEP, params=p).simulate()
    return (np.array([r.state_at("ball", t)[0][:3] for t in B.CHECKPOINTS]),
            time.perf_counter() - t0)


def main() -> Path:
    args, _ = parse_args(__doc__)
    deltas = DELTAS[-1:] if args.quick else DELTAS
    info = machine(step_s=STEP)
    B.build("two-way").simulate()  # compile or load the kernels before timing
    rows = []
    for mu in FRICTIONS:
        base, wall = ball_path(mu, 0.0)
        for delta in deltas:
            path, w = ball_path(mu, delta)
            d = np.linalg.norm(path - base, axis=1)
            rows.append({"friction": mu, "delta_m": delta, "wall_s": [wall, w],
                         "distance_m": dict(zip(map(str, B.CHECKPOINTS), d.tolist())),
                         "amplification_at_last": float(d[-1] / delta)})
            print(f"friction {mu:3.1f}  delta {delta:7.1e} m  distance (mm) at "
                  f"{', '.join(map(str, B.CHECKPOINTS))} s: "
                  + " ".join(f"{1e3 * v:8.4f}" for v in d)
                  + f"  amplification {d[-1] / delta:9.3g}", flush=True)
    return write_json(args.out, "basketball_sensitivity.json",
                      {"benchmark": "basketball_sensitivity", "machine": info, "runs": rows})


if __name__ == "__main__":
    print("wrote", main())
