"""Benchmark: the basketball scene (SPEC section 4) in each coupling mode, integrator variant,
and the same scene in MuJoCo; writes DIR/bench_basketball.json (see benchmarks/README.md).

What is timed, and how:
1. Our scene, ``B.build(mode)`` for two-way, one-way and hybrid: wall time of
   ``scene.simulate()`` only (building and settling the net are not timed), after one untimed
   warm-up run so Numba compilation is excluded. Each repeat builds a fresh scene. Reported:
   median, min and all samples of the wall time, ``result.total_s``, the primary debug-cycle
   time ``result.primary_cycle_s``, and ``result.timings()`` of the last repeat.
2. Two-way integrator variants: the default (explicit net at NetParams().dt, ball contact
   sub-cycled inside the net's kernel, coupling_dt 1e-3 s: the two-way entry of 1 is reused),
   the same at dt 5e-5 s, the strict lock-step explicit reference (dt = coupling_dt = 1e-5 s),
   implicit (dt 1e-4 s) and implicit at dt = coupling_dt = 1e-3 s. Beside each time: the
   ball's position at t = 0.6 s and its distance from the reference's.
3. MuJoCo (if installed), built in code with MjSpec: a free shell sphere; one body per knot
   (3 slide joints; the top row pinned: no joints) with our lumped masses and mass damping; a
   1-D flex on the knots for ball-net contact (friction 1.0); one spatial tendon per cord,
   k = EA/l0, damping stiffness_damping*k, tension-only by a spring dead band [0, l0]; a floor.
   (Why not flex edge springs: README.md.) The net settles first (1 s, damping x30, ball held;
   untimed, as ours does). For each step in MJ_STEPS a checked run decides stability (no
   bad-acceleration reset, finite, ball below 1 m at t = 1 s, knots within 1 m of the rim
   circle); the largest stable step is timed (mj_step calls only, after an untimed run).
   Compilation is timed separately. integrator = implicitfast.
   A second construction (``mujoco_flex``), MuJoCo's fastest faithful one by issue 22: no
   tendons, the flex's edges held at rest length by a flex equality constraint (solref two
   steps), swept over MJ_FLEX_STEPS, with each step's largest cord strain; the largest step
   whose cords stretched at most 5% is timed.
   For every run of ours and MuJoCo's, the ball at each checkpoint and its distance from the
   reference's (``ball_path_m``, ``ball_path_error_m``).
4. Ratios from the same run (medians). 5. Machine, versions, thread env vars, load average,
   commit. Wall-clock on a shared machine: orders of magnitude, not a test.
Run: ``.venv/bin/python benchmarks/bench_basketball.py --out out/bench [--repeats N] [--quick]``.
"""
from __future__ import annotations

import os

os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")  # before numpy/numba: DESIGN.md
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

import interplay  # noqa: E402
from interplay.errors import StabilityError  # noqa: E402
from interplay.geometry.net import net_knots  # noqa: E402
from interplay.io.atomic import atomic_path  # noqa: E402

import sys  # noqa: E402
sys.path.insert(0, str(Path(__file__).parent))
from common import calibration  # noqa: E402
from interplay.scenes import basketball as B  # noqa: E402

DURATION = 1.5  # s, the scene's default length
T_CHECK = 0.6  # s, where the ball's position is compared (B.FIT_TIME)
MODES = ("two-way", "one-way", "hybrid")
MJ_STEPS = (2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5)  # s, MuJoCo timesteps tried, largest first
# the flex net's steps: 1.56e-3 s is the one issue 22 found holding its cords under 5% strain
MJ_FLEX_STEPS = (3e-3, 2e-3, 1.56e-3, 1e-3, 5e-4, 2e-4)
REF = "explicit_dt1e-5_lockstep"


def spread(samples) -> dict:
    s = [float(v) for v in samples]
    return {"median": statistics.median(s), "min": min(s), "samples": s}


def ball_at(result, t=T_CHECK) -> list:
    return np.asarray(result.state_at("ball", t)[0][:3], float).tolist()


def ball_path(result) -> dict:
    """The ball's position (m) at each of the scene's checkpoints, keyed by the time (s)."""
    return {str(t): ball_at(result, t) for t in B.CHECKPOINTS}


