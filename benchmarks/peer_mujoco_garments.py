"""MuJoCo's flex cloth as the runner's peer (issue 16): the same garments, body and motion as
scenes/runner.py, timed beside ours in bench_runner.py.

Garment: the runner's dressed tee and sweat pants at t = 0, their own triangles, as two 2-D
flexes (one per garment, because a flex has one material: jersey for the tee, fleece for the
pants). Every free point is a body with three slide joints (the house construction of
bench_basketball.py) of the point's lumped mass (systems/garments.spring_set: area x the
fabric's density, so the total is the garments' mass). The flexes are compiled at the cut
(A-pose) points, so that MuJoCo's rest shape is the cut one, as our rest lengths are; the
joints then carry each point to its dressed place and velocity.

Stretch: MuJoCo's flex elasticity (``elastic2d`` both: its membrane and bending from young,
poisson and thickness). The membrane's sheet stiffness E t is set to our tensile stiffness
per width Y (N/m: our lattice springs k = sqrt3/2 Y give a sheet of stiffness Y) and its
thickness t = sqrt(12 B / Y) so that its plate bending E t^3 / 12 is our bending rigidity B
too (poisson 0). Not matched: our shear springs (60 and 40 N/m) are softer than an isotropic
sheet allows (E t / 2 = 200 and 125 N/m); our elastic bands rest shorter than cut (MuJoCo's
rest is the compiled shape, so its bands rest at their cut girth); our tether (each point
within 3 cm of its skinned reference) has no flex counterpart and is left out.

Integrator: MuJoCo 4.0's ``discrete`` (the constraint solve and an implicit velocity update
in the metric M + hD + h^2 K): 4.0 refuses flex elasticity under implicit and implicitfast.
Damping: our mass damping 0.3 /s as joint damping 0.3 m on each point's slide joints; no
stiffness damping, as ours.

Body: the runner's 17 segments as mocap bodies carrying the figure's contact primitives
(MocapFigure.contact_view: capsules, boxes, spheres), posed from the clip (MocapFigure at
that time) before every MuJoCo step. MuJoCo's colliders are rigid geoms, so the garments
collide with the segments' primitives, not with the skinned surface ours wears. A mocap body
has no velocity in the contact: the cloth sees a body that jumps each step.

Waistbands: the points our garments pin (Garments.pinned, which ride the skin) are joined
to the pelvis mocap body by an equality connect each, at the place in the pelvis frame where
they were cut (MuJoCo refuses flex points on a mocap body itself), solref two steps.

Contact: flex radius 5 mm (our skin contact thickness), friction 0.5 (ours), condim 3,
MuJoCo's default soft contact; the flexes do not collide with each other or themselves (ours
runs without self-contact too: RunnerParams.self_thickness 0).

Measured (bench_runner.py --quick, docs/clothing.md "Speed"): ~5 s a MuJoCo step, nearly all
in the constraint solve (mjTIMER_CONSTRAINT: ~21k contacts, every garment triangle near a
primitive, 28k degrees of freedom), whatever the solver's iteration cap (100 or 10: the same
time); MuJoCo warns each step that the flex stiffness is too ill-conditioned for its
effective-metric preconditioner.
"""
from __future__ import annotations

import time
import warnings

import numpy as np

MASS_DAMPING = 0.3  # 1/s: systems/garments.network's default
RADIUS = 0.005  # m: SkinContactParams.thickness
FRICTION = 0.5  # SkinContactParams.friction


def _material(fabric) -> dict:
    """Young (Pa), poisson, thickness (m) giving sheet stiffness E t = Y and bending
    E t^3 / 12 = B."""
    t = float(np.sqrt(12.0 * fabric.bending / fabric.tensile))
    return {"young": fabric.tensile / t, "poisson": 0.0, "thickness": t}


