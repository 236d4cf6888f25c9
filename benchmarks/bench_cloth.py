"""Cloth drape benchmark: a 1 m cloth pinned at two corners drapes over a fixed sphere
(radius 0.25 m) for 2 s, at several resolutions, with our explicit and implicit integrators
and MuJoCo's flex on the same scene. Writes JSON: simulated seconds per wall second (median
of --runs runs) at each integrator's largest stable step, and the log-log exponent of cost
against vertex count. Never a pass/fail timing assert.

    NUMBA_THREADING_LAYER=workqueue OPENBLAS_NUM_THREADS=1 \
        .venv/bin/python benchmarks/bench_cloth.py --sizes 32 64 --out bench_cloth.json
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import time

import numpy as np

os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

DURATION = 2.0  # s
RADIUS = 0.25  # m, sphere at the origin
HEIGHT = 0.35  # m, the cloth starts flat this high, centred over the sphere
DENSITY = 0.15  # kg/m^2, cotton
STRETCH = 200.0  # N, k = ratio / l0: cotton-like (the flags' cotton is 150 N)


def ours(n, integrator):
    """(simulated s per wall s, dt) for our network; the sphere contact is sub-cycled in the
    network's kernel (the basketball's path) and forces are exchanged every 1/60 s."""
    from interplay.geometry import shapes
    from interplay.systems.springmass import SpringNetwork
    x, t = shapes.grid(1.0, 1.0, n, n, origin=(-0.5, -0.5, HEIGHT))
    # stiffness-proportional damping shrinks the explicit bound (kd/m h < 2 per spring), so the
    # explicit cloth runs without it: the bound stays the undamped sqrt(2 m / sum k)
    beta = 0.0 if integrator == "explicit" else 1e-4
    kw = dict(mass_damping=0.1, stiffness_damping=beta, fixed=[0, n - 1])
    probe = SpringNetwork.from_mesh("c", x, t, DENSITY, STRETCH, integrator="implicit", **kw)
    dt = 0.9 * probe.stable_step() if integrator == "explicit" else 1.0 / 240.0
    h = max(dt, 1.0 / 60.0)
    net = SpringNetwork.from_mesh("c", x, t, DENSITY, STRETCH, dt=dt, integrator=integrator,
                                  cg_tolerance=1e-5, **kw)
    seg = net.segments()
    contact = (0.005, 2.0e3, 0.01, 0.3, 0.01, 0.0)  # thickness m, N/m, N s/m, mu, m/s, penalty
    t0 = time.perf_counter()
    for _ in range(int(round(DURATION / h))):
        net.clear_forces()
        net.add_moving_sphere(seg, np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), RADIUS,
                              1e9, contact)
        net.advance(h)
    wall = time.perf_counter() - t0
    if not np.all(np.isfinite(net.x)):
        raise RuntimeError(f"ours {integrator} {n}^2 went non-finite")
    return DURATION / wall, dt, float(net.x[:, 2].min())


def mujoco_flex(n, dt=2e-3):
    """(simulated s per wall s, dt) for MuJoCo's 2D flex grid on the same scene."""
    import mujoco
    sp = 1.0 / (n - 1)
    xml = f"""<mujoco><option timestep="{dt}" integrator="implicitfast"/>
    <worldbody><geom type="sphere" size="{RADIUS}"/>
    <flexcomp name="cloth" type="grid" count="{n} {n} 1" spacing="{sp} {sp} {sp}"
        pos="0 0 {HEIGHT}" radius="0.002" dim="2" mass="{DENSITY}">
      <edge equality="true" damping="0.001"/>
      <pin id="0 {n - 1}"/>
    </flexcomp></worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    steps = int(round(DURATION / dt))
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    wall = time.perf_counter() - t0
    return DURATION / wall, dt, float(np.min(d.flexvert_xpos[:, 2]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[32, 64, 128, 256])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--peers", nargs="*", default=["mujoco"])
    ap.add_argument("--out", default="bench_cloth.json")
    args = ap.parse_args()
    ours(8, "explicit"), ours(8, "implicit")  # compile outside the timings
    rows = []
    runners = {"ours-explicit": lambda n: ours(n, "explicit"),
               "ours-implicit": lambda n: ours(n, "implicit")}
    if "mujoco" in args.peers:
        runners["mujoco-flex"] = mujoco_flex
    for name, fn in runners.items():
        for n in args.sizes:
            try:
                res = [fn(n) for _ in range(args.runs)]
            except Exception as e:  # a peer that cannot build or blows up is reported as such
                rows.append({"solver": name, "n": n, "error": str(e)[:200]})
                print(name, n, "error:", str(e)[:120], flush=True)
                continue
            rate = statistics.median(r[0] for r in res)
            rows.append({"solver": name, "n": n, "vertices": n * n, "dt_s": res[0][1],
                         "realtime_factor": rate, "lowest_z_m": res[0][2]})
            print(f"{name:14s} {n:4d}^2  dt={res[0][1]:.2e} s  {rate:8.3f}x real time  "
                  f"lowest z {res[0][2]:+.3f} m", flush=True)
    slopes = {}
    for name in runners:
        pts = [(r["vertices"], 1.0 / r["realtime_factor"]) for r in rows
               if r["solver"] == name and "realtime_factor" in r]
        if len(pts) >= 2:
            v, c = np.log(np.array(pts)).T
            slopes[name] = float(np.polyfit(v, c, 1)[0])
    out = {"duration_s": DURATION, "runs": args.runs, "rows": rows,
           "cost_vs_vertices_loglog_exponent": slopes,
           "newton": "not run: not installed here, and not attempted in this benchmark"}
    with open(args.out, "w") as f:
        json.dump(out, f, indent=2)
    print(json.dumps(slopes))


if __name__ == "__main__":
    main()