def path_errors(path, ref) -> dict | None:
    """Distance (m) of a ball path from the reference's at each checkpoint both have."""
    if not path or not ref:
        return None
    return {t: float(np.linalg.norm(np.subtract(path[t], ref[t]))) for t in ref if t in path}


def time_scene(make, repeats):
    """Wall times of simulate() on fresh scenes, after one untimed warm-up run."""
    make().simulate()
    walls, results = [], []
    for _ in range(repeats):
        scene = make()
        t0 = time.perf_counter()
        results.append(scene.simulate())
        walls.append(time.perf_counter() - t0)
    return walls, results


# --- ours ------------------------------------------------------------------------------------
def bench_modes(repeats) -> dict:
    out = {}
    for mode in MODES:
        walls, rs = time_scene(lambda: B.build(mode), repeats)
        out[mode] = {"wall_s": spread(walls), "total_s": spread(r.total_s for r in rs),
                     "primary_cycle_s": spread(r.primary_cycle_s for r in rs),
                     "timings": rs[-1].timings(), "ball_at_0.6_m": ball_at(rs[-1]),
                     "ball_path_m": ball_path(rs[-1]),
                     "warnings": [str(w) for w in rs[-1].warnings]}
    return out


def bench_variants(repeats, modes) -> dict:
    p = B.BasketballParams()
    tw = modes["two-way"]
    out = {"explicit_default_subcycled": {
        "description": f"default: explicit net dt {p.net.dt:g} s, contact sub-cycled, "
                       f"coupling_dt {p.coupling_dt:g} s (the runs of modes.two-way)",
        "net_dt_s": p.net.dt, "coupling_dt_s": p.coupling_dt, "wall_s": tw["wall_s"],
        "ball_at_0.6_m": tw["ball_at_0.6_m"], "ball_path_m": tw["ball_path_m"]}}
    runs = {"explicit_dt5e-5_subcycled": ("explicit net dt 5e-5 s, contact sub-cycled, "
                                          "coupling_dt 1e-3 s", 5e-5, p.coupling_dt,
                                          lambda: B.build("two-way", dt=5e-5)),
            REF: ("explicit net, strict lock step: dt = coupling_dt = 1e-5 s", 1e-5, 1e-5,
                  lambda: B.build("two-way", dt=1e-5,
                                  params=dataclasses.replace(B.BasketballParams(), coupling_dt=1e-5))),
            "implicit_dt1e-4": ("implicit net dt 1e-4 s, coupling_dt 1e-3 s", 1e-4,
                                p.coupling_dt,
                                lambda: B.build("two-way", integrator="implicit", dt=1e-4)),
            # the ball solved with the knots (docs/coupling.md), at the coupling step
            "implicit_dt1e-3": ("implicit net dt = coupling_dt = 1e-3 s", 1e-3, 1e-3,
                                lambda: B.build("two-way", integrator="implicit", dt=1e-3,
                                                params=dataclasses.replace(
                                                    B.BasketballParams(), coupling_dt=1e-3)))}
    for name, (desc, dt, hc, make) in runs.items():
        entry = {"description": desc, "net_dt_s": dt, "coupling_dt_s": hc}
        try:
            walls, rs = time_scene(make, repeats)
        except StabilityError as e:
            entry["error"] = str(e)
        else:
            entry.update(wall_s=spread(walls), timings=rs[-1].timings(),
                         ball_path_m=ball_path(rs[-1]), **{"ball_at_0.6_m": ball_at(rs[-1])})
        out[name] = entry
    ref = out[REF].get("ball_at_0.6_m")
    for entry in out.values():
        if ref is not None and "ball_at_0.6_m" in entry:
            entry["ball_error_vs_reference_m"] = float(np.linalg.norm(
                np.subtract(entry["ball_at_0.6_m"], ref)))
        entry["ball_path_error_m"] = path_errors(entry.get("ball_path_m"),
                                                 out[REF].get("ball_path_m"))
    return out


