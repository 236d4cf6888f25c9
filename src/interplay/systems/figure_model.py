"""The MuJoCo model of a human figure, built in code with ``mujoco.MjSpec`` from the body plan
(geometry/anthropometry.py): 17 bodies, a free root joint, 30 hinges with anatomical limits,
one position-velocity servo per hinge, and the static environment (ground plane, platforms)
the figure stands on. No MJCF file exists to drift from the plan.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..geometry.anthropometry import Segment

# Peak joint torques (N m) of a 75 kg adult, scaled with body mass; sagittal leg values are of
# the order of measured isometric maxima (hip and knee extension ~ 250-350 N m).
TORQUE_LIMITS = {"neck": 60.0, "waist": 300.0, "shoulder": 150.0, "elbow": 100.0,
                 "wrist": 30.0, "hip": 350.0, "knee": 350.0, "ankle": 250.0, "toe": 60.0}
REFERENCE_MASS = 75.0  # kg, the body mass TORQUE_LIMITS are for
ARMATURE = 2e-3  # kg m^2 per hinge: keeps the lightest segments (toes, hands) well conditioned
FIGURE_GROUP, WORLD_GROUP = 2, 1  # contype/conaffinity bits: figure-world only, no self contact


@dataclass(frozen=True)
class EnvironmentParams:
    """What the figure stands on. floor: height (m) of a ground plane, None for none; platform:
    (x_min, x_max, y_min, y_max, top) m of a static deck whose top face is at z = top, () for
    none; friction: Coulomb coefficient of the feet on them (-); air_density (kg/m^3): 0 for
    none, else MuJoCo's quadratic drag on each segment's equivalent inertia box (air: 1.2)."""
    floor: float | None = 0.0  # m
    platform: tuple = ()  # m
    friction: float = 1.0
    air_density: float = 0.0  # kg/m^3


def joint_group(name: str) -> str:
    """The anatomical joint a hinge belongs to ("l_hip_flex" -> "hip")."""
    parts = name.split("_")
    return parts[1] if parts[0] in ("l", "r") else parts[0]


def build_model(plan: list[Segment], env: EnvironmentParams, dt: float, root=(0.0, 0.0, 0.0),
                yaw: float = 0.0, fixed_base: bool = False, gravity: bool = True, mass=None):
    """Compile the figure; root: where the pelvis's rest position is carried to (m), yaw (rad)
    about +z; fixed_base: weld the pelvis to the world (servo tests)."""
    import mujoco
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    spec.option.timestep = dt
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = [0.0, 0.0, -9.81 if gravity else 0.0]
    spec.option.density = float(env.air_density)
    world = spec.worldbody
    wkw = dict(contype=WORLD_GROUP, conaffinity=FIGURE_GROUP, friction=[env.friction, 0.005, 1e-4])
    if env.floor is not None:
        world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0],
                       pos=[0.0, 0.0, float(env.floor)], **wkw)
    if env.platform:
        if len(env.platform) != 5:
            raise ParameterError(f"platform must be (x_min, x_max, y_min, y_max, top) in m, got "
                                 f"{env.platform!r}")
        x0, x1, y0, y1, top = (float(v) for v in env.platform)
        if not (x1 > x0 and y1 > y0):
            raise ParameterError(f"platform {env.platform!r}: needs x_max > x_min and "
                                 "y_max > y_min")
        world.add_geom(name="platform", type=mujoco.mjtGeom.mjGEOM_BOX,
                       size=[(x1 - x0) / 2, (y1 - y0) / 2, 0.25],
                       pos=[(x0 + x1) / 2, (y0 + y1) / 2, top - 0.25], **wkw)
    c, s = np.cos(yaw / 2), np.sin(yaw / 2)
    bodies = {}
    scale = (mass if mass is not None else sum(g.mass for g in plan)) / REFERENCE_MASS
    gkw = dict(contype=FIGURE_GROUP, conaffinity=WORLD_GROUP,
               friction=[env.friction, 0.005, 1e-4])
    for seg in plan:
        if seg.parent is None:
            pos = np.asarray(root, float) + seg.offset
            body = world.add_body(name=seg.name, pos=pos, quat=[c, 0.0, 0.0, s])
            if not fixed_base:
                body.add_freejoint(name="root")
        else:
            body = bodies[seg.parent].add_body(name=seg.name, pos=seg.offset)
        bodies[seg.name] = body
        for jname, axis, (lo, hi) in seg.joints:
            body.add_joint(name=jname, type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis,
                           range=[lo, hi], limited=mujoco.mjtLimited.mjLIMITED_TRUE,
                           armature=ARMATURE)
            lim = TORQUE_LIMITS[joint_group(jname)] * scale
            act = spec.add_actuator(name=jname, target=jname,
                                    trntype=mujoco.mjtTrn.mjTRN_JOINT)
            # tau = 1 * ctrl + b1 theta + b2 thetadot with ctrl = g_s theta_d + g_d thetadot_d,
            # b1 = -g_s, b2 = -g_d: exactly the PD law; MuJoCo's implicitfast integrates the
            # -g_d thetadot term implicitly, which keeps stiff stance gains stable.
            act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            act.gainprm[0] = 1.0
            act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.forcerange = [-lim, lim]
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        kind = seg.shape[0]
        if kind == "capsule":
            body.add_geom(name=seg.name, type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                          size=[seg.shape[1], 0.0, 0.0],
                          fromto=np.concatenate([seg.shape[2], seg.shape[3]]), mass=seg.mass,
                          **gkw)
        elif kind == "box":
            body.add_geom(name=seg.name, type=mujoco.mjtGeom.mjGEOM_BOX, size=seg.shape[1],
                          pos=seg.shape[2], mass=seg.mass, **gkw)
        else:
            body.add_geom(name=seg.name, type=mujoco.mjtGeom.mjGEOM_SPHERE,
                          size=[seg.shape[1], 0.0, 0.0], pos=seg.shape[2], mass=seg.mass, **gkw)
    return spec.compile()


def geom_probe_points(model, geom_ids):
    """Local points (p,3) m, their geom index and radius (m), whose swept spheres bound each
    geom exactly along any direction: box corners (radius 0), capsule end centres, sphere
    centre. Used for the figure's lowest point."""
    import mujoco
    pts, gid, rad = [], [], []
    for g in geom_ids:
        size = model.geom_size[g]
        t = model.geom_type[g]
        if t == mujoco.mjtGeom.mjGEOM_BOX:
            local = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)],
                             float) * size
            r = 0.0
        elif t == mujoco.mjtGeom.mjGEOM_CAPSULE:
            local = np.array([[0.0, 0.0, -size[1]], [0.0, 0.0, size[1]]])
            r = size[0]
        else:
            local = np.zeros((1, 3))
            r = size[0]
        pts.append(local)
        gid += [g] * len(local)
        rad += [r] * len(local)
    return np.concatenate(pts), np.array(gid), np.array(rad)
