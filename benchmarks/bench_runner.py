"""Benchmark: the runner's garments (tee + sweat pants on the CMU jog); writes
DIR/bench_runner.json.

The runner scene (scenes/runner.py) built once (skin, garments, dressing: not timed), then its
garments' pass simulated for ``--seconds`` of the clip, ``repeats`` times: output frames of
1/30 s per wall second of the secondary pass (the garments with their skin contact and the
per-frame certificates, which are timed apart: the same run with the certificates off), the
vertex counts, and the load average. The issue asks for the same garment, body and motion in
MuJoCo's flex cloth as a peer in the same run: not built (docs/clothing.md says why).
Run: ``.venv/bin/python benchmarks/bench_runner.py --out out/bench [--quick]``.
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import time  # noqa: E402

from interplay.scenes import runner as RN  # noqa: E402


def one(seconds: float, certify: bool) -> tuple[float, dict]:
    scene = RN.build(duration=seconds, fps=30.0)
    net = next(s for s in scene.systems if s.name == "clothes")
    if not certify:
        net._skin = None
    t0 = time.perf_counter()
    res = scene.simulate()
    wall = time.perf_counter() - t0
    garments = res.timings()["passes"][1]["wall_s"]
    return garments, {"total_wall_s": wall, "meta": scene.meta}


def main():
    args, repeats = parse_args(__doc__, lambda ap: ap.add_argument("--seconds", type=float,
                                                                    default=1.0))
    seconds = 0.3 if args.quick else args.seconds
    one(0.05, False)  # build, cut, dress and compile once: later builds reuse the dressing
    rows = {}
    for certify in (False, True):
        samples, meta = [], None
        for _ in range(repeats):
            wall, info = one(seconds, certify)
            samples.append(wall)
            meta = info["meta"]
        frames = seconds * 30.0
        rows["with_certificates" if certify else "simulation_only"] = {
            "garment_pass_s": stats(samples), "frames": frames,
            "frames_per_wall_s": frames / stats(samples)["median"]}
    out = {"machine": machine(), "seconds": seconds, "vertices": meta["vertices"],
           "cloth_dt_s": RN.RunnerParams().cloth_dt, "runs": rows,
           "target_frames_per_wall_s": 1.0,
           "peer": {"mujoco_flex": "not built (docs/clothing.md)"}}
    print(write_json(args.out, "bench_runner.json", out))


if __name__ == "__main__":
    main()