# --- MuJoCo ----------------------------------------------------------------------------------
def mj_model(mujoco, timestep: float, cords: str = "tendons"):
    """The scene as an MjModel (see the module docstring); returns (model, compile seconds).
    cords: "tendons" (tension-only spatial tendons, k = EA/l0) or "flex-equality" (the flex's
    edges held at their rest lengths by MuJoCo's flex equality constraint, its default soft
    solref: inextensible cords that also resist compression)."""
    p = B.BasketballParams()
    netp, ballp = p.net, p.ball
    x, pairs = net_knots(netp)
    l0 = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    k = netp.cord_ea / l0  # N/m per cord
    m = np.zeros(len(x))  # cord mass lumped half on each end, as basketball_net() does
    cord_mass = netp.mass * l0 / l0.sum()
    np.add.at(m, pairs[:, 0], 0.5 * cord_mass)
    np.add.at(m, pairs[:, 1], 0.5 * cord_mass)
    top = int(netp.loops)  # knots 0..top-1 are the pinned top row
    G = mujoco.mjtGeom
    spec = mujoco.MjSpec()
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.worldbody.add_geom(name="floor", type=G.mjGEOM_PLANE, size=[5, 5, 0.1], priority=1,
                            friction=[p.floor.friction, 0.005, 1e-4])
    ball = spec.worldbody.add_body(name="ball", pos=list(ballp.position))
    ball.add_freejoint()
    ball.explicitinertial = True
    ball.mass = ballp.mass
    ball.inertia = [2.0 / 3.0 * ballp.mass * ballp.radius ** 2] * 3  # hollow shell
    ball.add_geom(type=G.mjGEOM_SPHERE, size=[ballp.radius, 0, 0],
                  friction=[p.contact.friction, 0.005, 1e-4])
    for i, q in enumerate(x):
        kb = spec.worldbody.add_body(name=f"knot{i}", pos=q.tolist())
        if i >= top:
            kb.explicitinertial = True
            kb.mass = m[i]
            kb.inertia = [1e-10] * 3
            for axis in np.eye(3):
                kb.add_joint(type=mujoco.mjtJoint.mjJNT_SLIDE, axis=axis.tolist())
        kb.add_site(name=f"site{i}")
    f = spec.add_flex()  # collision only: capsules of the cord radius along the cords
    f.name, f.dim, f.radius = "net", 1, netp.cord_radius
    f.vertbody = [f"knot{i}" for i in range(len(x))]
    f.vert = [0.0] * (3 * len(x))
    f.elem = pairs.ravel().tolist()
    f.friction = [p.contact.friction, 0.005, 1e-4]
    f.selfcollide = mujoco.mjtFlexSelf.mjFLEXSELF_NONE
    if cords == "flex-equality":
        # as stiff as MuJoCo's soft constraints go stably: a time constant of two steps
        spec.add_equality(type=mujoco.mjtEq.mjEQ_FLEX, name1="net",
                          objtype=mujoco.mjtObj.mjOBJ_FLEX, solref=[2.0 * timestep, 1.0])
    for c, (a, b) in enumerate(pairs if cords == "tendons" else ()):  # the cords' elasticity
        t = spec.add_tendon(name=f"cord{c}", stiffness=float(k[c]),
                            damping=float(netp.stiffness_damping * k[c]),
                            springlength=[0.0, float(l0[c])])  # dead band: tension only
        t.wrap_site(f"site{a}")
        t.wrap_site(f"site{b}")
    t0 = time.perf_counter()
    with warnings.catch_warnings():  # "flex has no passive forces": it only collides here
        warnings.simplefilter("ignore")
        model = spec.compile()
    compile_s = time.perf_counter() - t0
    # MjSpec refuses joint damping on flex vertex bodies; the model takes it (mass damping)
    model.dof_damping[6:] = netp.mass_damping * np.repeat(m[top:], 3)
    return model, compile_s


def mj_settle(mujoco, model, seconds=1.0, boost=30.0):
    """Let the net sag at rest, ball held in place; returns (qpos, seconds, ok)."""
    d = mujoco.MjData(model)
    q0 = d.qpos[:7].copy()
    saved = model.dof_damping.copy()
    model.dof_damping[6:] *= boost
    t0 = time.perf_counter()
    try:
        for _ in range(int(round(seconds / model.opt.timestep))):
            mujoco.mj_step(model, d)
            d.qpos[:7], d.qvel[:6] = q0, 0.0
    finally:
        model.dof_damping[:] = saved
    ok = d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number == 0 and np.isfinite(d.qpos).all()
    return d.qpos.copy(), time.perf_counter() - t0, bool(ok)


