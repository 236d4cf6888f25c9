"""The MuJoCo model of a human figure, built in code with ``mujoco.MjSpec`` from the body plan
(geometry/anthropometry.py): 17 bodies, a free root joint, 30 hinges with anatomical limits,
one position-velocity servo per hinge (its reference an integrator state), and the static
environment (ground plane, platforms) the figure stands on; also the figure's air drag and its
segments' extents. No MJCF file exists to drift from the plan.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..params import param
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
    none; opens (s): the time the platform drops away from under the figure (a gallows' plank
    or trapdoor: its free end falls faster than she can, so the support is simply gone), None
    for never; friction: Coulomb coefficient of the feet on them (-); air_density (kg/m^3): 0
    for none, else quadratic drag on each segment's equivalent inertia box (``AirDrag``; air
    1.2)."""
    floor: float | None = param(0.0, "m", ge=-1e4, le=1e4, doc="ground height, none: no ground")
    platform: tuple = param((), "m", ge=-1e4, le=1e4, length=(0, 5),
                            doc="x_min, x_max, y_min, y_max, top of a deck, or empty")
    opens: float | None = param(None, "s", ge=0.0, le=1e5, doc="the platform drops away then")
    friction: float = param(1.0, "-", ge=0.0, le=10.0)
    air_density: float = param(0.0, "kg/m^3", ge=0.0, le=100.0)


def joint_group(name: str) -> str:
    """The anatomical joint a hinge belongs to ("l_hip_flex" -> "hip")."""
    parts = name.split("_")
    return parts[1] if parts[0] in ("l", "r") else parts[0]


def build_model(plan: list[Segment], env: EnvironmentParams, dt: float, root=(0.0, 0.0, 0.0),
                yaw: float = 0.0, fixed_base: bool = False, gravity: bool = True, mass=None,
                extend=None):
    """Compile the figure; root: where the pelvis's rest position is carried to (m), yaw (rad)
    about +z; fixed_base: weld the pelvis to the world (servo tests); extend: None, or
    ``extend(spec, bodies)`` adding bodies and constraints of its own after the figure's
    (a swing she sits on: systems/swing.py), bodies the figure's by segment name."""
    import mujoco
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    spec.option.timestep = dt
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = [0.0, 0.0, -9.81 if gravity else 0.0]
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
            # tau = 1 * act + b1 theta + b2 thetadot with act = g_s theta_d + g_d thetadot_d +
            # tau_g (the servo reference), b1 = -g_s, b2 = -g_d: exactly the PD law plus the
            # gravity feed-forward; MuJoCo's implicitfast integrates the -g_d thetadot term
            # implicitly, which keeps stiff stance gains stable. act is an integrator state
            # (d act/dt = ctrl): the controller sets act at its ticks and ctrl to the
            # reference's rate, so MuJoCo moves the reference at every step without Python.
            act.dyntype = mujoco.mjtDyn.mjDYN_INTEGRATOR
            act.actlimited = mujoco.mjtLimited.mjLIMITED_FALSE
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
    if extend is not None:
        extend(spec, bodies)
    return spec.compile()


def geom_extents(model, geom_ids):
    """Per geom: half extents (g,3) m along its own axes that reach its surface without the
    rounding, and the rounding radius (g,) m: a box's half sizes and 0, a capsule's half
    length on z and its radius, a sphere's nothing and its radius. The geom's lowest point is
    then z_centre - |R_z| . extents - radius (R_z the z row of its rotation), exactly."""
    import mujoco
    ext, rad = np.zeros((len(geom_ids), 3)), np.zeros(len(geom_ids))
    for k, g in enumerate(geom_ids):
        size, t = model.geom_size[g], model.geom_type[g]
        if t == mujoco.mjtGeom.mjGEOM_BOX:
            ext[k] = size
        elif t == mujoco.mjtGeom.mjGEOM_CAPSULE:
            ext[k, 2], rad[k] = size[1], size[0]
        else:
            rad[k] = size[0]
    return ext, rad


class AirDrag:
    """Quadratic air drag on a figure's segments: F_b = -1/2 rho A_b(v) |v_b| v_b at each
    segment's centre of mass, A_b the area its equivalent inertia box (the box of its mass and
    principal inertia, as in MuJoCo's inertia fluid model) shows to the flow, drag coefficient
    1. Stateless and cheap: the figure evaluates it every few control ticks and holds it as a
    generalized force (qfrc_applied) in between, since drag changes over tenths of a second.
    (MuJoCo's own fluid model would add its force derivatives to every implicit step, doubling
    the figure's cost for a force this small.)"""

    def __init__(self, model, bodies, density: float):
        self.bodies = np.asarray(bodies, dtype=np.int64)
        self.density = float(density)
        m = model.body_mass[self.bodies]
        I = model.body_inertia[self.bodies]
        # full box sides from I_x = m (b^2 + c^2) / 12 and its permutations
        sides = np.sqrt(np.maximum(6.0 * (I.sum(axis=1)[:, None] - 2.0 * I) / m[:, None], 0.0))
        self.faces = np.stack([sides[:, 1] * sides[:, 2], sides[:, 0] * sides[:, 2],
                               sides[:, 0] * sides[:, 1]], axis=1)  # m^2, normal to x, y, z
        if len(set(model.body_rootid[self.bodies])) != 1:
            raise ParameterError("air drag needs the figure's segments in one kinematic tree")
        self.root = int(model.body_rootid[self.bodies[0]])
        # dof j moves body b when j's body is b or one of its ancestors
        self.moves = np.zeros((model.nv, len(self.bodies)))
        for k, b in enumerate(self.bodies):
            a = int(b)
            while a > 0:
                self.moves[model.body_dofadr[a]:model.body_dofadr[a] + model.body_dofnum[a],
                           k] = 1.0
                a = int(model.body_parentid[a])
        self.force = np.zeros((len(self.bodies), 3))

    def apply(self, data, qfrc):
        """Write the drag's generalized force (N, N m) for the current velocities into qfrc:
        Q_j = cdof_j . (r_b x F_b, F_b) summed over the bodies dof j moves, in MuJoCo's
        com-based frame (about the tree's centre of mass c, world axes; r_b = x_b - c)."""
        b = self.bodies
        cv = data.cvel[b]
        r = data.xipos[b] - data.subtree_com[self.root]
        v = cv[:, 3:] + _cross(cv[:, :3], r)
        local = np.abs(np.matmul(v[:, None, :], data.ximat[b].reshape(-1, 3, 3))[:, 0])
        area_speed = (local * self.faces).sum(axis=1)  # A |v|, per body along its box axes
        f = self.force
        np.multiply(v, (-0.5 * self.density) * area_speed[:, None], out=f)
        spatial = np.concatenate([_cross(r, f), f], axis=1)  # (torque about c, force)
        np.sum((data.cdof @ spatial.T) * self.moves, axis=1, out=qfrc)


def _cross(a, b):
    """Row-wise cross products of (n,3) arrays (np.cross costs more for a few rows)."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)
