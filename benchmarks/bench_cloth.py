"""Cloth drape benchmark: a 1 m cloth pinned at two corners drapes over a fixed sphere (radius
0.25 m) for 2 s, at several resolutions, with our integrators and the peers that install here
(MuJoCo's flex; NVIDIA Newton on the CPU when `newton` imports) on the same scene.

Writes DIR/bench_cloth.json atomically: simulated seconds per wall second (median of the
repeats; one run for sizes whose first run took over 20 s), each solver's step, the log-log
exponent of cost against vertex count, for local/global the iterations a step and how much of
backward Euler's objective its steps leave unminimized (`objective_gap`), the parallel spring kernel's
speed-up, and the machine. A size whose predicted run time exceeds --budget seconds is skipped
and listed as such. Never a pass/fail timing assert.

    .venv/bin/python benchmarks/bench_cloth.py --out out/bench
    .venv/bin/python benchmarks/bench_cloth.py --sizes 32 64 128 --solvers localglobal newton
"""
from __future__ import annotations

from common import machine, parse_args, stats, write_json  # noqa: I001 (pins threads first)

import copy  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from drape import (CONTACT_KD, CONTACT_KE, DENSITY, DURATION, HEIGHT, MU,  # noqa: E402
                   RADIUS, STRETCH, THICKNESS)
from drape import FRAME as H  # noqa: E402

CONTACT = (THICKNESS, CONTACT_KE, CONTACT_KD, MU, 0.01, 0.0)  # + eps m/s, constraint off
PROBES = (0.5, 1.0, 1.5, 2.0)  # s: local/global steps compared with converged ones here
CONVERGED = dict(lg_iterations=3000, lg_tolerance=1e-9)  # same solver and history


def cloth(n, integrator, dt, **kw):
    from interplay.geometry import shapes
    from interplay.systems.springmass import SpringNetwork
    x, t = shapes.grid(1.0, 1.0, n, n, origin=(-0.5, -0.5, HEIGHT))
    # stiffness-proportional damping shrinks the explicit bound (kd/m h < 2 per spring), so the
    # explicit cloth runs without it: the bound stays the undamped sqrt(2 m / sum k)
    beta = 0.0 if integrator == "explicit" else 1e-4
    return SpringNetwork.from_mesh("c", x, t, DENSITY, STRETCH, dt=dt, integrator=integrator,
                                   mass_damping=0.1, stiffness_damping=beta, fixed=[0, n - 1],
                                   **kw)


def drape_step(net, seg):
    """One coupling step against the sphere, sub-cycled in the network (its ``subcycle``
    hook): every integrator collides the points (as (p, p) element pairs)."""
    from interplay.kernels.contact import colliders
    net.clear_forces()
    cols = colliders(1)
    cols.radii[0], cols.masses[0], cols.law[0] = RADIUS, 1e9, CONTACT
    n = len(net.x)
    net.subcycle(cols, np.stack([np.arange(n)] * 2, axis=1))
    net.advance(H)


def step_gap(net, seg):
    """How much of backward Euler's objective one local/global step with the network's
    settings leaves unminimized: (Phi - Phi*) / (Phi0 - Phi*), Phi0 at the first guess and
    Phi* after a converged step (0 = converged, 1 = no progress). Both steps run on copies,
    so the network (and its L-BFGS history) is left as it was. Objective rather than
    positions: positions differ most along near-flat folding modes, which cost almost no energy
    and which a converged solve may settle either way."""
    best = copy.deepcopy(net)
    for k, v in CONVERGED.items():
        setattr(best, k, v)
    best.lg_memory = best.lg_memory or 5  # plain rows: converge with L-BFGS
    drape_step(best, seg)
    mine = copy.deepcopy(net)
    drape_step(mine, seg)
    phi0, phi = mine.lg_objective
    return float((phi - best.lg_objective[1]) / (phi0 - best.lg_objective[1]))


def ours(n, integrator, probe=False, **kw):
    """Our network on the drape; the probes (local/global only) are not timed."""
    if integrator == "explicit":
        dt = 0.9 * cloth(n, "implicit", 1.0).stable_step()
    else:
        dt = {"implicit": 1.0 / 240.0, "localglobal": H}[integrator]
    net = cloth(n, integrator, dt, cg_tolerance=1e-5, **kw)
    seg = net.segments()
    steps, errors, taken, wall = int(round(DURATION / H)), [], 0, 0.0
    probe_at = {int(round(t / H)) - 1 for t in PROBES} if probe else set()
    for i in range(steps):
        if i in probe_at:
            errors.append(step_gap(net, seg))
        t0 = time.perf_counter()
        drape_step(net, seg)
        wall += time.perf_counter() - t0
        taken += getattr(net, "lg_taken", 0)
    if not np.all(np.isfinite(net.x)):
        raise RuntimeError(f"ours {integrator} {n}^2 went non-finite")
    row = {"wall_s": wall, "dt_s": dt, "lowest_z_m": float(net.x[:, 2].min())}
    if integrator == "localglobal":
        row["iterations_per_step"] = taken / steps
    if errors:
        row["objective_gap"] = errors
    return row


