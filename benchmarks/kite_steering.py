"""The stunt kite's answer to its steering (issue 18): from the kite held at the window's top,
full steering to one side for 1.5 s, per design. Records where the kite was held, the lines'
pull, the heading's change in the first second and in 1.5 s (deg, positive to the pilot's
left: a left pull should turn it positive), and the moments on the frame over that first
second (N m about its centre of mass, in the kite's axes: roll about the spine, yaw about the
sail's normal; each look's mean over 0.1 s, then their least, mean and largest) from the sail
(carried, with its air), the bridle and the tail. Writes
DIR/kite_steering.json; nothing passes or fails here (docs/kites.md's table).

    .venv/bin/python benchmarks/kite_steering.py --out out/bench [--dihedral 25,10,0,-10,-25]
        [--seed 0] [--set KEY=VALUE ...]
"""
from __future__ import annotations

from common import machine, parse_args, write_json  # noqa: I001 (pins threads first)

import math  # noqa: E402

import numpy as np  # noqa: E402

from interplay.params import apply  # noqa: E402
from interplay.scenes import stunt_kite  # noqa: E402

STEP = 8.0  # s: when full steering starts (the kite held at the window's top by then)
LENGTH = 1.5  # s of full steering
PARTS = ("sail-ties", "bridle", "tail-tie")
WINDOW = 0.05  # s: each look's moments are the mean over this either side of it


def step_response(overrides: dict, u: float) -> dict:
    """Hold the kite, then steer by u (+1: full left) from STEP for LENGTH s."""
    p = apply(stunt_kite.StuntKiteParams(), {"control.manoeuvre": "hold", **overrides})
    scene = stunt_kite.build(duration=STEP + LENGTH, fps=10.0, params=p)
    pilot = scene.primary.controller
    axes = next(s for s in scene.systems if s.name == "stunt-frame").inertia.axes
    looks = []
    decide = pilot._decide

    def steered(figure, t):  # the pilot as built, overruled from STEP on
        decide(figure, t)
        if t >= STEP:
            pilot.u = u
        phi, eps, chi = pilot.observe(figure.rest.mean(axis=0))
        looks.append((t, math.degrees(phi), math.degrees(eps), math.degrees(chi),
                      pilot.kite.poses()[1][0] @ axes.T))
    pilot._decide = steered
    res = scene.simulate()
    t = np.array([r[0] for r in looks])
    held = [r for r in looks if STEP - 1.0 < r[0] < STEP]
    after = [r for r in looks if r[0] >= STEP]
    turn = np.degrees(np.unwrap(np.radians([r[3] for r in after])))
    first = np.searchsorted(t[t >= STEP], STEP + 1.0)
    pull = 0.0
    for hand in ("l_handle", "r_handle"):
        log = res.logs[f"stunt-{hand}"]
        pull += float(np.linalg.norm(log.force[(log.t > STEP - 1.0) & (log.t < STEP)],
                                     axis=1).mean())
    moments = {}
    for part in PARTS:
        log = res.logs[f"stunt-{part}"]
        roll, yaw = [], []
        for r in after[:first]:
            k = r[4]  # columns: the kite's nose, left and windward normal in the world
            i0, i1 = np.searchsorted(log.t, [r[0] - WINDOW, r[0] + WINDOW])
            tq = log.torque[i0:i1].mean(axis=0)  # the sail's ripple averaged out
            roll.append(tq @ k[:, 0])
            yaw.append(tq @ k[:, 2])
        moments[part] = {"roll_n_m": [float(min(roll)), float(np.mean(roll)),
                                      float(max(roll))],
                         "yaw_n_m": [float(min(yaw)), float(np.mean(yaw)), float(max(yaw))]}
    return {"came_down_s": stunt_kite.KP.came_down(res.frames["stunt-frame"]),
            "held_at_deg": {"elevation": float(np.mean([r[2] for r in held])),
                            "azimuth": float(np.mean([r[1] for r in held])),
                            "heading": float(np.mean([r[3] for r in held]))},
            "pull_n": pull,
            "turn_deg": {"1 s": float(turn[min(first, len(turn) - 1)] - turn[0]),
                         f"{LENGTH} s": float(turn[-1] - turn[0])},
            "moments_first_s": moments}


def main():
    def more(ap):
        ap.add_argument("--dihedral", default="25,10,0,-10,-25")
        ap.add_argument("--seed", type=int, default=0)
        ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    a, _ = parse_args(__doc__, more)
    base = dict(s.split("=", 1) for s in a.set)
    base["wind.seed"] = str(a.seed)
    out = {"machine": machine(), "overrides": base, "cases": {}}
    for d in a.dihedral.split(","):
        case = {}
        for side, u in (("full left", 1.0), ("full right", -1.0)):
            case[side] = step_response({**base, "kite.dihedral": d}, u)
            print(d, side, case[side]["turn_deg"], "down at", case[side]["came_down_s"],
                  flush=True)
        out["cases"][d] = case
    print(write_json(a.out, "kite_steering.json", out))


if __name__ == "__main__":
    main()
