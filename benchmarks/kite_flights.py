"""The kites' flights measured (issue 18): each single-line kite over a long flight (time
aloft, line elevation, azimuth and yaw wander), the diamond flown without its tail, and the
stunt kite's loops and figure-8s over several gust seeds (each manoeuvre's time, whether the
kite came down, each line's taut share). Writes DIR/kite_flights.json; nothing passes or
fails here (the tests assert the physics; this records what the scenes do).

    .venv/bin/python benchmarks/kite_flights.py --out out/bench [--seeds 10] [--quick]
        [--only single|stunt] [--stunt-duration 36] [--set KEY=VALUE ...]
"""
from __future__ import annotations

from common import machine, parse_args, write_json  # noqa: I001 (pins threads first)

import time  # noqa: E402
from dataclasses import replace  # noqa: E402

from interplay.params import apply  # noqa: E402
from interplay.scenes import kites, stunt_kite  # noqa: E402


def single(duration, overrides=None):
    """Every kite of the kites scene over ``duration`` s: its flight (``kites.flight``)."""
    p = apply(kites.KitesParams(), overrides or {})
    t0 = time.perf_counter()
    res = kites.build(duration=duration, fps=10.0, params=p).simulate()
    wall = time.perf_counter() - t0
    return {"overrides": overrides or {}, "duration_s": duration, "wall_s": wall,
            "kites": {name: kites.flight(res, name) for name in kites.KITES}}


def stunt(manoeuvre, seed, duration, overrides=None):
    """One stunt flight in the gusts of ``seed``, the scene's parameters changed by
    ``overrides`` ({--set key: value}): the scene's figures."""
    p = apply(stunt_kite.StuntKiteParams(), overrides or {})
    p = replace(p, control=replace(p.control, manoeuvre=manoeuvre),
                wind=replace(p.wind, seed=seed))
    t0 = time.perf_counter()
    res = stunt_kite.build(duration=duration, fps=10.0, params=p).simulate()
    return {"seed": seed, "overrides": overrides or {}, "wall_s": time.perf_counter() - t0,
            "figures": stunt_kite.figures(res)}


def main():
    def more(ap):
        ap.add_argument("--seeds", type=int, default=10)
        ap.add_argument("--only", choices=("single", "stunt"), default=None)
        ap.add_argument("--stunt-duration", type=float, default=36.0)
        ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a stunt-kite parameter for every stunt flight")
    a, _ = parse_args(__doc__, more)
    long = 30.0 if a.quick else 130.0
    seeds = range(2 if a.quick else a.seeds)
    out = {"machine": machine()}
    if a.only != "stunt":
        out["single"] = single(long)
        out["diamond_without_tail"] = single(60.0 if not a.quick else 30.0,
                                             {"diamond_parts.tail.length": "0"})
    if a.only != "single":
        sets = dict(kv.split("=", 1) for kv in a.set)
        out["stunt"] = {m: [stunt(m, s, a.stunt_duration, sets) for s in seeds]
                        for m in ("loop", "figure8")}
        out["stunt_summary"] = summary(out["stunt"])
    print(write_json(a.out, f"kite_flights{'_' + a.only if a.only else ''}.json", out))


def summary(runs):
    """Per manoeuvre over the seeds: how many completed their first manoeuvre, how many in
    4 s or less (a loop), how many stayed up, and the lines' taut shares (min, median)."""
    import numpy as np
    out = {}
    for m, rs in runs.items():
        first = [next((v for k, v in r["figures"].items() if k.startswith(m + " 1")), None)
                 for r in rs]
        taut = [min(r["figures"].get("l_handle taut share", 0.0),
                    r["figures"].get("r_handle taut share", 0.0)) for r in rs]
        out[m] = {"seeds": len(rs), "completed": sum(f is not None for f in first),
                  "in_4_s": sum(f is not None and f <= 4.0 for f in first),
                  "stayed_up": sum(r["figures"].get("came down at s") is None for r in rs),
                  "first_s": first, "taut_min_share": taut,
                  "taut_95": sum(t >= 0.95 for t in taut),
                  "taut_median": float(np.median(taut))}
    return out


if __name__ == "__main__":
    main()
