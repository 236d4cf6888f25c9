"""The bounce controller: a gymnast's straight bounce on a trampoline, as a state machine in
the style of the paper's (SPEC 2.3), with a balance law that keeps her over the bed's centre.

States, each a set of joint targets (control/fsm.py):

* ``flight``: straight body, toes pointed, arms overhead; at the apex (centre of mass
  falling) she hands over to
* ``descend``: the legs prepare for landing (knees and hips flexed to ``knee_land`` and
  ``hip_land``, feet flat, stiff stance gains ``leg_omega``), arms come down in front; on
  foot contact
* ``absorb``: the legs hold their flexion against the bed while it is depressed, for
  ``thrust_delay`` s, then
* ``thrust``: hips, knees and ankles extend (velocity targets scaled by ``power``, the
  ankles to ``ankle_push``) timed to the bed's recoil, and the arms swing up to
  ``arm_swing``; when both feet leave the bed she is in ``flight`` again.

Balance (``BounceBalance``, the figure's feedback at every control tick), after Raibert's
hopping machines: in the air the legs are placed for the landing, hip flexion (forward-back)
and abduction (sideways) turned so the feet land ahead of the centre of mass by
``k_speed`` v + ``k_place`` (c - c0) along each axis (v the centre of mass's horizontal
velocity, c - c0 its offset from the bed's centre), which brakes a drift and steers her back,
and with ``aim`` the hips are servoed in the descent on the feet's measured miss from there;
on the bed the hips servo the pelvis upright against the planted legs (``k_attitude`` of the
legs' lean), which stops the body rotating. Offsets slew at most SLEW so a new phase does not
kick the servos.

Angles in rad (anatomical sense: flexion positive; ankle flexion is dorsiflexion), times in
s, gains as stated. The defaults of ``BounceParams`` are the output of ``interplay tune
trampoline`` (control/search.py simulated annealing; docs/trampoline.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ..errors import ParameterError
from ..geometry.anthropometry import SEGMENTS
from ..params import param
from .fsm import Controller, State, Transition

SLEW = 4.0  # rad/s: the balance offsets' fastest change
PLACE_MAX = 0.35  # rad: the largest leg angle the foot placement asks for
LEG_LENGTH = 0.85  # m: hip to sole of the default 1.70 m gymnast, for the placement angle
ARM_RANGE = (-1.0, 2.5)  # rad: how far the circling arms may go from their pose
EXTEND = 8.0  # 1/s: the thrust's extension rate, as a share of the crouch per second, at power 1


@dataclass(frozen=True)
class BounceParams:
    """The bounce controller's free parameters (the search's variables; units in the module
    docstring): landing posture knee_land (rad; the ankles and hips bend by half of it so the
    hips stay over the ankles), lean (rad of extra ankle flexion: the body forward over the
    middle of the feet) and trunk (rad of extra hip flexion);
    leg_omega (rad/s): the stance legs' servo frequency, ankle_share (-) the ankles' share
    of it on the bed; thrust_delay (s) after touchdown;
    power (-): the extension's velocity targets; ankle_push (rad, negative: plantarflexion);
    arm_swing (rad of shoulder abduction at takeoff: the arms rise sideways, so the two
    arms' angular momenta cancel and the swing does not tip her), arm_land (rad); foot
    placement k_speed (s), k_place (-); on the bed, the ankles' feedback on the centre of
    mass's lead over the feet k_lead (rad/m), on its velocity k_drift (rad s/m) and on the
    body's angular momentum k_spin (rad per kg m^2/s), and the hips' servo of the pelvis
    upright against the legs' lean, k_attitude (-); in the air, k_turn (m per kg m^2/s):
    the feet land that much behind the centre of mass per unit of the body's backward
    angular momentum, so the bed's push on the next landing turns the spin back; on the bed,
    k_hip_spin (rad per kg m^2/s): the hips extend against a backward spin (and flex against
    a forward one), which turns the legs' push on the bed, and with it the bed's friction
    under the feet a metre below the centre of mass, against the spin; k_arms (-): the share
    of the body's pitch spin the arms take in the air by circling (forward against a
    backward spin), so the trunk lands upright, a trampolinist's correction; aim (-): in the
    descent the hips are servoed on where the feet are, each tick's hip target the present
    angle turned by aim times the feet's miss over the leg's length (0: the placement is the
    open-loop leg angle above, blind to where the hips' servos leave the feet and to the
    trunk's tilt carrying the centre of mass off the hips); on the bed sideways, where her ankles
    have no roll joint to steer with, the hips shift the pelvis over the feet: k_side (rad/m)
    of abduction per metre of the centre of mass's sideways lead over the soles and
    k_side_drift (rad s/m) per m/s of its sideways speed (the landing's hip strategy,
    control/landing.py), and k_roll (rad/m): the knee on the side she leans to straightens
    and the other bends by k_roll times that lead; width (rad): each hip's abduction from
    the descent on, the feet landing apart (0: together, as she flies); sideways gains of
    their own on top of the shared ones: k_speed_side (s) adds to k_speed and k_turn_side
    (m s/(kg m^2)) to k_turn in the sideways placement, k_hip_roll (rad s/(kg m^2)) to
    k_hip_spin in the hips' answer to the roll on the bed (0: the shared gains alone)."""
    knee_land: float = param(
        0.1424226959213322, "rad", ge=0.0, le=2.0, doc="knee flexion at landing")
    lean: float = param(0.20698593380938535, "rad", ge=-1.0, le=1.0, doc="extra ankle flexion")
    trunk: float = param(-0.1351097518235242, "rad", ge=-1.0, le=1.5, doc="extra hip flexion")
    leg_omega: float = param(
        17.29121847458241, "rad/s", gt=0.0, le=100.0, doc="stance servo frequency")
    ankle_share: float = param(
        0.5098146189903848, "-", gt=0.0, le=2.0, doc="ankles' share of leg_omega")
    thrust_delay: float = param(0.2930074239134891, "s", ge=0.0, le=2.0, doc="after touchdown")
    power: float = param(0.5783727889949792, "-", gt=0.0, le=5.0, doc="the extension's speed")
    ankle_push: float = param(0.2713425921382224, "rad", ge=-1.0, le=0.6, doc="ankle at takeoff")
    arm_swing: float = param(
        2.706300621605705, "rad", ge=0.0, le=3.2, doc="shoulder abduction, takeoff")
    arm_land: float = param(
        0.9417450686491842, "rad", ge=0.0, le=3.2, doc="shoulder abduction, landing")
    k_speed: float = param(
        0.020480619970776732, "s", ge=0.0, le=5.0, doc="foot placement on speed")
    k_place: float = param(
        0.23091748549548033, "-", ge=0.0, le=5.0, doc="foot placement on offset")
    k_lead: float = param(4.8181943941287235, "rad/m", ge=0.0, le=50.0)
    k_drift: float = param(1.1785864179627352, "rad s/m", ge=0.0, le=20.0)
    k_spin: float = param(0.043532118254619445, "rad s/(kg m^2)", ge=0.0, le=1.0)
    k_attitude: float = param(0.20039058361221426, "-", ge=0.0, le=3.0)
    k_turn: float = param(0.004144061806616518, "m s/(kg m^2)", ge=-1.0, le=1.0)
    k_hip_spin: float = param(-0.03455440288576774, "rad s/(kg m^2)", ge=-1.0, le=1.0)
    k_arms: float = param(0.670278510898547, "-", ge=0.0, le=5.0)
    aim: float = param(
        1.2391029812565044, "-", ge=0.0, le=10.0, doc="the hips servoed on the feet's miss")
    k_side: float = param(
        1.8443404812826967, "rad/m", ge=-20.0, le=20.0, doc="sideways hips on the lead")
    k_side_drift: float = param(
        4.081760045683858, "rad s/m", ge=-20.0, le=20.0, doc="on its speed")
    width: float = param(
        0.01284751283714039, "rad", ge=-0.5, le=0.75, doc="each hip's abduction, landing")
    k_roll: float = param(
        -3.2997047394784764, "rad/m", ge=-50.0, le=50.0, doc="knees on the sideways lead")
    k_speed_side: float = param(
        0.032003794831570655, "s", ge=-5.0, le=5.0, doc="sideways placement on speed")
    k_turn_side: float = param(
        0.0017048954315904547, "m s/(kg m^2)", ge=-1.0, le=1.0, doc="sideways placement, roll")
    k_hip_roll: float = param(
        0.032831302149056774, "rad s/(kg m^2)", ge=-2.0, le=2.0, doc="sideways hips on the roll")

    def validated(self) -> "BounceParams":
        for f in fields(self):
            v = getattr(self, f.name)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ParameterError(f"bounce controller: {f.name} must be a finite number, "
                                     f"got {v!r}")
        if not (self.leg_omega > 0 and self.thrust_delay >= 0 and self.power > 0):
            raise ParameterError("bounce controller: leg_omega and power must be positive and "
                                 f"thrust_delay >= 0 s, got {self.leg_omega}, {self.power}, "
                                 f"{self.thrust_delay}")
        return self


#: the search's box: name -> (low, high), in the units above
BOUNDS = {"knee_land": (0.1, 0.9), "lean": (-0.1, 0.4), "trunk": (-0.2, 0.4),
          "leg_omega": (6.0, 20.0), "ankle_share": (0.05, 1.0), "thrust_delay": (0.0, 0.3),
          "power": (0.3, 2.0), "ankle_push": (-0.6, 0.4), "arm_swing": (1.5, 3.1),
          "arm_land": (0.0, 1.5), "k_speed": (0.0, 0.6), "k_place": (0.0, 1.0),
          "k_lead": (0.0, 6.0), "k_drift": (0.0, 1.5), "k_spin": (0.0, 0.05),
          "k_attitude": (0.0, 1.2), "k_turn": (0.0, 0.05), "k_hip_spin": (-0.06, 0.06),
          "k_arms": (0.0, 1.5), "aim": (0.0, 4.0), "k_side": (-1.0, 5.0),
          "k_side_drift": (0.0, 8.0), "width": (0.0, 0.3),
          "k_roll": (-8.0, 2.0), "k_speed_side": (-0.3, 0.3), "k_turn_side": (-0.01, 0.01),
          "k_hip_roll": (-0.1, 0.1)}


def controller(p: BounceParams) -> Controller:
    """flight -> descend -> absorb -> thrust -> flight, starting in descend (she is dropped
    from her first apex)."""
    p = p.validated()
    legs = (("hip", p.leg_omega), ("knee", p.leg_omega), ("ankle", p.leg_omega))
    # on the bed the ankles may be softer: a limp ankle puts no torque into the bed, so the
    # bed's push runs from the foot up the leg, nearer the centre of mass
    stance = (("hip", p.leg_omega), ("knee", p.leg_omega),
              ("ankle", p.ankle_share * p.leg_omega))
    flight = State("flight", pose=(("hip", 0.0), ("knee", 0.05), ("ankle", -0.3), ("waist", 0.0),
                                   ("neck", 0.0), ("shoulder_flex", 0.0),
                                   ("shoulder_abd", p.arm_swing), ("elbow", 0.05),
                                   ("toe", 0.0)),
                   transitions=(Transition("com_falling", "descend"),), blend=0.15)
    descend = State("descend", pose=(("hip_flex", 0.5 * p.knee_land + p.trunk),
                                     ("hip_abd", p.width), ("knee", p.knee_land),
                                     ("ankle", 0.5 * p.knee_land + p.lean),
                                     ("shoulder_abd", p.arm_land), ("elbow", 0.1)),
                    gains=legs, support=True, blend=0.4,
                    transitions=(Transition("foot_contact", "absorb"),))
    absorb = State("absorb", gains=stance, support=True, blend=0.0,
                   transitions=(Transition("time", "thrust", p.thrust_delay),
                                Transition("no_foot_contact", "flight")))
    # the extension keeps the trunk's tilt in the world (trunk + lean, forward): the hips open
    # by exactly what the thighs turn, so no part of the body is swung round against the bed
    # and the push adds no spin; velocities in proportion, so the hips rise over the feet
    hip_end = p.trunk + p.lean - p.ankle_push
    thrust = State("thrust", pose=(("hip_flex", hip_end), ("knee", 0.0), ("ankle", p.ankle_push),
                                   ("shoulder_abd", p.arm_swing), ("elbow", 0.0)),
                   velocity=(("hip_flex", -EXTEND * p.power * (0.5 * p.knee_land + p.trunk
                                                              - hip_end)),
                             ("knee", -EXTEND * p.power * p.knee_land),
                             ("ankle", -EXTEND * p.power * (0.5 * p.knee_land + p.lean
                                                            - p.ankle_push)),
                             ("shoulder_abd", 8.0)),
                   gains=stance, support=True, blend=0.0,
                   transitions=(Transition("no_foot_contact", "flight"),))
    return Controller((flight, descend, absorb, thrust), start="descend")


class BounceBalance:
    """The figure's feedback (systems/figure.py): joint offsets (rad), foot placement in the
    air and the ankles' balance on the bed; centre (m): the bed's centre (x, y)."""

    def __init__(self, p: BounceParams, joints, centre=(0.0, 0.0)):
        self.p = p.validated()
        self.centre = np.asarray(centre, float)
        idx = {n: i for i, n in enumerate(joints)}
        self.flex = np.array([idx["l_hip_flex"], idx["r_hip_flex"]])
        self.ankles = np.array([idx["l_ankle"], idx["r_ankle"]])
        self.thighs = [SEGMENTS.index("l_thigh"), SEGMENTS.index("r_thigh")]
        self.shoulders = np.array([idx["l_shoulder_flex"], idx["r_shoulder_flex"]])
        self.arms = None  # kg m^2: the arms' inertia about the shoulders' axis (first tick)
        self.abd_l, self.abd_r = idx["l_hip_abd"], idx["r_hip_abd"]
        self.knees = np.array([idx["l_knee"], idx["r_knee"]])
        self.out = np.zeros(len(joints))

    def capture(self) -> dict:
        # the arms' inertia is measured at the first tick's pose: a resumed run keeps it
        return {"out": self.out.copy(),
                "arms": np.array([np.nan if self.arms is None else self.arms])}

    def restore(self, snap: dict):
        if snap:
            self.out[:] = snap["out"]
            arms = float(np.asarray(snap["arms"]).ravel()[0])
            self.arms = None if math.isnan(arms) else arms

    def offsets(self, fig, sensors) -> np.ndarray:
        d = fig.data
        fwd, left = fig.heading_axes()
        p = self.p
        com, v = sensors["com"], sensors["com_vel"]
        want = np.zeros_like(self.out)
        if len(fig.feet_touching()):
            # on the bed: the ankle strategy, steering the pressure under the feet to keep the
            # centre of mass over them and the body from rotating
            rel = com - d.geom_xpos[fig.sole_geoms].mean(axis=0)
            lead = rel @ fwd
            spin = d.subtree_angmom[fig.root] @ left  # > 0: pitching forward
            want[self.ankles] = -(p.k_lead * lead + p.k_drift * (v @ fwd) + p.k_spin * spin)
            # and the hips: flexed by the legs' lean, the pelvis is held upright over them
            leg = (d.geom_xpos[fig.sole_geoms].mean(axis=0)
                   - d.xpos[fig.seg_body[self.thighs]].mean(axis=0))
            want[self.flex] = (p.k_attitude * math.atan2(leg @ fwd, -leg[2])
                               + p.k_hip_spin * spin)
            side = (p.k_attitude * math.atan2(leg @ left, -leg[2])
                    - (p.k_hip_spin + p.k_hip_roll) * (d.subtree_angmom[fig.root] @ fwd)
                    + p.k_side * (rel @ left) + p.k_side_drift * (v @ left))
            want[self.abd_l], want[self.abd_r] = side, -side
            # and the knees: the leg on the side she leans to straightens, the other bends
            want[self.knees] = np.array([-1.0, 1.0]) * (p.k_roll * (rel @ left))
        else:
            # in the air: place the feet ahead of the centre of mass to brake and steer back,
            # the hips turned against the pelvis's pitch and roll so the legs aim in the world
            up = d.xmat[fig.root].reshape(3, 3)[:, 2]
            pitch = math.atan2(up @ fwd, up[2])  # pelvis leaning forward: > 0
            roll = math.atan2(-(up @ left), up[2])  # leaning to her right: > 0
            c = com[:2] - self.centre
            spin = d.subtree_angmom[fig.root]  # kg m^2/s: forward pitch about +left
            turn_fwd = p.k_turn * (spin @ left)  # spinning forward: land with the feet ahead
            # rolling to her right: feet to the right
            turn_side = -(p.k_turn + p.k_turn_side) * (spin @ fwd)

            def angle(a):
                return float(np.clip(math.asin(np.clip(a / LEG_LENGTH, -1.0, 1.0)),
                                     -PLACE_MAX, PLACE_MAX))
            tilt = PLACE_MAX
            # m: where the feet should land, ahead of and left of the centre of mass
            fore = p.k_speed * (v[:2] @ fwd[:2]) + p.k_place * (c @ fwd[:2]) + turn_fwd
            aside = ((p.k_speed + p.k_speed_side) * (v[:2] @ left[:2])
                     + p.k_place * (c @ left[:2]) + turn_side)
            want[self.flex] = angle(fore) + float(np.clip(pitch, -tilt, tilt))
            want[self.abd_l] = angle(aside) - float(np.clip(roll, -tilt, tilt))
            want[self.abd_r] = -want[self.abd_l]
            if p.aim > 0.0 and fig.fsm.state.name == "descend":
                # the feet's miss (m) from there: each tick the hips aim from where they are,
                # so the servos' lag and the trunk's tilt are seen
                ahead = d.geom_xpos[fig.sole_geoms].mean(axis=0) - com
                miss = np.array([fore - ahead @ fwd, aside - ahead @ left]) * (p.aim / LEG_LENGTH)
                now = fig.angles() - fig.reference()
                want[self.flex] = now[self.flex] + miss[0]
                want[self.abd_l] = now[self.abd_l] + miss[1]
                want[self.abd_r] = now[self.abd_r] - miss[1]
        step = SLEW * fig.control_dt
        self.out[:] = np.clip(want, self.out - step, self.out + step)
        # the arms circle in the air against the body's pitch spin (the offset integrates the
        # rate r = -k L / I_arms: shoulder flexion turns the arms about -left), and come back
        # on the bed
        if self.arms is None:
            self.arms = arm_inertia(fig)
        if len(fig.feet_touching()):
            self.out[self.shoulders] = self.out[self.shoulders] - np.clip(
                self.out[self.shoulders], -step, step)
        else:
            rate = -p.k_arms * (d.subtree_angmom[fig.root] @ left) / self.arms
            self.out[self.shoulders] = np.clip(self.out[self.shoulders]
                                               + rate * fig.control_dt, *ARM_RANGE)
        return self.out


def arm_inertia(fig) -> float:
    """(kg m^2) both arms' moment of inertia about the line through the shoulders, at rest
    hanging: sum m_i (d_i^2) + I_i over the upper arms, forearms and hands."""
    m, d = fig.model, fig.data
    total = 0.0
    for side in ("l", "r"):
        shoulder = d.xpos[fig.seg_body[SEGMENTS.index(f"{side}_upper_arm")]]
        for seg in ("upper_arm", "forearm", "hand"):
            b = fig.seg_body[SEGMENTS.index(f"{side}_{seg}")]
            r = d.xipos[b] - shoulder
            total += m.body_mass[b] * (r[0] ** 2 + r[2] ** 2) + m.body_inertia[b][1]
    return float(total)