def mujoco_flex(n, dt=2e-3):
    """MuJoCo's 2D flex grid on the same scene (implicitfast, its default contact)."""
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
    t0 = time.perf_counter()
    for _ in range(int(round(DURATION / dt))):
        mujoco.mj_step(m, d)
    return {"wall_s": time.perf_counter() - t0, "dt_s": dt,
            "lowest_z_m": float(np.min(d.flexvert_xpos[:, 2]))}


def newton_runner():
    """Newton's cloth on the CPU, or the reason it cannot run here."""
    try:
        from peer_newton import available, newton_cloth
    except ImportError as e:
        return None, f"not run: {e}"
    why = available()
    if why:
        return None, f"not run: {why}"

    def run(n, first):
        rate, dt, lowest, wall = newton_cloth(n, DURATION)
        return {"wall_s": wall, "dt_s": dt, "lowest_z_m": lowest}
    return run, None


def parallel_speedup(sizes, steps_per_spring=2e6):
    """Serial vs parallel explicit step (us) on the undeformed cloth, and their largest
    position difference after the same steps (m)."""
    rows = []
    for n in sizes:
        a = cloth(n, "explicit", 1e-6, parallel=False)
        b = cloth(n, "explicit", 1e-6, parallel=True)
        steps = max(10, int(steps_per_spring / len(a.si)))
        a.advance(2e-6), b.advance(2e-6)  # compile and warm up
        t0 = time.perf_counter()
        a.advance(steps * 1e-6)
        t1 = time.perf_counter()
        b.advance(steps * 1e-6)
        t2 = time.perf_counter()
        rows.append({"n": n, "springs": len(a.si), "serial_us": (t1 - t0) / steps * 1e6,
                     "parallel_us": (t2 - t1) / steps * 1e6, "speedup": (t1 - t0) / (t2 - t1),
                     "max_diff_m": float(np.abs(a.x - b.x).max())})
        print("parallel", rows[-1], flush=True)
    return rows


def runners(args):
    """name -> run(n, first) -> row (first: the size's first run, which alone is probed),
    and the peers that could not run, with why."""
    out, missing = {}, {}
    for s in args.solvers:
        if s == "localglobal":
            for it in args.lg_iterations:
                for sv in args.lg_solvers:
                    out[f"ours-lbfgs-{sv}-{it}it"] = (
                        lambda n, first, it=it, sv=sv: ours(n, "localglobal", first,
                                                            lg_iterations=it, lg_solver=sv))
                out[f"ours-plain-{it}it"] = (  # plain local/global (L-BFGS memory 0)
                    lambda n, first, it=it: ours(n, "localglobal", first, lg_iterations=it,
                                                 lg_memory=0, lg_solver="direct"))
        elif s in ("implicit", "explicit"):
            out[f"ours-{s}"] = lambda n, first, s=s: ours(n, s)
        elif s == "mujoco":
            out["mujoco-flex"] = lambda n, first: mujoco_flex(n)
        elif s == "newton":
            run, why = newton_runner()
            if run is None:
                missing["newton"] = why
            else:
                out["newton"] = run
    return out, missing


def measure(name, fn, sizes, repeats, budget):
    """Rows for one solver over the sizes, skipping a size predicted to exceed the budget."""
    rows, walls = [], []
    for n in sizes:
        if walls:  # predict from the last growth (or v^1.5 after one size) and skip
            grow = walls[-1][1] / walls[-2][1] if len(walls) > 1 else 8.0
            predicted = walls[-1][1] * grow ** np.log2(n / walls[-1][0])
            if predicted > budget:
                rows.append({"solver": name, "n": n, "skipped": f"predicted {predicted:.0f} s"
                             f" a run > budget {budget:.0f} s"})
                print(f"{name:22s} {n:4d}^2  skipped: predicted {predicted:.0f} s", flush=True)
                continue
        try:
            res = [fn(n, True)]
            if res[0]["wall_s"] < 20.0:
                res += [fn(n, False) for _ in range(repeats - 1)]
        except Exception as e:  # a peer that cannot build or blows up is reported as such
            rows.append({"solver": name, "n": n, "error": str(e)[:200]})
            print(f"{name:22s} {n:4d}^2  error: {str(e)[:120]}", flush=True)
            continue
        wall = stats([r["wall_s"] for r in res])
        row = {"solver": name, "n": n, "vertices": n * n, **res[0], "wall_s": wall,
               "realtime_factor": DURATION / wall["median"], "runs": len(res)}
        walls.append((n, wall["median"]))
        rows.append(row)
        err = row.get("objective_gap")
        print(f"{name:22s} {n:4d}^2  dt={row['dt_s']:.2e} s  {row['realtime_factor']:8.3f}x "
              f"real time  lowest z {row['lowest_z_m']:+.3f} m"
              + (f"  objective gap max {max(err):.3f}" if err else "")
              + f"  ({len(res)} runs)", flush=True)
    return rows


