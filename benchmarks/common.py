"""What every benchmark script shares: its command line, timing statistics, the machine it ran
on, and an atomic JSON write. Import it first: it pins the thread settings (DESIGN.md)."""
from __future__ import annotations

import os

os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
from pathlib import Path  # noqa: E402

from interplay.io.atomic import atomic_path  # noqa: E402


def parse_args(doc: str, extra=None):
    """--out DIR, --repeats N (at least 3) and --quick (1 repeat, short runs), plus whatever
    ``extra(parser)`` adds; returns (args, repeats)."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="1 repeat, short runs (smoke check)")
    if extra is not None:
        extra(ap)
    a = ap.parse_args()
    return a, 1 if a.quick else max(3, a.repeats)


def stats(samples) -> dict:
    """Median, min and every sample (s)."""
    return {"median": statistics.median(samples), "min": min(samples), "samples": samples}


def machine(**extra) -> dict:
    """CPU count, Python, platform, thread settings, load average and the calibration
    kernel's time, plus ``extra``."""
    return {"cpus": os.cpu_count(), "python": platform.python_version(),
            "platform": platform.platform(),
            "numba_threading_layer": os.environ["NUMBA_THREADING_LAYER"],
            "load_average_before": list(os.getloadavg()), "calibration": calibration(),
            **extra}


def _chain(n_nodes: int, steps: int) -> float:
    """A fixed piece of work like ours: a chain of unit masses on springs (k = 1e3 N/m,
    h = 1e-3 s) stepped by symplectic Euler; returns the last node's height (m)."""
    x = [0.001 * i for i in range(n_nodes)]
    v = [0.0] * n_nodes
    for _ in range(steps):
        for i in range(1, n_nodes):
            f = -1e3 * (x[i] - x[i - 1] - 0.001)
            if i + 1 < n_nodes:
                f += 1e3 * (x[i + 1] - x[i] - 0.001)
            v[i] += 1e-3 * (f - 9.81)
        for i in range(1, n_nodes):
            x[i] += 1e-3 * v[i]
    return x[-1]


def calibration(repeats: int = 5) -> dict:
    """The same fixed kernel (``_chain``, 100 nodes x 1,000,000 steps, compiled by Numba without
    a cache) timed in this run: these machines vary 2x from day to day, so a benchmark's
    times divided by this one's median compare across days. {"kernel", "median", "min",
    "samples"} (s)."""
    import time

    import numba
    fn = numba.njit(cache=False)(_chain)
    fn(100, 10)  # compile
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(100, 1_000_000)
        samples.append(time.perf_counter() - t0)
    return {"kernel": "spring chain, 100 nodes x 1,000,000 symplectic Euler steps", **stats(samples)}


def _calibrate(o, unit: float):
    """Beside every timing statistic (a dict with "median" and "samples", from ``stats``) in
    o, its median over the calibration kernel's: a figure that compares across days."""
    if isinstance(o, dict):
        if "median" in o and "samples" in o:
            o["median_over_calibration"] = o["median"] / unit
        for v in o.values():
            _calibrate(v, unit)
    elif isinstance(o, list):
        for v in o:
            _calibrate(v, unit)


def write_json(out_dir, name: str, result: dict) -> Path:
    """Write ``result`` to out_dir/name atomically (temp file, then rename); returns the path.
    Every timing statistic gets its ratio to the calibration kernel timed in ``machine()``."""
    result.setdefault("machine", {})["load_average_after"] = list(os.getloadavg())
    cal = result["machine"].get("calibration")
    if cal is not None:
        _calibrate({k: v for k, v in result.items() if k != "machine"}, cal["median"])
    out = Path(out_dir) / name
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps(result, indent=2))
    return out