def mj_start(mujoco, model, qpos):
    d = mujoco.MjData(model)
    d.qpos[:] = qpos
    d.qvel[:3] = B.BasketballParams().ball.velocity
    mujoco.mj_forward(model, d)
    return d


def mj_check(mujoco, model, qpos) -> dict:
    """A run in 1 ms chunks that watches the stability criteria."""
    netp = B.BasketballParams().net
    ts = model.opt.timestep
    d = mj_start(mujoco, model, qpos)
    knots = model.body("knot0").id
    x, pairs = net_knots(netp)
    l0 = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    chunk = max(1, int(round(1e-3 / ts)))
    n = int(round(DURATION / ts))
    marks = {int(round(t / ts)): str(t) for t in B.CHECKPOINTS}
    out = {"ball_at_0.6_m": None, "ball_z_at_1s_m": None, "max_knot_rim_distance_m": 0.0,
           "max_cord_strain": 0.0, "ball_path_m": {}}
    i = 0
    while i < n:
        # to the next checkpoint or 1 ms on, whichever comes first
        step = min([chunk] + [k - i for k in marks if k > i])
        mujoco.mj_step(model, d, nstep=step)
        i += step
        if i in marks:
            out["ball_path_m"][marks[i]] = np.asarray(d.qpos[:3], float).tolist()
        if d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number or not np.isfinite(d.qpos).all():
            out["failure"] = f"bad acceleration (MuJoCo reset the state) at t = {i * ts:.4f} s"
            break
        xk = d.xpos[knots:]
        dist = np.hypot(np.hypot(xk[:, 0], xk[:, 1]) - netp.rim_radius,
                        xk[:, 2] - netp.rim_height).max()
        out["max_knot_rim_distance_m"] = max(out["max_knot_rim_distance_m"], float(dist))
        strain = np.linalg.norm(xk[pairs[:, 0]] - xk[pairs[:, 1]], axis=1) / l0 - 1.0
        out["max_cord_strain"] = max(out["max_cord_strain"], float(strain.max()))
        if out["ball_z_at_1s_m"] is None and i * ts >= 1.0 - 0.5 * ts:
            out["ball_z_at_1s_m"] = float(d.qpos[2])
    out["ball_at_0.6_m"] = out["ball_path_m"].get(str(T_CHECK))
    if "failure" not in out:
        if out["max_knot_rim_distance_m"] > 1.0:
            out["failure"] = "a knot left the 1 m ball around the rim"
        elif out["ball_z_at_1s_m"] is None or out["ball_z_at_1s_m"] >= 1.0:
            out["failure"] = "ball not below 1 m at t = 1 s"
    out["stable"] = "failure" not in out
    return out


def mj_timed(mujoco, model, qpos):
    """Wall time of the stepping loop only, and the ball at t = 0.6 s."""
    ts = model.opt.timestep
    n, n06 = int(round(DURATION / ts)), int(round(T_CHECK / ts))
    d = mj_start(mujoco, model, qpos)
    t0 = time.perf_counter()
    mujoco.mj_step(model, d, nstep=n06)
    b06 = np.asarray(d.qpos[:3], float).tolist()
    mujoco.mj_step(model, d, nstep=n - n06)
    return time.perf_counter() - t0, b06