def build(mujoco, runner, surface, clothes, pinned, x, v, dt: float):
    """(model, data, info): the MjModel of the garments on the runner's primitives, at the
    dressed points x (n,3) m with velocities v (n,3) m/s, step dt (s)."""
    from interplay.geometry.anthropometry import SEGMENTS, segment_primitive
    from interplay.systems.garments import spring_set
    masses = spring_set(clothes)[2]
    cut = clothes.vertices
    G = mujoco.mjtGeom
    spec = mujoco.MjSpec()
    spec.option.timestep = dt
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_DISCRETE
    spec.option.gravity = [0.0, 0.0, -9.81]
    prims = [segment_primitive(sg.shape) for sg in runner.plan]  # its contact view's
    seg = {}
    for k, name in enumerate(SEGMENTS):
        # compiled at the A-pose the garments were cut in
        b = spec.worldbody.add_body(name=name, mocap=True, pos=surface.pos0[k].tolist(),
                                    quat=_quat(surface.rot0[k]))
        p = prims[k]
        common = dict(contype=0, conaffinity=1, friction=[FRICTION, 0.005, 1e-4])
        if p.kind == "capsule":
            b.add_geom(type=G.mjGEOM_CAPSULE, size=[p.radius, 0, 0],
                       fromto=[*p.a, *p.b], **common)
        elif p.kind == "sphere":
            b.add_geom(type=G.mjGEOM_SPHERE, size=[p.radius, 0, 0], pos=list(p.centre),
                       **common)
        elif p.kind == "box":
            b.add_geom(type=G.mjGEOM_BOX, size=list(p.axes), pos=list(p.centre), **common)
        else:
            b.add_geom(type=G.mjGEOM_ELLIPSOID, size=list(p.axes), pos=list(p.centre),
                       **common)
        seg[name] = b
    pin = np.zeros(len(cut), bool)
    pin[pinned] = True
    names = []
    for i, q in enumerate(cut):
        kb = spec.worldbody.add_body(name=f"v{i}", pos=q.tolist())
        kb.explicitinertial = True
        kb.mass = float(masses[i])
        kb.inertia = [1e-10] * 3
        for axis in np.eye(3):
            kb.add_joint(type=mujoco.mjtJoint.mjJNT_SLIDE, axis=axis.tolist())
        names.append(f"v{i}")
        if pin[i]:
            # MuJoCo refuses flex points on a mocap body: the pinned point is connected to
            # the pelvis where it was cut, as stiff as the soft constraint goes stably (a
            # time constant of two steps)
            spec.add_equality(type=mujoco.mjtEq.mjEQ_CONNECT, name1=f"v{i}", name2="pelvis",
                              objtype=mujoco.mjtObj.mjOBJ_BODY, data=[0.0] * 12,
                              solref=[2.0 * dt, 1.0])
    for part in clothes.parts:
        idx = clothes.groups[part.name]
        f = spec.add_flex()
        f.name, f.dim, f.radius = part.name, 2, RADIUS
        f.vertbody = [names[i] for i in idx]
        f.vert = [0.0] * (3 * len(idx))
        f.elem = part.triangles.ravel().tolist()  # the part's own point numbers
        mat = _material(part.fabric)
        f.young, f.poisson, f.thickness = mat["young"], mat["poisson"], mat["thickness"]
        f.elastic2d = 3  # both: membrane and bending
        f.friction = [FRICTION, 0.005, 1e-4]
        f.condim = 3
        f.contype, f.conaffinity = 1, 0  # the body's geoms, not each other nor themselves
        f.selfcollide = mujoco.mjtFlexSelf.mjFLEXSELF_NONE
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = spec.compile()
    # MjSpec refuses joint damping on flex vertex bodies; the model takes it (mass damping)
    model.dof_damping[:] = MASS_DAMPING * np.repeat(masses, 3)
    data = mujoco.MjData(model)
    data.qpos[:] = (x - cut).ravel()
    data.qvel[:] = v.ravel()
    info = {"bodies": np.array([model.body(n).id for n in names]), "masses": masses,
            "materials": {p.name: _material(p.fabric) for p in clothes.parts}}
    return model, data, info


def _quat(R) -> list:
    from scipy.spatial.transform import Rotation
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return [float(w), float(x), float(y), float(z)]


def _pose(runner, data, t: float) -> None:
    runner.set_time(t)
    data.mocap_pos[:] = runner.segment_positions()
    data.mocap_quat[:] = runner.segment_orientations()  # w, x, y, z as MuJoCo's


def points(data, bodies) -> np.ndarray:
    """(n,3) m: the garment points in our order (``bodies``: point i's body id)."""
    return data.xpos[bodies].copy()


def strains(x, clothes) -> dict:
    """Edge strain of the garments' triangle edges against their cut lengths: the largest
    and the 99th percentile (a few springs caught in a pinch strain far in ours too)."""
    t = clothes.triangles
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    l0 = np.linalg.norm(clothes.vertices[e[:, 0]] - clothes.vertices[e[:, 1]], axis=1)
    s = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1) / l0 - 1.0
    return {"max": float(s.max()), "p99": float(np.percentile(s, 99))}


