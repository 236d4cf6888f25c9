"""Benchmark: a wedge of 8 short runs on 1 and on 2 local workers, and on a local Ray cluster;
writes DIR/bench_sweep.json.

The wedge: the basketball (two-way, 1.5 s; 0.5 s with --quick) with net.cord_ea at 8 values
from 150 to 500 N, each variant writing every output `interplay sweep` writes by default
(summary, tracks, scene.json, USD, OBJ, a 1280x720 preview video, the report). Timed: one
``run_sweep`` into a fresh folder, from the Numba warm-up (cache already warm: ~0.1 s) and
the workers' start to the last variant's folder; the contact sheet's stills, drawn afterwards
by the driver, are not.

speed_up = median T(1 worker) / median T(2 workers), the repeats interleaved (1, 2, 1, 2, ...)
so that both see the same machine load (loadavg recorded with every sample, and the cores the
sweep actually got: its CPU time over its wall time). Ray: a one-node
cluster of 2 CPUs started here (``local_ray_head``); T(ray) covers connecting, the code check,
Ray's workers starting, the 8 variants and gathering their folders into DIR; overhead per
variant = (median T(ray) - median T(2 workers)) / 8. Wall-clock on a shared 2-core machine:
ratios, never pass/fail.
Run: ``.venv/bin/python benchmarks/bench_sweep.py --out out/bench [--repeats 3] [--no-ray]``.
"""
from __future__ import annotations

import common  # noqa: F401  (thread settings first)

import os  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from interplay.batch.executor import LocalPool, RayCluster, local_ray_head  # noqa: E402
from interplay.batch.sweep import run_sweep  # noqa: E402
from interplay.batch.variants import RunRequest, plan  # noqa: E402
from interplay.outputs.writer import OutputOptions  # noqa: E402

VARIANTS = 8


def cpu_s() -> float:
    """CPU time (s) of this process and its reaped children (a local pool's workers)."""
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def timed_sweep(variants, executor, root: Path) -> dict:
    """One sweep into a fresh folder: wall time, the variants' own wall times summed, the
    CPU time it got (this process and the pool's workers; Ray's are not our children) over
    the wall time, i.e. how many cores it had on average, and the 1-minute load before."""
    out = Path(tempfile.mkdtemp(dir=root))
    load = os.getloadavg()[0]
    c0, t0 = cpu_s(), time.perf_counter()
    doc = run_sweep(variants, out, OutputOptions(quiet=True), executor,
                    {"scene": "basketball", "keys": ["net.cord_ea"]}, log=lambda m: None)
    wall = time.perf_counter() - t0
    cores = (cpu_s() - c0) / wall if executor.kind == "local" else None
    assert doc["counts"]["ok"] == len(variants), doc["counts"]
    per = [r["timings"]["wall_s"] for r in doc["variants"]]
    shutil.rmtree(out)
    return {"wall_s": wall, "variant_wall_s_sum": sum(per), "cores_used": cores,
            "load_1min": load}


def summarise(samples: list) -> dict:
    return {**common.stats([s["wall_s"] for s in samples]),
            "variant_wall_s_sum_median": statistics.median(s["variant_wall_s_sum"]
                                                           for s in samples),
            "cores_used": [s["cores_used"] for s in samples],
            "load_1min": [s["load_1min"] for s in samples]}


def main():
    args, repeats = common.parse_args(__doc__, lambda ap: ap.add_argument(
        "--no-ray", action="store_true", help="skip the Ray cluster"))
    base = RunRequest("basketball", duration=0.5 if args.quick else None)
    variants = plan(base, [{"net.cord_ea": format(v, "g")}
                           for v in np.linspace(150.0, 500.0, VARIANTS)])
    root = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    result = {"benchmark": "sweep", "wedge": {"scene": "basketball", "variants": VARIANTS,
                                              "duration_s": 0.5 if args.quick else 1.5,
                                              "key": "net.cord_ea", "outputs": "all"},
              "machine": common.machine()}
    try:
        timed_sweep(variants[:1], LocalPool(1), root)  # compile once, untimed
        runs = {1: [], 2: []}
        for _ in range(repeats):
            for n in (1, 2):
                runs[n].append(timed_sweep(variants, LocalPool(n), root))
                r = runs[n][-1]
                print(f"{n} worker(s): {r['wall_s']:.2f} s, {r['cores_used']:.2f} cores "
                      f"(load {r['load_1min']:.2f})", flush=True)
        local = {f"workers_{n}": summarise(s) for n, s in runs.items()}
        local["speed_up"] = local["workers_1"]["median"] / local["workers_2"]["median"]
        local["target_speed_up"] = 1.7
        result["local"] = local
        if not args.no_ray:
            result["ray"] = bench_ray(variants, root, repeats, local["workers_2"]["median"])
    finally:
        shutil.rmtree(root, ignore_errors=True)
    path = common.write_json(args.out, "bench_sweep.json", result)
    print(f"speed-up 1 -> 2 workers: {result['local']['speed_up']:.2f}x "
          f"(target 1.7x); wrote {path}")
    if "ray" in result:
        print(f"Ray: {result['ray']['overhead_per_variant_s']:.2f} s per variant over the "
              f"local pool; connecting {result['ray']['connect_s']:.2f} s")


def bench_ray(variants, root, repeats, local_median) -> dict:
    src = str(Path(__file__).resolve().parents[1] / "src")
    env = {"PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}
    t0 = time.perf_counter()
    with local_ray_head(2, env) as address:
        start_s = time.perf_counter() - t0
        t1 = time.perf_counter()
        with RayCluster(address):
            pass
        connect_s = time.perf_counter() - t1
        samples = []
        for _ in range(repeats):
            samples.append(timed_sweep(variants, RayCluster(address), root))
            print(f"ray: {samples[-1]['wall_s']:.2f} s", flush=True)
    s = summarise(samples)
    return {"cluster_start_s": start_s, "connect_s": connect_s, "cpus": 2, **s,
            "overhead_per_variant_s": (s["median"] - local_median) / len(variants),
            "ratio_to_local_2": s["median"] / local_median}


if __name__ == "__main__":
    main()