def bench_mujoco(repeats, ref, ref_path, cords="tendons", steps=MJ_STEPS,
                 strain_limit=None) -> dict:
    """One MuJoCo construction of the scene (mj_model's ``cords``): a checked run at each of
    ``steps``, then the largest stable one (whose cords stretched at most ``strain_limit``,
    if given: a faithful net) timed; the ball against our reference (at 0.6 s, ``ref``, and
    at every checkpoint, ``ref_path``)."""
    try:
        import mujoco
    except ImportError:
        return {"skipped": "mujoco not installed"}
    log = []
    mujoco.set_mju_user_warning(log.append)  # keep MUJOCO_LOG.TXT out of the working tree
    err = (lambda b: None if b is None or ref is None
           else float(np.linalg.norm(np.subtract(b, ref))))
    sweep = []
    for ts in steps:
        model, _ = mj_model(mujoco, ts, cords)
        qpos, _, ok = mj_settle(mujoco, model)
        row = ({"timestep_s": ts, "stable": False, "failure": "net blew up while settling"}
               if not ok else {"timestep_s": ts, **mj_check(mujoco, model, qpos)})
        row["ball_error_vs_reference_m"] = err(row.get("ball_at_0.6_m"))
        row["ball_path_error_m"] = path_errors(row.get("ball_path_m"), ref_path)
        sweep.append(row)
    stable = [r["timestep_s"] for r in sweep if r["stable"]]
    timed = [r["timestep_s"] for r in sweep if r["stable"] and (
        strain_limit is None or r["max_cord_strain"] <= strain_limit)]
    out = {"version": mujoco.__version__, "integrator": "implicitfast",
           "cords": {"tendons": "spatial tendons (tension-only, k = EA/l0) + a 1-D flex for "
                                "contact",
                     "flex-equality": "a 1-D flex whose edges a flex equality constraint "
                                      "holds at rest length (solref 2 steps)"}[cords],
           "sweep": sweep, "stable_timesteps_s": stable, "strain_limit": strain_limit}
    if timed:
        ts = timed[0]
        model, compile_s = mj_model(mujoco, ts, cords)
        qpos, settle_s, _ = mj_settle(mujoco, model)
        mj_timed(mujoco, model, qpos)  # untimed: warm caches
        runs = [mj_timed(mujoco, model, qpos) for _ in range(repeats)]
        walls = [w for w, _ in runs]
        n = int(round(DURATION / ts))
        row = sweep[steps.index(ts)]
        out.update(timestep_s=ts, compile_s=compile_s, settle_s=settle_s, wall_s=spread(walls),
                   steps=n, us_per_step=1e6 * statistics.median(walls) / n, nv=int(model.nv),
                   ntendon=int(model.ntendon), nflexedge=int(model.nflexedge),
                   max_cord_strain=row["max_cord_strain"],
                   ball_path_error_m=row["ball_path_error_m"],
                   **{"ball_at_0.6_m": runs[-1][1],
                      "ball_error_vs_reference_m": err(runs[-1][1])})
    out["warnings_logged"] = len(log)
    return out


# --- report ----------------------------------------------------------------------------------
def machine() -> dict:
    import numba
    import scipy
    try:
        import mujoco
        mjv = mujoco.__version__
    except ImportError:
        mjv = None
    cpu = platform.processor()
    try:
        cpu = next(ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo")
                   if ln.startswith("model name")) or cpu
    except (OSError, StopIteration):
        pass
    return {"platform": platform.platform(), "processor": cpu, "cpu_count": os.cpu_count(),
            "python": platform.python_version(), "numpy": np.__version__,
            "numba": numba.__version__, "scipy": scipy.__version__, "mujoco": mjv,
            "interplay": interplay.__version__,
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "NUMBA_THREADING_LAYER": os.environ.get("NUMBA_THREADING_LAYER"),
            "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
            "loadavg_start": list(os.getloadavg()), "calibration": calibration(), **source()}


def source() -> dict:
    """The commit measured, and any uncommitted edits under src/ (the tree is shared)."""
    git = ["git", "-C", str(Path(__file__).resolve().parents[1])]
    try:
        head = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True)
        st = subprocess.run(git + ["status", "--porcelain", "--", "src"], capture_output=True,
                            text=True)
    except OSError:
        return {"git_commit": None}
    return {"git_commit": head.stdout.strip() or None,
            "src_uncommitted": [ln[3:] for ln in st.stdout.splitlines()]}


def ratios(modes, variants, mj, mj_flex) -> dict:
    med = lambda e: e["wall_s"]["median"] if e and "wall_s" in e else None  # noqa: E731
    tw = modes["two-way"]["total_s"]["median"]  # result.total_s: the coupled run's wall time
    out = {"two_way_real_time_factor": med(modes["two-way"]) / DURATION,
           "hybrid_primary_over_two_way_total":
               modes["hybrid"]["primary_cycle_s"]["median"] / tw,
           "one_way_primary_over_two_way_total":
               modes["one-way"]["primary_cycle_s"]["median"] / tw}
    for name in (REF, "implicit_dt1e-4", "implicit_dt1e-3"):
        if med(variants[name]) is not None:
            out[f"{name}_over_default"] = med(variants[name]) / med(modes["two-way"])
    if med(mj) is not None:
        out["mujoco_over_two_way"] = med(mj) / med(modes["two-way"])
    if med(mj_flex) is not None:
        out["mujoco_flex_over_two_way"] = med(mj_flex) / med(modes["two-way"])
    return out