def exponent(rows):
    """Slope of log(wall) against log(vertices) over the measured sizes."""
    pts = [(r["vertices"], r["wall_s"]["median"]) for r in rows if "realtime_factor" in r]
    if len(pts) < 2:
        return None
    v, c = np.log(np.array(pts)).T
    return float(np.polyfit(v, c, 1)[0])


def summary(rows, iterations):
    """Per size: our default local/global (L-BFGS, ``iterations`` a step, lg_solver "auto":
    multigrid from MULTIGRID_MIN_POINTS free points), the fastest peer, and their ratio."""
    from interplay.systems.springmass import MULTIGRID_MIN_POINTS
    rate = {(r["solver"], r["n"]): r["realtime_factor"] for r in rows if "realtime_factor" in r}
    out = []
    for n in sorted({r["n"] for r in rows}):
        solver = "multigrid" if n * n - 2 >= MULTIGRID_MIN_POINTS else "direct"
        mine = rate.get((f"ours-lbfgs-{solver}-{iterations}it", n))
        peers = {k: v for (k, m), v in rate.items() if m == n and not k.startswith("ours")}
        best = max(peers, key=peers.get) if peers else None
        out.append({"n": n, "default": f"ours-lbfgs-{solver}-{iterations}it",
                    "realtime_factor": mine, "fastest_peer": best,
                    "peer_realtime_factor": peers.get(best),
                    "ratio": mine / peers[best] if mine and best else None})
    return out


def main():
    def extra(ap):
        ap.add_argument("--sizes", type=int, nargs="+", default=[32, 64, 128, 256])
        ap.add_argument("--budget", type=float, default=60.0, help="s a run; larger: skipped")
        ap.add_argument("--solvers", nargs="+",
                        default=["localglobal", "implicit", "explicit", "mujoco", "newton"])
        ap.add_argument("--lg-iterations", type=int, nargs="+", default=[10, 20])
        ap.add_argument("--lg-solvers", nargs="+", default=["multigrid", "direct"])
        ap.add_argument("--no-parallel", action="store_true", help="skip the parallel kernel")
    args, repeats = parse_args(__doc__, extra)
    if args.quick:
        args.sizes = [s for s in args.sizes if s <= 64]
    import numba
    import scipy
    info = machine(numpy=np.__version__, scipy=scipy.__version__, numba=numba.__version__,
                   numba_threads=numba.get_num_threads())
    for integ in ("explicit", "implicit", "localglobal"):
        cloth(4, integ, 1e-4).advance(1e-3)  # compile outside the timings
    solvers, missing = runners(args)
    rows, slopes = [], {}
    for name, fn in solvers.items():
        mine = measure(name, fn, args.sizes, repeats, args.budget)
        rows += mine
        slopes[name] = exponent(mine)
    try:
        import mujoco
        info["mujoco"] = mujoco.__version__
    except ImportError:
        info["mujoco"] = None
    result = {"duration_s": DURATION, "coupling_step_s": H, "repeats": repeats,
              "probes_s": PROBES, "converged_step": CONVERGED, "rows": rows,
              "cost_vs_vertices_loglog_exponent": slopes, "peers_not_run": missing,
              "summary": {f"{it}it": summary(rows, it) for it in args.lg_iterations},
              "machine": info}
    if not args.no_parallel:
        result["parallel_explicit"] = parallel_speedup([n for n in args.sizes if n <= 256])
    path = write_json(args.out, "bench_cloth.json", result)
    for key, table in result["summary"].items():
        for row in table:
            print("summary", key, row)
    print("exponents", {k: (round(v, 2) if v else v) for k, v in slopes.items()}, "->", path)


if __name__ == "__main__":
    main()
