"""Where one coupling step of a kite goes (issue 18): wall ms per coupling step and share of
the run for each system's advance, each interaction's exchange and completion, the frames
recorded, the health checks, and the scheduler's own Python (the rest), measured by wrapping
those methods with a timer (~0.3 us per call, included), with the load average and the
calibration kernel's time (``common.machine``). Prints a table; nothing is written.

    .venv/bin/python benchmarks/kite_breakdown.py [--case one|three|stunt] [--duration 10]
"""
from __future__ import annotations

from common import machine  # noqa: I001 (pins threads first)

import argparse  # noqa: E402
import collections  # noqa: E402
import time  # noqa: E402

from interplay.scenes import kites, stunt_kite  # noqa: E402

CASES = {"one": lambda d: kites.build(duration=d, fps=10.0, kites=("diamond",)),
         "three": lambda d: kites.build(duration=d, fps=10.0),
         "stunt": lambda d: stunt_kite.build(duration=d, fps=10.0)}


def timed(acc, obj, method, key):
    """Replace obj.method by itself timed into acc[key] (s)."""
    f = getattr(obj, method)

    def g(*a, **k):
        t0 = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            acc[key] += time.perf_counter() - t0
    setattr(obj, method, g)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", choices=tuple(CASES), default="one")
    ap.add_argument("--duration", type=float, default=10.0)
    a = ap.parse_args()
    CASES[a.case](0.1).simulate()  # compile the kernels
    scene = CASES[a.case](a.duration)
    acc = collections.defaultdict(float)
    for s in scene.systems:
        kind = s.name.split("-", 1)[-1]
        timed(acc, s, "advance", f"advance {kind}")
        timed(acc, s, "frame", "frame recording")
        timed(acc, s, "health", "health checks")
    for it in scene.interactions:
        kind = f"{type(it).__name__} {it.name.split('-', 1)[-1]}"
        timed(acc, it, "exchange", f"exchange {kind}")
        if hasattr(it, "complete"):
            timed(acc, it, "complete", f"complete {kind}")
    m = machine()
    t0 = time.perf_counter()
    scene.simulate()
    total = time.perf_counter() - t0
    steps = round(a.duration / scene.coupling_dt)
    print(f"{a.case}: {total / a.duration:.3f} wall s per simulated s, {1e3 * total / steps:.3f} "
          f"ms per coupling step ({steps} steps); load average {m['load_average_before']}, "
          f"calibration kernel {m['calibration']['median']:.3f} s")
    rows = sorted(acc.items(), key=lambda kv: -kv[1])
    for key, s in rows + [("scheduler and the rest", total - sum(acc.values()))]:
        print(f"  {key:45s} {1e3 * s / steps:7.3f} ms  {100 * s / total:5.1f}%")


if __name__ == "__main__":
    main()
