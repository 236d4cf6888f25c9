"""A vault's second flight and its landing (SPEC 4, the floor mat): the take-off state off the
vault table and the landing controller that sticks it.

Take-off (``VaultParams``): the gymnast leaves the table after a handspring with her centre
of mass ``vx`` m/s forward and ``vz`` m/s up, her body past the handstand by ``pitch0 - pi``
rad and turning forward at ``spin`` rad/s. Published second-flight kinematics of handspring
vaults put the horizontal velocity at table take-off at about 3-4 m/s and the vertical at
about 2-3 m/s, with forward rotation (Takei 1991, 1998; Naundorf et al. 2008; docs/mat.md).

The state machine (control/fsm.py), in the paper's style:

* ``flight``: straight body, arms overhead, toes pointed, while she turns over; once the
  trunk is within ``prepare_at`` rad of upright (``pitch_above``, with a look-ahead of
  ``spot`` s at her rate, as gymnasts spot the landing) she hands over to
* ``prepare``: legs forward (hips flexed to ``hip_prepare``, knees a little bent), feet
  flat, arms up; on foot contact
* ``touchdown``: absorb with hips, knees and ankles (flexed to ``hip_absorb``,
  ``knee_absorb``, ``ankle_absorb``) on soft servos (``absorb_omega``), the arms coming
  forward; after ``absorb`` s
* ``hold``: arms out to the sides, knees soft, the ankles balancing the centre of mass over
  the feet (the figure's ankle strategy and ``LandingBalance``): she stands, no step.

On the ground, from touch-down on, ``LandingBalance`` also feeds back the capture point
xi = (c - s) + v / w0 along her heading (c - s the centre of mass's lead over the middle of
the soles, v its speed, w0 = sqrt(g / h) for its height h over them: where an inverted
pendulum would come to rest): the hips flex by ``cp_hip`` xi (a bend at the hips pushes the
ground backwards under the feet, braking a centre of mass headed past the toes), the ankles
plantarflex by ``cp_ankle`` xi and the knees extend by ``cp_knee`` xi (rad/m each).

Angles in rad (anatomical sense: flexion positive; ankle flexion is dorsiflexion), times in
s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..geometry.anthropometry import BodyParams
from ..params import param
from ..systems.base import GRAVITY
from ..systems.figure import Figure, FigureParams
from ..systems.figure_model import EnvironmentParams
from .bounce import BounceBalance, BounceParams
from .fsm import Controller, State, Transition



@dataclass(frozen=True)
class VaultParams:
    """The take-off off the table and the landing controller (module docstring): the gymnast
    (64.38 kg, 1.70 m: the paper's Table I gymnast); table (m): the vault table's height;
    com0 (m): her centre of mass above the table at take-off; vx, vz (m/s); pitch0 (rad: the
    trunk's forward turn from upright, pi = inverted); spin (rad/s forward); prepare_at
    (rad), spot (s); the landing posture hip_prepare, knee_prepare, ankle_prepare (negative:
    toes pointed, so the toes land first and the ankles start the absorption), arms_prepare
    (rad of shoulder flexion); the absorption hip_absorb, knee_absorb, ankle_absorb (rad), its servo
    frequency absorb_omega (rad/s) and damping ratio absorb_zeta (-: the stance legs' servos
    act on the whole body's inertia, so a critically damped one resists a fast flexion with
    kilonewtons and throws her back up) and time absorb (s); hold: arms_out (rad of shoulder
    abduction), knee_hold (rad); the balance over the feet on landing: k_lead (rad/m),
    k_drift (rad s/m), k_spin (rad per kg m^2/s), k_attitude (-: the hip strategy, the
    pelvis held upright over the legs), k_hip_spin (rad per kg m^2/s: the hips against the
    body's pitch), and in the air k_speed (s): the feet are placed ahead of the centre of mass
    by k_speed times its horizontal speed; hold_lead (rad/m), hold_drift (rad s/m): the
    figure's ankle strategy in ``hold`` (ankles against the centre of mass's lead over the
    feet and its speed); k_side (rad/m), k_side_drift (rad s/m): the hip strategy sideways on
    the ground (the hips ab/adducted together, shifting the pelvis over the feet against the
    centre of mass's sideways lead over the middle of the soles and its sideways speed); vy
    (m/s): a sideways take-off velocity (0 in the vault; the landing search perturbs it);
    cp_hip, cp_ankle, cp_knee (rad/m): the capture-point feedback (module docstring)."""
    mass: float = param(64.38, "kg", ge=10.0, le=500.0)
    height: float = param(1.70, "m", ge=0.5, le=3.0)
    table: float = param(1.25, "m", ge=0.0, le=5.0, doc="vault table height")
    com0: float = param(0.95, "m", ge=0.0, le=3.0, doc="centre of mass above the table")
    vx: float = param(3.3, "m/s", ge=-20.0, le=20.0, doc="horizontal take-off velocity")
    vz: float = param(2.5, "m/s", ge=-20.0, le=20.0, doc="vertical take-off velocity")
    vy: float = param(0.0, "m/s", ge=-5.0, le=5.0, doc="sideways take-off velocity (left +)")
    pitch0: float = param(3.45, "rad", ge=-7.0, le=7.0, doc="trunk's turn from upright")
    spin: float = param(3.0505318143348936, "rad/s", ge=-30.0, le=30.0, doc="forward rotation")
    prepare_at: float = param(2.0, "rad", ge=0.0, le=3.2)
    spot: float = param(0.0866386721047684, "s", ge=0.0, le=2.0)
    hip_prepare: float = param(0.2772502106418362, "rad", ge=-0.5, le=2.5)
    knee_prepare: float = param(0.4062858940972105, "rad", ge=0.0, le=2.5)
    ankle_prepare: float = param(-0.5965310216637655, "rad", ge=-1.0, le=1.0, doc="toes first")
    arms_prepare: float = param(3.1, "rad", ge=-1.0, le=3.2)
    hip_absorb: float = param(1.2385498106316593, "rad", ge=0.0, le=2.5)
    knee_absorb: float = param(1.8534487167148126, "rad", ge=0.0, le=2.5)
    ankle_absorb: float = param(0.6551613383489778, "rad", ge=-0.5, le=1.0)
    absorb_omega: float = param(6.335577070180416, "rad/s", gt=0.0, le=100.0)
    absorb_zeta: float = param(0.2358546600010747, "-", gt=0.0, le=10.0, doc="absorption damping")
    absorb: float = param(0.2, "s", ge=0.0, le=5.0)
    arms_out: float = param(1.4, "rad", ge=0.0, le=3.2)
    knee_hold: float = param(0.4018196417934671, "rad", ge=0.0, le=2.5)
    k_lead: float = param(1.6380137657176401, "rad/m", ge=0.0, le=50.0)
    k_drift: float = param(0.2592356154095098, "rad s/m", ge=0.0, le=20.0)
    k_spin: float = param(0.012535857741316651, "rad s/(kg m^2)", ge=0.0, le=1.0)
    k_attitude: float = param(0.2947564098834199, "-", ge=0.0, le=3.0)
    k_hip_spin: float = param(-0.02446327686928802, "rad s/(kg m^2)", ge=-1.0, le=1.0)
    hold_lead: float = param(0.0, "rad/m", ge=0.0, le=20.0, doc="hold: on the lead")
    hold_drift: float = param(0.6422428885793572, "rad s/m", ge=0.0, le=20.0, doc="hold: on speed")
    k_side: float = param(-1.0, "rad/m", ge=-20.0, le=20.0, doc="sideways hips")
    k_side_drift: float = param(1.922683354170515, "rad s/m", ge=-20.0, le=20.0, doc="on speed")
    k_speed: float = param(0.19689038915231383, "s", ge=0.0, le=5.0)
    cp_hip: float = param(2.0497659366018897, "rad/m", ge=-20.0, le=20.0, doc="hips on xi")
    cp_ankle: float = param(0.7613353373157984, "rad/m", ge=-20.0, le=20.0, doc="ankles on xi")
    cp_knee: float = param(-1.6072265382393776, "rad/m", ge=-20.0, le=20.0, doc="knees on xi")


def controller(p: VaultParams) -> Controller:
    """flight -> prepare -> touchdown -> hold, starting in flight (off the table)."""
    flight = State("flight", pose=(("hip", 0.0), ("knee", 0.0), ("ankle", -0.5), ("waist", 0.0),
                                   ("neck", 0.0), ("shoulder_flex", 3.0), ("shoulder_abd", 0.0),
                                   ("elbow", 0.0), ("toe", 0.0)),
                   transitions=(Transition("pitch_above", "prepare", -p.prepare_at,
                                           lookahead=p.spot),), blend=0.0)
    # the legs are soft already in the air: a leg held stiff meets the ground as a rod, and
    # the impact throws her back up (measured: a 16 kN spike and a 0.2 m rebound on a rigid
    # floor) before the touch-down state's first tick
    legs = (("hip", p.absorb_omega), ("knee", p.absorb_omega), ("ankle", p.absorb_omega))
    prepare = State("prepare", pose=(("hip_flex", p.hip_prepare), ("hip_abd", 0.0),
                                     ("knee", p.knee_prepare), ("ankle", p.ankle_prepare),
                                     ("shoulder_flex", p.arms_prepare), ("shoulder_abd", 0.0),
                                     ("elbow", 0.0)), gains=legs,
                    blend=0.15, transitions=(Transition("foot_contact", "touchdown"),))
    touchdown = State("touchdown", pose=(("hip_flex", p.hip_absorb), ("knee", p.knee_absorb),
                                         ("ankle", p.ankle_absorb), ("shoulder_flex", 1.5),
                                         ("elbow", 0.1)),
                      gains=legs, zeta=p.absorb_zeta, support=True, blend=0.0,
                      transitions=(Transition("time", "hold", p.absorb),))
    hold = State("hold", pose=(("hip_flex", 0.5 * p.knee_hold), ("hip_abd", 0.0),
                               ("knee", p.knee_hold), ("ankle", 0.5 * p.knee_hold),
                               ("waist", 0.0), ("neck", 0.0), ("shoulder_flex", 0.0),
                               ("shoulder_abd", p.arms_out), ("elbow", 0.1), ("toe", 0.0)),
                 support=True, balance=(p.hold_lead, p.hold_drift), blend=0.6)
    return Controller((flight, prepare, touchdown, hold), start="flight")


SIDE_MAX = 0.3  # rad: the largest sideways hip offset
SIDE_RATE = 3.0  # rad/s: its fastest change (a shift, not a kick)
CP_MAX = 0.6  # rad: the largest capture-point offset of a joint
CP_RATE = 6.0  # rad/s: its fastest change


class LandingBalance(BounceBalance):
    """The figure's feedback for a landing (the trampoline's balance law, control/bounce.py,
    reused): in the air, from ``prepare`` on, the feet are placed ahead of the centre of mass
    by k_speed times its speed; on the ground the ankles steer the centre of mass over the feet
    and the hips hold the pelvis upright over the legs, and (its own) shift it sideways over
    the feet (k_side, k_side_drift) and answer the capture point (cp_hip, cp_ankle,
    cp_knee). Nothing while she turns over in ``flight`` (the placement's angles mean nothing
    upside down)."""

    def __init__(self, p: VaultParams, joints):
        bp = BounceParams(k_speed=p.k_speed, k_place=0.0, k_lead=p.k_lead, k_drift=p.k_drift,
                          k_spin=p.k_spin, k_attitude=p.k_attitude, k_turn=0.0,
                          k_hip_spin=p.k_hip_spin, k_arms=0.0, aim=0.0, k_side=0.0,
                          k_side_drift=0.0, k_roll=0.0, k_speed_side=0.0,
                          k_turn_side=0.0, k_hip_roll=0.0)  # sideways: its own, below
        super().__init__(bp, joints)
        self.k_side, self.k_side_drift = p.k_side, p.k_side_drift
        self.side = 0.0  # rad: the sideways hip offset now
        self.cp_gain = np.array([p.cp_hip, -p.cp_ankle, -p.cp_knee])
        self.cp = np.zeros(3)  # rad: the capture point's hip, ankle and knee offsets now

    def capture(self) -> dict:
        return dict(super().capture(), side=np.array(self.side), cp=self.cp.copy())

    def restore(self, snap: dict):
        super().restore(snap)
        if snap:
            self.side = float(snap["side"])
            self.cp[:] = snap["cp"]

    def offsets(self, fig, sensors) -> np.ndarray:
        if fig.fsm.state.name == "flight":
            return self.out
        out = super().offsets(fig, sensors)
        # sideways, on the ground: a symmetric stand-in never pushes her sideways, a mat's
        # dent and a crooked take-off do; the hips shift the pelvis over the feet
        want = 0.0
        cp = np.zeros(3)
        if len(fig.feet_touching()):
            d = fig.data
            fwd, left = fig.heading_axes()
            rel = sensors["com"] - d.geom_xpos[fig.sole_geoms].mean(axis=0)
            lead = rel @ left
            want = float(np.clip(self.k_side * lead + self.k_side_drift * (sensors["com_vel"]
                                                                           @ left),
                                 -SIDE_MAX, SIDE_MAX))
            # the capture point: where over the ground the centre of mass, an inverted
            # pendulum of its height over the soles, would come to rest
            w0 = math.sqrt(-GRAVITY[2] / max(rel[2], 0.3))
            xi = rel @ fwd + (sensors["com_vel"] @ fwd) / w0
            cp = np.clip(self.cp_gain * xi, -CP_MAX, CP_MAX)
        step = SIDE_RATE * fig.control_dt
        self.side = float(np.clip(want, self.side - step, self.side + step))
        self.cp = np.clip(cp, self.cp - CP_RATE * fig.control_dt,
                          self.cp + CP_RATE * fig.control_dt)
        res = out.copy()
        res[self.abd_l] += self.side
        res[self.abd_r] -= self.side
        res[self.flex] += self.cp[0]
        res[self.ankles] += self.cp[1]
        res[self.knees] += self.cp[2]
        return res


def rotation_y(angle: float) -> np.ndarray:
    """MuJoCo quaternion (w, x, y, z) of a turn of ``angle`` rad about +y (forward pitch for a
    figure facing +x)."""
    return np.array([math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0])


def gymnast(p: VaultParams, floor: float | None, takeoff_x: float = 0.0,
            air_density: float = 1.2, name: str = "gymnast") -> Figure:
    """The gymnast leaving the table: her centre of mass at (takeoff_x, 0, table + com0) m
    moving (vx, 0, vz) m/s, the body in its flight posture turned pitch0 rad forward and
    turning at spin rad/s about her left-right axis; floor (m): MuJoCo's ground under her."""
    env = EnvironmentParams(floor=floor, air_density=air_density)
    fig = Figure(name, FigureParams(body=BodyParams(p.mass, p.height), environment=env,
                                    position=(takeoff_x, 0.0, p.table)), controller(p))
    fig.feedback = LandingBalance(p, fig.joints)
    d, mj = fig.data, fig._mj
    d.qpos[fig.qadr] = fig.targets  # the flight posture the controller starts in
    d.qpos[3:7] = rotation_y(p.pitch0)
    d.qvel[:] = 0.0
    mj.mj_forward(fig.model, d)
    com = fig.com()
    d.qpos[:3] += np.array([takeoff_x, 0.0, p.table + p.com0]) - com
    mj.mj_forward(fig.model, d)
    # the whole body turning at w about its centre of mass: the root moves at v + w x r
    w = np.array([0.0, p.spin, 0.0])
    r = d.qpos[:3] - fig.com()
    d.qvel[:3] = np.array([p.vx, p.vy, p.vz]) + np.cross(w, r)
    R = d.xmat[fig.root].reshape(3, 3)
    d.qvel[3:6] = R.T @ w  # MuJoCo's free joint: angular velocity in the body frame
    d.qvel[6:] = 0.0
    mj.mj_forward(fig.model, d)
    fig._plan(0.0)
    return fig
