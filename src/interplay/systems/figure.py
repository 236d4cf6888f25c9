"""Active human figures on MuJoCo (SPEC 2.3): 17 segments, 30 PD-servoed hinges, a state-
machine controller, MuJoCo's own ground contact, and forces from other systems through
``xfrc_applied``.

Rates: MuJoCo steps at ``dt`` and evaluates the servo law at every step (the servos are MuJoCo
actuators with exactly the PD law of control/pd.py plus the gravity feed-forward of
control/gravity.py); the controller (state machine and balance) plans targets, gains and the
feed-forward every ``control_dt``, and the servo reference between its ticks is interpolated
at every MuJoCo step, so targets move smoothly. Both rates are independent of the coupling
step, which the figure substeps inside one Python loop over ``mj_step``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..control.fsm import Controller, StateMachine
from ..control.gravity import GravityCompensation
from ..control.pd import axis_inertias, pd_gains
from ..errors import ParameterError, require_positive
from ..params import param
from ..geometry.anthropometry import (SEGMENTS, BodyParams, body_plan, joint_names,
                                      segment_mesh, segment_primitive)
from .base import System, substeps
from .figure_model import (FIGURE_GROUP, WORLD_GROUP, AirDrag, EnvironmentParams, build_model,
                           geom_extents, joint_group)
from .shape import figure_shape
from .views import BodiesView, RigidParts

LEG_GROUPS = ("hip", "knee", "ankle", "toe")
FEET = ("l_foot", "l_toes", "r_foot", "r_toes")
HANDS = ("l_hand", "r_hand")
BALANCE_RATE = 0.5  # rad/s, fastest change of the balance offset
BALANCE_MAX = 0.25  # rad, largest balance offset
DRAG_TICKS = 4  # control ticks the air drag is held for (20 ms: drag changes over seconds)
# MjData arrays a snapshot keeps: the state, the servo reference and its rate, the held drag
STATE_ARRAYS = ("qpos", "qvel", "act", "ctrl", "qfrc_applied", "qacc_warmstart")


@dataclass(frozen=True)
class FigureParams:
    """body: mass and height; environment: ground and platforms; position (m): the ground point
    below the pelvis at rest; yaw (rad): heading about +z (0 faces +x); dt (s): MuJoCo's step;
    control_dt (s): the controller's period; omega (rad/s) and zeta (-): default servo natural
    frequency and damping ratio; support_omega (rad/s): the stance legs' frequency while they
    carry the body (about the whole body's inertia, so soft, with tau_g holding the weight);
    gravity_compensation: add the feed-forward torques that hold the desired pose against
    gravity (control/gravity.py) to the servo law."""
    body: BodyParams = BodyParams()
    environment: EnvironmentParams = EnvironmentParams()
    position: tuple = param((0.0, 0.0, 0.0), "m", ge=-1e4, le=1e4)
    yaw: float = param(0.0, "rad", ge=-100.0, le=100.0)
    dt: float = param(1e-3, "s", ge=1e-7, le=0.01)
    control_dt: float = param(5e-3, "s", ge=1e-5, le=0.1)
    omega: float = param(20.0, "rad/s", gt=0.0, le=1e3)
    zeta: float = param(1.0, "-", gt=0.0, le=10.0)
    support_omega: float = param(8.0, "rad/s", gt=0.0, le=1e3)
    gravity_compensation: bool = True


class Figure(System, RigidParts):
    """An articulated human figure. Generalized state: (qpos, d qpos/dt) — for the free root
    the quaternion's time derivative, not MuJoCo's body-frame angular velocity, so tracks can
    Hermite-interpolate a consistent pair. Segment order is anthropometry.SEGMENTS; its contact
    view has one part per segment.

    The servo gains in MuJoCo's model (actuator bias parameters) and its time step are derived
    from the controller state (omega, zeta, the support flag: all in ``capture()``) and the
    substep, rewritten from them on restore and at every advance: the model holds no state of
    its own.

    feedback: None, or an object with ``offsets(figure, sensors) -> (joints,)`` rad added to
    the targets at every control tick (a scene's own balance law: control/bounce.py) and
    ``capture()`` / ``restore(snap)`` of its memory as plain arrays.

    extend: None, or ``extend(spec, bodies)`` adding a scene's own bodies to her MuJoCo model
    (figure_model.build_model; the swing she sits on, systems/swing.py); her mass is her
    segments' alone."""

    integrator = "MuJoCo implicitfast, PD servo actuators"

    def __init__(self, name: str, params: FigureParams = FigureParams(),
                 controller: Controller | None = None, fixed_base: bool = False,
                 gravity: bool = True, feedback=None, extend=None):
        super().__init__(name, params.dt)
        import mujoco
        self._mj = mujoco
        self.params = params
        self.control_dt = require_positive(name, "control_dt", params.control_dt, "s")
        self.plan = body_plan(params.body)
        pos = np.asarray(params.position, dtype=float)
        if pos.shape != (3,) or not np.all(np.isfinite(pos)):
            raise ParameterError(f"{name}: position must be 3 finite numbers (m), got "
                                 f"{params.position!r}")
        self.model = build_model(self.plan, params.environment, params.dt,
                                 root=pos + [0.0, 0.0, 5e-4], yaw=params.yaw,
                                 fixed_base=fixed_base, gravity=gravity,
                                 mass=params.body.mass, extend=extend)
        m = self.model
        self.data = mujoco.MjData(m)
        self.free = not fixed_base
        self.joints = joint_names(self.plan)
        self.seg_body = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, s)
                                  for s in SEGMENTS])
        self.seg_geom = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, s)
                                  for s in SEGMENTS])
        self.foot_geoms = self.seg_geom[[SEGMENTS.index(s) for s in FEET]]
        self.hand_geoms = self.seg_geom[[SEGMENTS.index(s) for s in HANDS]]
        self.sole_geoms = self.seg_geom[[SEGMENTS.index(s) for s in ("l_foot", "r_foot")]]
        jid = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in self.joints])
        self.qadr = m.jnt_qposadr[jid]
        self.vadr = m.jnt_dofadr[jid]
        self.root = self.seg_body[0]
        self.leg = np.array([joint_group(j) in LEG_GROUPS for j in self.joints])
        self.ankles = np.array([i for i, j in enumerate(self.joints) if joint_group(j) == "ankle"])
        mujoco.mj_forward(m, self.data)
        # inertia each hinge moves (rest pose): its subtree, or the rest of the body when the
        # subtree is planted (stance legs); the hinge's armature adds to both
        sub = np.zeros((len(jid), m.nbody), dtype=bool)
        for k, j in enumerate(jid):
            b0 = m.jnt_bodyid[j]
            for b in range(1, m.nbody):
                a = b
                while a > 0 and a != b0:
                    a = m.body_parentid[a]
                sub[k, b] = a == b0
        world = np.zeros((len(jid), m.nbody), dtype=bool)
        world[:, 1:] = True
        self.inertia_distal = axis_inertias(m, self.data, jid, sub) + m.dof_armature[self.vadr]
        self.inertia_support = (axis_inertias(m, self.data, jid, world & ~sub)
                                + m.dof_armature[self.vadr])
        self._mass = float(m.body_mass[self.seg_body].sum())  # hers, not what ``extend`` added
        self.targets = np.zeros(len(jid))
        self.vtargets = np.zeros(len(jid))
        self.omega = np.full(len(jid), require_positive(name, "omega", params.omega, "rad/s"))
        self.zeta = np.full(len(jid), require_positive(name, "zeta", params.zeta))
        self.support = False
        self.fsm = StateMachine(controller, self.joints) if controller is not None else None
        self._next_control = 0.0
        self.balance_offset = 0.0
        self._blend = None
        feet = [SEGMENTS.index(f) for f in ("l_foot", "r_foot")]
        # geom id -> which foot (0 left, 1 right) its sole or toes belong to, -1 for none;
        # geom id -> is a hand: contact tests by table lookup, no set operations per tick
        self._geom_foot = np.full(m.ngeom, -1, dtype=np.int64)
        self._geom_foot[self.foot_geoms] = (0, 0, 1, 1)  # FEET: left foot, toes, right ...
        self._geom_hand = np.zeros(m.ngeom, dtype=bool)
        self._geom_hand[self.hand_geoms] = True
        self._geom_sole = np.full(m.ngeom, -1, dtype=np.int64)
        self._geom_sole[self.sole_geoms] = (0, 1)
        # segments another system's contact touched this step (``mark_touching``): a foot on
        # a bed is sensed like a foot on MuJoCo's ground
        self.touched = np.zeros(len(SEGMENTS), dtype=bool)
        self._feet_seg = np.array([SEGMENTS.index(s) for s in FEET])
        self._hand_seg = np.array([SEGMENTS.index(s) for s in HANDS])
        self.feedback = feedback
        self.offsets = np.zeros(len(jid))
        self.gravity = GravityCompensation(m, self.qadr, self.vadr, self.seg_body[feet],
                                           self.seg_geom[feet], self.free)
        self.drag = (AirDrag(m, self.seg_body, params.environment.air_density)
                     if params.environment.air_density > 0 else None)
        self._c0, self._dc, self._ff = np.zeros(len(jid)), np.zeros(len(jid)), np.zeros(len(jid))
        self._tick = 0.0
        if self.fsm is not None:
            self._enter(self.fsm.start)
        self.apply_gains()
        self._ff[:] = self._feedforward(self.targets)
        self._plan(0.0)
        nq = m.nq
        self._gx, self._gv = np.zeros(nq), np.zeros(nq)
        self._qdot, self._w = np.zeros(4), np.zeros(4)
        self._extent, self._round = geom_extents(m, self.seg_geom)
        self._twist = np.zeros(6)
        self.color = None
        self._platform = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "platform")
        # the contact view's parts: her segments (a subclass may add bodies of its model
        # that contacts should see, e.g. a swing's seat: ``add_part``)
        self.part_body = self.seg_body.copy()
        self._view = BodiesView(self, SEGMENTS, self.segment_meshes(),
                                [segment_primitive(s.shape) for s in self.plan],
                                m.body_mass[self.seg_body], movable=True)

    def add_part(self, name: str, body: int, mesh, primitive) -> None:
        """Show another body of her MuJoCo model to contacts as a part after her segments:
        ``mesh`` (vertices (n,3) m, triangles) and ``primitive`` in the body's frame."""
        v = self._view
        self.part_body = np.r_[self.part_body, int(body)]
        self._view = BodiesView(self, v.names + [name], v.meshes + [mesh],
                                list(v.primitives) + [primitive],
                                self.model.body_mass[self.part_body], movable=True)

    # --- servos and control ------------------------------------------------------------------
    def apply_gains(self):
        """Set the actuators to the PD law for the current omega, zeta and support flag."""
        inertia = np.where(self.support & self.leg, self.inertia_support, self.inertia_distal)
        self.kp, self.kd = pd_gains(inertia, self.omega, self.zeta)
        self.model.actuator_biasprm[:, 1] = -self.kp
        self.model.actuator_biasprm[:, 2] = -self.kd

    def _reference(self, t, balance=True):
        """Desired angles (rad) and rates (rad/s) at time t (s): the state's targets, reached
        along a smoothstep 3u^2 - 2u^3 from where the previous state left them, plus the
        balance offset on the ankles and the feedback's offsets."""
        target, vtarget = self.targets.copy(), self.vtargets.copy()
        if self._blend is not None:
            start, end, t0, T = self._blend
            u = min(max((t - t0) / T, 0.0), 1.0)
            target = start + (end - start) * (3 * u * u - 2 * u ** 3)
            vtarget += (end - start) * (6 * u - 6 * u * u) / T
        if balance and self.balance_offset:
            target[self.ankles] += self.balance_offset
        if balance and self.feedback is not None:
            target += self.offsets
        return target, vtarget

    def reference(self) -> np.ndarray:
        """The state's desired joint angles (rad) now, before the balance and the feedback's
        offsets: what an offset is added to."""
        return self._reference(self.time, balance=False)[0]

    def _feedforward(self, target) -> np.ndarray:
        """Gravity compensation (N m) for the desired angles (control/gravity.py): the weight
        on the feet while the state says they carry the body and one touches the ground."""
        if not self.params.gravity_compensation or (self.free and not self.support):
            return np.zeros(len(target))
        feet = self.feet_touching() if self.free else np.zeros(0, np.int64)
        return self.gravity.torques(self.data.qpos, target, feet)

    def feet_touching(self) -> np.ndarray:
        """Indices (0 left, 1 right) of the feet touching anything: MuJoCo's ground under a
        foot or its toes, or another system's contact on them this step."""
        owner = self._geom_foot[self.data.contact.geom[:self.data.ncon]]
        touch = np.bincount(owner[owner >= 0], minlength=2) > 0
        ext = self.touched[self._feet_seg]
        touch |= ext[[0, 2]] | ext[[1, 3]]  # FEET: left foot, left toes, right ...
        return np.flatnonzero(touch)

    def _plan(self, t):
        """The servo reference over the control period from t (s): kp theta_d + kd thetadot_d
        + tau_g at both ends; the actuators' integrator state starts at the first and its
        rate (ctrl) carries it to the second, so every MuJoCo step in between sees the
        reference interpolated linearly and targets never jump by a whole period's change."""
        th0, w0 = self._reference(t)
        th1, w1 = self._reference(t + self.control_dt)
        ff1 = self._feedforward(th1)
        self._c0[:] = self.kp * th0 + self.kd * w0 + self._ff
        self._dc[:] = self.kp * th1 + self.kd * w1 + ff1 - self._c0
        self._ff[:] = ff1
        self._tick = t
        self.data.act[:] = self._c0
        self.data.ctrl[:] = self._dc / self.control_dt

    def angles(self) -> np.ndarray:
        """Current joint angles (rad), in ``joints`` order."""
        return self.data.qpos[self.qadr].copy()

    def set_targets(self, targets=None, velocities=None):
        """Set desired joint angles (rad) and velocities (rad/s) directly (no controller)."""
        if targets is not None:
            self.targets[:] = targets
        if velocities is not None:
            self.vtargets[:] = velocities
        self._blend = None
        self._ff[:] = self._feedforward(self.targets)
        self._plan(self.time)

    def _enter(self, index, t=0.0):
        start = self._reference(t, balance=False)[0]
        self.fsm.enter(index, t, self.targets, self.vtargets, self.angles(), self.omega,
                       self.zeta, self.params.omega, self.params.zeta)
        self.support = self.fsm.state.support
        if self.support:  # stance legs: soft gains, tau_g carries the weight
            soft = self.leg.copy()
            soft[self.fsm.state.gain_idx] = False
            self.omega[soft] = self.params.support_omega
        T = self.fsm.state.blend
        self._blend = (start, self.targets.copy(), t, T) if T > 0 and t > 0 else None
        self.apply_gains()

    def sensors(self) -> dict:
        """What transitions read: foot/hand contact, centre of mass (m), its velocity (m/s),
        how far (m) it is ahead of the middle of the feet along the facing direction, and the
        trunk's pitch (rad): how far its up axis has turned forward from vertical about the
        starting left-right axis (-pi..pi; pi is head down), and its rate (rad/s)."""
        d, m = self.data, self.model
        geoms = d.contact.geom[:d.ncon]
        self._mj.mj_subtreeVel(m, d)
        com = d.subtree_com[self.root].copy()
        hands = self.touched[self._hand_seg].any()
        return {"foot_contact": len(self.feet_touching()) > 0,
                "hand_contact": bool(self._geom_hand[geoms].any() or hands),
                "com": com, "com_vel": d.subtree_linvel[self.root].copy(),
                "com_ahead": float(np.dot(com - d.geom_xpos[self.sole_geoms].mean(axis=0),
                                          self._forward())),
                "pitch": self.pitch(), "pitch_rate": self.pitch_rate()}

    def pitch_rate(self) -> float:
        """The trunk's forward pitch rate (rad/s): its angular velocity about the starting
        left-right axis."""
        w = self.part_velocities([SEGMENTS.index("torso")])[1][0]
        yaw = self.params.yaw
        return float(-w[0] * math.sin(yaw) + w[1] * math.cos(yaw))

    def pitch(self) -> float:
        """The trunk's forward pitch (rad, -pi..pi): the angle of its up axis from vertical,
        positive towards the heading the figure started with (its yaw)."""
        up = self.data.xmat[self.seg_body[SEGMENTS.index("torso")]].reshape(3, 3)[:, 2]
        yaw = self.params.yaw
        return math.atan2(up[0] * math.cos(yaw) + up[1] * math.sin(yaw), up[2])

    def _forward(self) -> np.ndarray:
        """The pelvis's facing direction in the horizontal plane (unit)."""
        fwd = self.data.xmat[self.root].reshape(3, 3)[:, 0].copy()
        fwd[2] = 0.0
        return fwd / max(np.linalg.norm(fwd), 1e-9)

    def heading_axes(self) -> tuple[np.ndarray, np.ndarray]:
        """(forward, left): the pelvis's facing and its left in the horizontal plane (unit),
        the axes balance feedback works along."""
        fwd = self._forward()
        return fwd, np.array([-fwd[1], fwd[0], 0.0])

    def _control(self, t):
        if self.fsm is not None:
            s = self.sensors()
            nxt = self.fsm.fired(t, s)
            if nxt is not None:
                self._enter(nxt, t)
            self.balance_offset = self._balance(s) if self.fsm.state.balance else 0.0
            if self.feedback is not None:
                self.offsets[:] = self.feedback.offsets(self, s)
        if self._blend is not None and t >= self._blend[2] + self._blend[3]:
            self._blend = None
        self._plan(t)
        if self.drag is not None and round(t / self.control_dt) % DRAG_TICKS == 0:
            self.drag.apply(self.data, self.data.qfrc_applied)
        self._next_control += self.control_dt

    def _balance(self, s) -> float:
        """Ankle-strategy feedback (rad): plantarflex when the centre of mass is ahead of the
        centre of the feet on the ground (the middle of the support polygon: the foot boxes'
        centres, heel to toe joint) or moving forward, dorsiflex when behind. The offset slews
        at most BALANCE_RATE so a large error leans the body over gradually instead of kicking
        it off its feet; it is capped at BALANCE_MAX."""
        d = self.data
        geoms = d.contact.geom[:d.ncon]
        owner = self._geom_sole[geoms]
        sole = np.bincount(owner[owner >= 0], minlength=2) > 0
        sole |= self.touched[self._feet_seg[[0, 2]]]
        touching = self.sole_geoms[np.flatnonzero(sole)]
        if len(touching) == 0:
            return self.balance_offset
        centre = d.geom_xpos[touching].mean(axis=0)
        fwd = self._forward()
        kp, kd = self.fsm.state.balance
        e = float(np.dot(s["com"] - centre, fwd))
        v = float(np.dot(s["com_vel"], fwd))
        want = float(np.clip(-(kp * e + kd * v), -BALANCE_MAX, BALANCE_MAX))
        step = BALANCE_RATE * self.control_dt
        return float(np.clip(want, self.balance_offset - step, self.balance_offset + step))

    # --- dynamics ----------------------------------------------------------------------------
    def clear_forces(self):
        self.data.xfrc_applied[:] = 0.0
        self.touched[:] = False

    def mark_touching(self, parts):
        """Segments another system's contact touches this step (cleared with the forces);
        parts added by ``add_part`` are not hers to sense."""
        parts = np.asarray(parts, dtype=np.int64)
        self.touched[parts[parts < len(self.touched)]] = True

    def add_wrench(self, force, torque=None, point=None, body=0):
        """Add a force (N) at a world point (m; default the segment's centre of mass) and a
        torque (N m) to a segment, named or by index in SEGMENTS (default the pelvis), or to a
        part added by ``add_part`` by its index in the contact view."""
        b = self.part_body[SEGMENTS.index(body) if isinstance(body, str) else int(body)]
        f = np.asarray(force, dtype=float)
        w = self.data.xfrc_applied[b]
        w[:3] += f
        if point is not None:
            w[3:] += np.cross(np.asarray(point, dtype=float) - self.data.xipos[b], f)
        if torque is not None:
            w[3:] += torque

    def _run(self, n: int, sub: float):
        m, d, mj = self.model, self.data, self._mj
        if m.opt.timestep != sub:
            m.opt.timestep = sub
        opens = self.params.environment.opens
        done = 0
        while done < n:
            t = self.time + done * sub
            if t >= self._next_control - 1e-9 * sub:
                self._control(t)
            k = min(n - done, max(1, math.ceil((self._next_control - t) / sub - 1e-9)))
            if opens is not None and self._platform >= 0:
                # the platform is there until it opens, gone from the first substep at or
                # after; the model keeps no state of its own: this follows from the time
                gone = t >= opens - 1e-9 * sub
                m.geom_contype[self._platform] = 0 if gone else WORLD_GROUP
                m.geom_conaffinity[self._platform] = 0 if gone else FIGURE_GROUP
                if not gone:
                    k = min(k, max(1, math.ceil((opens - t) / sub - 1e-9)))
            mj.mj_step(m, d, nstep=k)
            done += k

    def _sync(self):
        """Positions, frames and velocities of the segments for the state mj_step ended in
        (mj_step leaves them from the start of its step): what interactions read."""
        m, d, mj = self.model, self.data, self._mj
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        mj.mj_comVel(m, d)

    def step(self, h):
        self._run(1, h)
        self._sync()

    def advance(self, h, dt=None):
        n = substeps(h, self.dt if dt is None else dt)
        self._run(n, h / n)
        self._sync()
        self.time += h

    # --- measures ----------------------------------------------------------------------------
    @property
    def mass(self) -> float:
        return self._mass

    def com(self) -> np.ndarray:
        """Centre of mass (m)."""
        return self.data.subtree_com[self.root].copy()

    def kinetic_energy(self):
        res = np.zeros(self.model.nv)
        self._mj.mj_mulM(self.model, self.data, res, self.data.qvel)
        return 0.5 * float(np.dot(self.data.qvel, res))

    def momentum(self):
        m, d = self.model, self.data
        self._mj.mj_subtreeVel(m, d)
        return self._mass * self.data.subtree_linvel[self.root].copy()

    def lowest_z(self) -> float:
        """Height (m) of the figure's lowest surface point."""
        d, g = self.data, self.seg_geom
        # xmat is row-major: entries 6..8 are the z row of each geom's rotation
        z = (d.geom_xpos[g, 2] - (np.abs(d.geom_xmat[g, 6:9]) * self._extent).sum(axis=1)
             - self._round)
        return float(z.min())

    def segment_wrenches(self) -> np.ndarray:
        """(17,6) external force (N) and torque about the segment's centre of mass (N m) other
        systems applied to each segment in the last coupling step."""
        return self.data.xfrc_applied[self.seg_body].copy()

    def health(self):
        d = self.data
        if not (math.isfinite(d.qpos.sum()) and math.isfinite(d.qvel.sum())):
            return [f"{self.name}: state became non-finite at t={self.time:.4f} s"]
        return []

    # --- state -------------------------------------------------------------------------------
    def generalized_state(self):
        """(qpos, qpos rate); buffers are reused: copy them to keep them."""
        d = self.data
        self._gx[:] = d.qpos
        if self.free:
            self._gv[:3] = d.qvel[:3]
            # d q / dt = q (0, w) / 2 with w the body-frame angular velocity
            self._w[1:] = d.qvel[3:6]
            self._mj.mju_mulQuat(self._qdot, d.qpos[3:7], self._w)
            self._gv[3:7] = 0.5 * self._qdot
            self._gv[7:] = d.qvel[6:]
        else:
            self._gv[:] = d.qvel
        return self._gx, self._gv

    def set_generalized_state(self, x, xdot):
        d = self.data
        d.qpos[:] = x
        if self.free:
            q = np.asarray(x[3:7], dtype=float)
            q = q / np.linalg.norm(q)
            d.qpos[3:7] = q
            d.qvel[:3] = xdot[:3]
            # body-frame angular velocity: w = 2 conj(q) qdot (vector part)
            w = np.zeros(4)
            self._mj.mju_mulQuat(w, q * [1.0, -1.0, -1.0, -1.0], np.asarray(xdot[3:7], float))
            d.qvel[3:6] = 2.0 * w[1:]
            d.qvel[6:] = xdot[7:]
        else:
            d.qvel[:] = xdot
        self._mj.mj_forward(self.model, d)

    def capture(self):
        d = self.data
        snap = {k: getattr(d, k).copy() for k in STATE_ARRAYS}
        snap.update(time=np.array(self.time), next_control=np.array(self._next_control),
                    targets=self.targets.copy(), vtargets=self.vtargets.copy(),
                    omega=self.omega.copy(), zeta=self.zeta.copy(),
                    fsm=np.array([self.fsm.current if self.fsm else 0,
                                  self.fsm.entered if self.fsm else 0.0]),
                    support=np.array(self.support), balance=np.array(self.balance_offset),
                    blend=np.zeros(0) if self._blend is None else np.concatenate(
                        [self._blend[0], self._blend[1], self._blend[2:]]),
                    servo=np.concatenate([self._c0, self._dc, self._ff, [self._tick]]),
                    touched=self.touched.copy(), offsets=self.offsets.copy())
        if self.feedback is not None:
            snap.update({f"feedback_{k}": v for k, v in self.feedback.capture().items()})
        return snap

    def restore(self, snap):
        d = self.data
        for k in STATE_ARRAYS:
            getattr(d, k)[:] = snap[k]
        self.time = float(snap["time"])
        self._next_control = float(snap["next_control"])
        self.targets[:], self.vtargets[:] = snap["targets"], snap["vtargets"]
        self.omega[:], self.zeta[:] = snap["omega"], snap["zeta"]
        if self.fsm is not None:
            self.fsm.current, self.fsm.entered = int(snap["fsm"][0]), float(snap["fsm"][1])
        self.support = bool(snap["support"])
        self.balance_offset = float(snap["balance"])
        b, n = snap["blend"], len(self.targets)
        self._blend = None if len(b) == 0 else (b[:n].copy(), b[n:2 * n].copy(), b[-2], b[-1])
        self.apply_gains()
        n3 = 3 * n
        self._c0[:], self._dc[:], self._ff[:] = (snap["servo"][:n3].reshape(3, n))
        self._tick = float(snap["servo"][n3])
        self.touched[:], self.offsets[:] = snap["touched"], snap["offsets"]
        if self.feedback is not None:
            self.feedback.restore({k[9:]: v for k, v in snap.items()
                                   if k.startswith("feedback_")})
        self._mj.mj_forward(self.model, d)

    def frame(self):
        d = self.data
        return {"segment_positions": d.xpos[self.seg_body].copy(),
                "segment_orientations": d.xquat[self.seg_body].copy(),
                "segment_wrenches": d.xfrc_applied[self.seg_body].copy(),
                "com": d.subtree_com[self.root].copy()}

    # --- the contact view: one rigid part per segment ---------------------------------------
    def contact_view(self):
        return self._view

    def part_poses(self):
        d = self.data
        return d.xpos[self.part_body], d.xmat[self.part_body].reshape(-1, 3, 3)

    def part_centres(self):
        return self.data.xipos[self.part_body]

    def part_velocities(self, parts=None):
        """MuJoCo's velocities of the segments' centres of mass, world frame (one call per
        segment asked for)."""
        bodies = self.part_body if parts is None else self.part_body[np.asarray(parts)]
        lin, ang = np.empty((len(bodies), 3)), np.empty((len(bodies), 3))
        for k, b in enumerate(bodies):
            self._mj.mj_objectVelocity(self.model, self.data, self._mj.mjtObj.mjOBJ_BODY,
                                       int(b), self._twist, 0)
            ang[k], lin[k] = self._twist[:3], self._twist[3:]
        return lin, ang

    def part_inverse_inertias(self):
        """Zero: a contact sees a segment's own mass only; its joints make the real effective
        mass larger, so the contact is a little softer than it could be, never less stable."""
        return np.zeros((len(self.part_body), 3, 3))

    def centre_of_mass(self):
        return self.com()

    def add_part_wrench(self, part, force, torque=None, point=None, dfdx=None, dfdv=None):
        self.add_wrench(force, torque, point, body=int(part))

    def shapes(self):
        return [figure_shape(self.name, self.plan, self.color)]

    # --- geometry ----------------------------------------------------------------------------
    def segment_meshes(self) -> list:
        """Per segment (vertices (n,3) m in the segment frame, triangles (m,3))."""
        return [segment_mesh(s.shape) for s in self.plan]

    def surface(self):
        """The whole figure's triangle surface at the current pose: vertices (n,3) m and
        triangles (m,3)."""
        d = self.data
        verts, tris, base = [], [], 0
        for k, (v, t) in enumerate(self.segment_meshes()):
            b = self.seg_body[k]
            verts.append(d.xpos[b] + v @ d.xmat[b].reshape(3, 3).T)
            tris.append(t + base)
            base += len(v)
        return np.concatenate(verts), np.concatenate(tris)
