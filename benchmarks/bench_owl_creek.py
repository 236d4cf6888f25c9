"""Benchmark of the owl-creek scene (issue 20): wall time per coupling mode. Writes
DIR/bench_owl_creek.json; nothing passes or fails on time.

Each mode runs the scene (drapes left out: they cost the same in every mode) for --duration
simulated seconds: the noose two-way (the default: the alien and the rope in lock step, the
rope's 10 substeps per 1 ms coupling step carrying the sub-cycled contact) without the vest,
with it one-way (the default: driven by his recorded motion in a pass of its own) or
two-way (the vest in lock step with him too), and the noose one-way (the alien alone, then
the rope driven by his recorded motion: the paper's failure, timed for what it would save),
no vest.
Per mode: the primary debug-cycle time (the passes up to the alien's), the total, simulated
seconds per wall second, and the ratio to the two-way noose timed in the same run. Medians of
--repeats runs after an untimed warm-up that compiles the kernels.

    .venv/bin/python benchmarks/bench_owl_creek.py --out out/bench [--repeats 3] [--quick]
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import statistics  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402

from interplay.scenes import owl_creek as OC  # noqa: E402


def modes() -> dict:
    """label -> (noose coupling, changes to the scene's parameters)."""
    none = {"vest": {"enabled": False}}
    return {"noose two-way": ("two-way", none),
            "noose two-way, vest one-way (the default)": ("two-way", {}),
            "noose and vest two-way": ("two-way", {"vest": {"coupling": "two-way"}}),
            "noose one-way": ("one-way", none)}


def _params(changes: dict) -> OC.OwlCreekParams:
    p = OC.OwlCreekParams()
    p = replace(p, drapes=replace(p.drapes, enabled=False))
    for group, values in changes.items():
        p = replace(p, **{group: replace(getattr(p, group), **values)})
    return p


def bench(coupling: str, changes: dict, duration: float, repeats: int) -> dict:
    OC.build(coupling, duration=0.05, params=_params(changes)).simulate()  # compile
    walls, prim = [], []
    for _ in range(repeats):
        scene = OC.build(coupling, duration=duration, params=_params(changes))
        t0 = time.perf_counter()
        r = scene.simulate()
        walls.append(time.perf_counter() - t0)
        prim.append(r.primary_cycle_s)
    return {"coupling": coupling, "changes": changes,
            "duration_s": duration, "wall_s": stats(walls), "primary_pass_s": stats(prim),
            "sim_s_per_wall_s": duration / statistics.median(walls)}


def main():
    a, repeats = parse_args(__doc__, lambda ap: ap.add_argument(
        "--duration", type=float, default=None, help="simulated seconds (default 3; quick 1.5)"))
    import mujoco
    duration = a.duration or (1.5 if a.quick else 3.0)
    result = {"machine": machine(mujoco=mujoco.__version__), "repeats": repeats,
              "modes": {label: bench(c, ch, duration, repeats)
                        for label, (c, ch) in modes().items()}}
    base = result["modes"]["noose two-way"]["wall_s"]["median"]
    for r in result["modes"].values():
        r["wall_over_noose_two_way"] = r["wall_s"]["median"] / base
        r["primary_over_noose_two_way"] = r["primary_pass_s"]["median"] / base
    out = write_json(a.out, "bench_owl_creek.json", result)
    for label, r in result["modes"].items():
        print(f"{label:42s} wall {r['wall_s']['median']:6.2f} s, primary pass "
              f"{r['primary_pass_s']['median']:6.2f} s for {duration:.1f} s simulated "
              f"({r['sim_s_per_wall_s']:.2f}x real time; {r['wall_over_noose_two_way']:.2f}x "
              "the two-way noose)")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