def print_table(data, path):
    from rich.console import Console
    from rich.table import Table
    fmt = lambda v: "-" if v is None else f"{v:.3f}"  # noqa: E731
    t = Table(title=f"basketball, {DURATION} s simulated (median of {data['repeats']})")
    for c in ("run", "wall s", "min s", "primary cycle s", "ball @0.6 s (m)", "err vs ref m"):
        t.add_column(c)
    rows = [(f"ours {k}", e) for k, e in data["modes"].items()]
    rows += [(f"two-way {k}", e) for k, e in data["variants"].items()]
    for key, label in (("mujoco", "MuJoCo tendons"), ("mujoco_flex", "MuJoCo flex eq.")):
        if "wall_s" in data[key]:
            rows.append((f"{label} dt {data[key]['timestep_s']:g}", data[key]))
    for name, e in rows:
        w, ball = e.get("wall_s", {}), e.get("ball_at_0.6_m")
        t.add_row(name, fmt(w.get("median")), fmt(w.get("min")),
                  fmt(e.get("primary_cycle_s", {}).get("median")),
                  " ".join(f"{v:+.3f}" for v in ball) if ball else e.get("error", "")[:40],
                  fmt(e.get("ball_error_vs_reference_m")))
    con = Console(width=max(Console().width, 120))
    con.print(t)
    mj = data["mujoco"]
    con.print(f"MuJoCo: {mj['skipped']}" if "skipped" in mj else
              f"MuJoCo stable timesteps (s): {mj['stable_timesteps_s']} of {list(MJ_STEPS)}")
    fl = data["mujoco_flex"]
    for row in fl.get("sweep", ()):
        errs = row.get("ball_path_error_m") or {}
        con.print(f"MuJoCo flex equality dt {row['timestep_s']:g}: "
                  + ("stable" if row["stable"] else row.get("failure", "unstable"))
                  + f", cord strain up to {row.get('max_cord_strain', float('nan')):.1%}, "
                  + "ball off by " + ", ".join(f"{e:.3f}" for e in errs.values()) + " m")
    con.print("ratios: " + ", ".join(f"{k} {v:.3g}" for k, v in data["ratios"].items()))
    con.print(f"wrote {path}")


def main(argv=None) -> Path:
    ap = argparse.ArgumentParser(description="Time the basketball scene (our modes and "
                                 "integrators, and MuJoCo); write DIR/bench_basketball.json.")
    ap.add_argument("--out", default="out/bench", help="output folder (default out/bench)")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per figure (default 3)")
    ap.add_argument("--quick", action="store_true", help="one repeat: a smoke check")
    a = ap.parse_args(argv)
    repeats = 1 if a.quick else max(1, a.repeats)
    info = machine()
    modes = bench_modes(repeats)
    variants = bench_variants(repeats, modes)
    ref, ref_path = variants[REF].get("ball_at_0.6_m"), variants[REF].get("ball_path_m")
    mj = bench_mujoco(repeats, ref, ref_path)
    mj_flex = bench_mujoco(repeats, ref, ref_path, "flex-equality", MJ_FLEX_STEPS,
                           strain_limit=0.05)
    info["loadavg_end"] = list(os.getloadavg())
    data = {"benchmark": "basketball", "duration_s": DURATION, "repeats": repeats,
            "machine": info, "modes": modes, "variants": variants, "mujoco": mj,
            "mujoco_flex": mj_flex, "ratios": ratios(modes, variants, mj, mj_flex)}
    path = Path(a.out) / "bench_basketball.json"
    with atomic_path(path) as tmp:  # temp file beside it, then os.replace
        tmp.write_text(json.dumps(data, indent=2) + "\n")
    print_table(data, path)
    return path


if __name__ == "__main__":
    main()
