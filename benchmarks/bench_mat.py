"""Benchmark of the floor-mat scene (issue 17). Writes DIR/bench_mat.json; nothing passes or
fails on time.

* ``hybrid_primary``: the hybrid primary pass (the gymnast on the vertical spring-dampers),
  what the animator waits for while hand-tuning her landing; simulated s per wall s;
* ``mat_pass``: the hybrid secondary pass (the mat driven one-way by her recorded motion,
  the contact sub-cycled in its explicit substeps);
* ``two_way``: gymnast and mat in lock step, the whole run;
* ``two_way_regularised``: two-way with the contact's regularised friction instead of the
  scene's sticking friction (``contact.stick`` false), the baseline of what sticking costs;
* ratios: the two-way wall time over the hybrid primary pass (the issue asks >= 5), the
  mat pass over the primary pass ("the mat simulation is several times slower than
  hers"), and two-way with sticking friction over two-way without, timed alternately.

Medians of --repeats runs (>= 3) after an untimed warm-up that compiles the kernels; the
JSON records the load average before and after (the machine is shared).

    .venv/bin/python benchmarks/bench_mat.py --out out/bench [--repeats 3] [--quick]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import statistics  # noqa: E402

from dataclasses import replace  # noqa: E402

from interplay.scenes import mat as M  # noqa: E402


def bench(duration: float, repeats: int) -> dict:
    M.build("hybrid", duration=0.05).simulate()  # compile
    M.build("two-way", duration=0.05).simulate()
    p = M.MatSceneParams()
    regularised = replace(p, contact=replace(p.contact, stick=False))
    prim, mat, two, reg = [], [], [], []
    for _ in range(repeats):
        r = M.build("hybrid", duration=duration).simulate()
        t = r.timings()
        prim.append(t["primary_pass_s"])
        mat.append(t["secondary_pass_s"])
        r2 = M.build("two-way", duration=duration).simulate()
        two.append(r2.timings()["primary_pass_s"])  # one pass: both systems
        r3 = M.build("two-way", duration=duration, params=regularised).simulate()
        reg.append(r3.timings()["primary_pass_s"])
    out = {}
    for key, walls in (("hybrid_primary", prim), ("mat_pass", mat), ("two_way", two),
                       ("two_way_regularised", reg)):
        out[key] = {"duration_s": duration, "wall_s": stats(walls),
                    "wall_per_sim_s": statistics.median(walls) / duration,
                    "sim_s_per_wall_s": duration / statistics.median(walls)}
    out["two_way_over_primary"] = statistics.median(two) / statistics.median(prim)
    out["mat_pass_over_primary"] = statistics.median(mat) / statistics.median(prim)
    out["sticking_over_regularised"] = statistics.median(two) / statistics.median(reg)
    return out


def main():
    a, repeats = parse_args(__doc__)
    import mujoco
    duration = 1.2 if a.quick else 2.2
    result = {"machine": machine(mujoco=mujoco.__version__), "repeats": repeats,
              **bench(duration, repeats), "targets": {"two_way_over_primary": 5.0}}
    out = write_json(a.out, "bench_mat.json", result)
    for key, label in (("hybrid_primary", "hybrid primary pass (stand-in)"),
                       ("mat_pass", "mat pass (one-way replay)"),
                       ("two_way", "two-way (gymnast + mat)"),
                       ("two_way_regularised", "two-way, regularised friction")):
        r = result[key]
        print(f"{label:34s} {r['wall_per_sim_s']:6.2f} wall s per simulated s")
    print(f"two-way costs {result['two_way_over_primary']:.1f}x the hybrid primary pass; "
          f"the mat pass {result['mat_pass_over_primary']:.1f}x; sticking friction "
          f"{result['sticking_over_regularised']:.2f}x the regularised law's two-way")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
