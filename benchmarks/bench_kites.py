"""Benchmark of the kites (issue 18): wall time per simulated second of one single-line kite
(the diamond: sail, frame, bridle and line, tail, five attachments), of the kites scene (three
kites) and of the stunt kite (two lines, pilot), each against a baseline timed in the same
run: the diamond's sail alone in the same wind (its cloth and aerodynamics, nothing coupled),
so the ratio is what the components and their coupling cost beyond the cloth. Targets: one
kite >= 1x real time, the stunt kite >= 0.5x. Writes DIR/bench_kites.json; nothing passes
or fails on time.

    .venv/bin/python benchmarks/bench_kites.py --out out/bench [--repeats 3] [--quick]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import time  # noqa: E402

import numpy as np  # noqa: E402

from interplay.geometry.kite import diamond  # noqa: E402
from interplay.interactions.aero import Aerodynamics  # noqa: E402
from interplay.scene import Scene  # noqa: E402
from interplay.scenes import kite_parts as KP  # noqa: E402
from interplay.scenes import kites, stunt_kite  # noqa: E402


def sail_alone(duration):
    """The diamond's sail, pinned at its tie points, in the kites' wind."""
    p = kites.KitesParams()
    scene = Scene("sail", duration=duration, fps=10.0, coupling_dt=p.coupling_dt)
    wind = scene.add(KP.kite_wind(p.wind))
    g = diamond(p.diamond)
    R = KP.launch_pose(np.zeros(3), 20.0, 45.0, g.bridles[0][1], -55.0)
    sail = scene.add(KP.sail_network("sail", g, p.diamond_parts.sail, R[0], R[1], None))
    sail.fixed[g.ties] = True
    scene.connect(Aerodynamics("air", wind, sail, p.diamond_parts.aero))
    return scene


CASES = {"sail alone (baseline)": sail_alone,
         "one kite (diamond)": lambda d: kites.build(duration=d, fps=10.0, kites=("diamond",)),
         "kites scene (three kites)": lambda d: kites.build(duration=d, fps=10.0),
         "stunt kite": lambda d: stunt_kite.build(duration=d, fps=10.0)}


def main():
    a, repeats = parse_args(__doc__)
    duration = 4.0 if a.quick else 20.0
    for make in CASES.values():
        make(0.1).simulate()  # compile the kernels
    rows = {name: [] for name in CASES}
    for _ in range(repeats):  # interleaved: a load change hits every case alike
        for name, make in CASES.items():
            scene = make(duration)
            t0 = time.perf_counter()
            scene.simulate()
            rows[name].append((time.perf_counter() - t0) / duration)
    base = stats(rows["sail alone (baseline)"])["median"]
    out = {"machine": machine(), "repeats": repeats, "duration_s": duration, "cases": {}}
    for name, r in rows.items():
        s = stats(r)
        out["cases"][name] = {"wall_s_per_sim_s": s, "real_time_factor": 1.0 / s["median"],
                              "ratio_to_baseline": s["median"] / base}
        print(f"{name:28s} {s['median']:.3f} wall s per sim s ({1 / s['median']:.2f}x real "
              f"time), {s['median'] / base:.1f}x the sail alone")
    print(write_json(a.out, "bench_kites.json", out))


if __name__ == "__main__":
    main()