def run(runner, surface, clothes, pinned, x, v, seconds: float, dt: float,
        bound: dict) -> dict:
    """Step the peer ``seconds`` (s) at ``dt`` (s) from the dressed state; returns the wall
    time of the stepping (s), the end points, their edge strains and whether it held
    (finite, no MuJoCo bad-acceleration warning, and its largest and 99th-percentile strain
    within ``bound``'s "max" and "p99": ours at the same time, whose dressed state already
    strains some edges far past their cut length)."""
    import mujoco
    log = []
    mujoco.set_mju_user_warning(log.append)  # keep MUJOCO_LOG.TXT out of the working tree
    t0 = time.perf_counter()
    model, data, info = build(mujoco, runner, surface, clothes, pinned, x, v, dt)
    build_s = time.perf_counter() - t0
    steps = max(1, int(round(seconds / dt)))
    _pose(runner, data, 0.0)
    mujoco.mj_forward(model, data)
    t0 = time.perf_counter()
    ncon = 0
    for k in range(steps):
        _pose(runner, data, (k + 1) * dt)  # the body where it is at the step's end
        mujoco.mj_step(model, data)
        ncon = max(ncon, int(data.ncon))
        if not np.isfinite(data.qpos[:3]).all():
            break
    wall = time.perf_counter() - t0
    end = points(data, info["bodies"])
    finite = bool(np.isfinite(end).all())
    strain = strains(end, clothes) if finite else {"max": float("inf"), "p99": float("inf")}
    bad = int(data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number)
    return {"dt_s": dt, "steps": steps, "seconds": steps * dt, "wall_s": wall,
            "s_per_step": wall / steps, "build_s": build_s,
            "ok": finite and bad == 0 and all(strain[k] <= bound[k] for k in bound),
            "strain": strain,
            "bad_qacc_warnings": bad, "mujoco_warnings": len(log), "contacts_max": ncon, "x": end,
            "nv": int(model.nv), "nflexvert": int(model.nflexvert),
            "materials": info["materials"]}


def pants_drop(x, x0, pants, pelvis_z, pelvis_z0) -> float:
    """How far (m) the pants' points sank relative to the pelvis from x0 to x (mean)."""
    return float((x0[pants, 2] - pelvis_z0).mean() - (x[pants, 2] - pelvis_z).mean())


def peer_row(runner, surface, clothes, pinned, x0, v0, ours_end, seconds: float,
             steps=(1 / 60, 1 / 120, 1 / 240)) -> dict:
    """The benchmark's ``peer.mujoco_flex`` row: ``seconds`` (s) of the clip at each step
    in ``steps``, largest first, stopping at the first that holds (``run``: no more
    stretched than ours at the same time); frames (1/30 s)
    per wall second at that step; the mean and largest distance (m) of its garment points
    from ours (``ours_end``, ours at the same time), and how far each pair of pants sank
    against the pelvis."""
    tries, bound = [], strains(ours_end, clothes)
    for dt in steps:
        r = run(runner, surface, clothes, pinned, x0, v0, seconds, dt, bound)
        tries.append(r)
        if r["ok"]:
            break
    best = next((r for r in tries if r["ok"]), tries[-1])
    x = best.pop("x")
    for r in tries:
        r.pop("x", None)
    runner.set_time(0.0)
    z0 = float(runner.segment_positions()[0, 2])
    runner.set_time(best["seconds"])
    z1 = float(runner.segment_positions()[0, 2])
    pants = clothes.groups["pants"]
    d = np.linalg.norm(x - ours_end, axis=1) if np.isfinite(x).all() else np.full(1, np.inf)
    return {"held": best["ok"], "dt_s": best["dt_s"], "seconds": best["seconds"],
            "frames_per_wall_s": best["seconds"] * 30.0 / best["wall_s"],
            "vertices": best["nflexvert"], "dofs": best["nv"],
            "strain_ours_start": strains(x0, clothes),
            "strain_ours_end": strains(ours_end, clothes),
            "distance_from_ours_m": {"mean": float(d.mean()), "max": float(d.max())},
            "pants_sank_m": {"mujoco": pants_drop(x, x0, pants, z1, z0),
                             "ours": pants_drop(ours_end, x0, pants, z1, z0)},
            "tries": tries}
