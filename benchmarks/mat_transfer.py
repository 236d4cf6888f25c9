"""How the landing search's best candidates transfer from the stand-in to the full mat (issue
17, docs/mat.md "Friction that sticks"): the search ranks candidates on the hybrid primary pass
alone; this runs each of the K best (distinct losses) of a search's evaluations.jsonl hybrid
and two-way, and reports `compare mat`'s contrast (the centre-of-mass path off two-way's, the
peak force over two-way's), both dents and whether each sticks. Writes DIR/mat_transfer.json
(atomically); nothing is timed, nothing passes or fails. The runs are spread over --workers
processes (each candidate's two runs in one).

    .venv/bin/python benchmarks/mat_transfer.py out/mat-search/evaluations.jsonl \
        [--best 8] [--workers 2] [--set KEY=VALUE ...] [--out out/bench]
"""
from __future__ import annotations

from common import machine, write_json  # noqa: I001 (pins threads first)

import argparse  # noqa: E402
import json  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402

from interplay.params import apply  # noqa: E402
from interplay.scenes import mat as M  # noqa: E402
from interplay.scenes.landing_measures import contrast, landing_figures  # noqa: E402


def best(path: str, k: int) -> list:
    """The k lowest-loss evaluations with distinct losses: (loss, their vault.* sets)."""
    rows = sorted((json.loads(line) for line in open(path)), key=lambda r: r["loss"])
    out, seen = [], set()
    for r in rows:
        if round(r["loss"], 9) not in seen:
            seen.add(round(r["loss"], 9))
            out.append((r["loss"], [s for s in r["set"] if s.startswith("vault.")]))
    return out[:k]


def transfer(task) -> dict:
    """One candidate run hybrid and two-way: contrast, dents and stick of each."""
    loss, sets, extra = task
    params = apply(M.MatSceneParams(), dict(s.split("=", 1) for s in extra + sets))
    runs = {c: M.build(c, params=params).simulate() for c in ("hybrid", "two-way")}
    fig = {c: landing_figures(r) for c, r in runs.items()}
    c = contrast(runs)
    return {"loss": loss, "sets": sets,
            "path_off_two_way_m": c["hybrid: centre-of-mass path off two-way's (m)"],
            "peak_over_two_way": c["hybrid: peak force over two-way's"],
            **{f"{k}_{c}": fig[c][key] for c in runs for k, key in
               (("peak_N", "peak vertical force (N)"), ("dent_m", "mat depression (m)"),
                ("stuck", "stuck"))}}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("evaluations")
    ap.add_argument("--best", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--out", default="out/bench")
    a = ap.parse_args()
    tasks = [(loss, sets, a.set) for loss, sets in best(a.evaluations, a.best)]
    with ProcessPoolExecutor(a.workers) as pool:
        rows = list(pool.map(transfer, tasks))
    for i, r in enumerate(rows, 1):
        print(f"{i}: loss {r['loss']:.4f}  path {100 * r['path_off_two_way_m']:.2f} cm  peak "
              f"{r['peak_over_two_way']:.3f} ({r['peak_N_hybrid']:.0f} / "
              f"{r['peak_N_two-way']:.0f} N)  dent {r['dent_m_hybrid']:.3f} / "
              f"{r['dent_m_two-way']:.3f} m  stuck {r['stuck_hybrid']}, {r['stuck_two-way']}")
    out = write_json(a.out, "mat_transfer.json",
                     {"machine": machine(), "evaluations": a.evaluations, "sets": a.set,
                      "candidates": rows})
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
