"""A platform dive (SPEC 4, the diver): the state machine of a forward dive in pike, how its
entry into the water is measured, and the search that tunes it.

The dive: stand at the edge, crouch with the arms back, tip forward over the toes until the
centre of mass is ``lead`` m ahead of the feet, then the take-off (a hip-knee-ankle
extension while the arms swing up), a pike in the air (legs straight, folded at the hips:
the body turns fast), and the opening: straight body, arms stretched overhead, toes pointed,
for a hands-first entry. The opening is timed by rotation, as divers spot the water: when the
trunk has turned ``open`` rad forward from upright (the figure's ``pitch_above`` event; by
OPEN_BY m above the water at the latest). Opened late (the default, a "rip") the body has
turned head-down and the slow rotation of the straight body carries it to vertical at the
entry; opened early (``entry="flat"``, at ``open_flat`` rad) it meets the water on its
front.

Angles are rad in the anatomical sense (control/behaviours.py); heights are m above the
still water surface.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError
from ..geometry.anthropometry import SEGMENTS, BodyParams
from ..params import param
from ..systems.figure import Figure, FigureParams
from ..systems.figure_model import EnvironmentParams
from . import behaviours as B
from .fsm import Controller, State, Transition

ENTRIES = ("rip", "flat")
TIP_MAX = 1.5  # s: the take-off starts by then even if the lean never gets far enough
LEAVE_MAX = 0.3  # s: the feet leave by then after the push
OPEN_BY = 2.0  # m: the centre of mass's height above the water by which he opens anyway
HANDS = (SEGMENTS.index("l_hand"), SEGMENTS.index("r_hand"))
WRISTS = HANDS  # a hand's frame origin is its wrist
TOES = (SEGMENTS.index("l_toes"), SEGMENTS.index("r_toes"))
LEADING = ("l_hand", "r_hand", "l_forearm", "r_forearm")  # what a hands-first entry leads with


@dataclass(frozen=True)
class DiveParams:
    """The diver (the paper's figures: 64.38 kg, 1.70 m) and his dive: entry "rip" (opens at
    ``open``) or "flat" (a belly-flop: opens early, at ``open_flat``); stand (s) at the edge;
    crouch (s), its depth (-, 1 = deep) and trunk lean (rad); tip_ankle (rad of dorsiflexion)
    tips him forward over his toes until his centre of mass is lead (m) ahead of the middle
    of his feet; the take-off: hip (rad of hip flexion it extends to), power (-, scales the
    extension's velocity targets), arm_swing (rad of shoulder flexion the arms swing to),
    push (s) before a foot leaving the platform ends it;
    reach (s): how long he stays stretched after leaving the platform, so his legs clear its
    edge, before the pike (rad of hip flexion in the air); open, open_flat: the trunk's
    forward pitch (rad from upright) at which he opens out, or will within spot (s) at the
    rate he turns. The defaults were found by ``tune`` (docs/diver.md)."""
    # the domains are the bungee jumper's (the same figure and leap, scenes/bungee.py)
    mass: float = param(64.38, "kg", ge=10.0, le=500.0)
    height: float = param(1.70, "m", ge=0.5, le=3.0)
    entry: str = "rip"  # checked by validated(), with what each entry is
    stand: float = param(0.3, "s", ge=0.0, le=100.0)
    crouch: float = param(0.6, "s", ge=0.0, le=100.0)
    depth: float = param(0.6, "-", ge=0.0, le=2.0)
    lean: float = param(0.327, "rad", ge=-1.6, le=1.6)
    tip_ankle: float = param(0.52, "rad", ge=-1.6, le=1.6)
    lead: float = param(0.106, "m", ge=-1.0, le=1.0)
    hip: float = param(-0.101, "rad", ge=-1.6, le=2.6)
    power: float = param(0.83, "-", ge=0.0, le=5.0)
    arm_swing: float = param(2.692, "rad", ge=-3.2, le=3.2)
    push: float = param(0.1, "s", ge=0.0, le=100.0)
    reach: float = param(0.217, "s", ge=0.0, le=100.0)
    pike: float = param(1.905, "rad", ge=-3.2, le=3.2)
    open: float = param(2.99, "rad", ge=0.0, le=3.2)
    spot: float = param(0.0, "s", ge=0.0, le=10.0)
    open_flat: float = param(1.2, "rad", ge=0.0, le=3.2)

    def validated(self) -> "DiveParams":
        if self.entry not in ENTRIES:
            raise ParameterError(f"dive.entry={self.entry!r}: choose {' or '.join(ENTRIES)} "
                                 "(rip: a vertical hands-first entry; flat: a belly-flop)")
        return self

    @property
    def opening(self) -> float:
        """rad: the trunk's pitch at which this dive opens out."""
        return self.open if self.entry == "rip" else self.open_flat


def pike(name="pike", next=None, pitch=None, spot=0.0, below=None, hip=1.9) -> State:
    """In the air: legs straight and together, folded ``hip`` rad at the hips, arms reaching
    along the legs, toes pointed; hands over when the trunk has pitched forward past
    ``pitch`` (rad), or will have within ``spot`` s at its rate, or the centre of mass falls
    below ``below`` (m)."""
    trans = ((Transition("pitch_above", next, pitch, lookahead=spot),
              Transition("com_below", next, below)) if next else ())
    return State(name, pose=(("hip_flex", hip), ("hip_abd", 0.0), ("knee", 0.0),
                             ("ankle", -0.7), ("waist_flex", 0.3), ("shoulder_flex", 1.2),
                             ("shoulder_abd", 0.0), ("elbow", 0.0)),
                 transitions=trans, blend=0.15)


def open_out(name="open") -> State:
    """The entry position, held into the water: straight body, toes pointed, arms stretched
    overhead beside the ears (hands first)."""
    return State(name, pose=(("hip", 0.0), ("knee", 0.0), ("ankle", -0.7), ("toe", 0.0),
                             ("waist", 0.0), ("neck", 0.0), ("shoulder_flex", 3.05),
                             ("shoulder_abd", 0.0), ("shoulder_rot", 0.0), ("elbow", 0.0),
                             ("wrist", 0.0)),
                 blend=0.25)


def takeoff(p: DiveParams) -> tuple:
    """The push (control/behaviours.py ``leap``) for ``push`` s, then the same extension
    until the feet leave the platform, then ``reach`` s stretched (none if 0). A leap that
    hands over at the first tick without foot contact took off early whenever a foot bounced
    in the push, with half the forward speed and several times the spin: the dive's outcome
    split in two for any small change."""
    after = "reach" if p.reach > 0.0 else "pike"
    push = replace(B.leap("takeoff", power=p.power, arm_swing=p.arm_swing, hip=p.hip),
                   transitions=(Transition("time", "leave", p.push),))
    leave = replace(push, name="leave", transitions=(Transition("no_foot_contact", after),
                                                     Transition("time", after, LEAVE_MAX)))
    reach = (B.layout("reach", next="pike", after=p.reach),) if p.reach > 0.0 else ()
    return (push, leave) + reach


def controller(p: DiveParams, level: float = 0.0) -> Controller:
    """stand -> crouch -> tip -> take-off (push, leave) -> reach -> pike -> open (to the end);
    level (m): the height of the still water surface."""
    return Controller((B.stand(next="crouch", after=p.stand),
                       B.crouch(next="tip", after=p.crouch, depth=p.depth, lean=p.lean),
                       B.tip(next="takeoff", ankle=p.tip_ankle, lead=p.lead, after=TIP_MAX),
                       *takeoff(p),
                       pike(next="open", pitch=p.opening, spot=p.spot, below=level + OPEN_BY,
                            hip=p.pike),
                       open_out()), start="stand")


def diver(p: DiveParams, platform, stance_x: float, floor=None, air_density=1.2,
          level: float = 0.0) -> Figure:
    """The diver standing on ``platform`` (x0, x1, y0, y1, top) m, ankles at x = stance_x (m),
    facing +x, under his dive controller; floor (m): the pool's bottom, None for none."""
    p = p.validated()
    env = EnvironmentParams(floor=floor, platform=tuple(platform), air_density=air_density)
    return Figure("diver", FigureParams(body=BodyParams(p.mass, p.height), environment=env,
                                        position=(stance_x, 0.5 * (platform[2] + platform[3]),
                                                  platform[4])),
                  controller(p, level))


@dataclass
class Entry:
    """The moment the diver's lowest point reaches the still surface: time (s); point (m)
    where it crosses; speed (m/s) of the centre of mass; angle (deg) of the body's axis, from
    the toe joints to the wrists, from straight down (0: vertical hands-first, 90: flat);
    velocity_angle (deg) between that axis and the centre of mass's velocity; leading: the
    segment that touches first; over (deg): the angle signed, positive past vertical (the
    wrists behind the toes: over-rotated), negative short of it."""
    time: float
    point: np.ndarray
    speed: float
    angle: float
    velocity_angle: float
    leading: str
    over: float = 0.0

    @property
    def hands_first(self) -> bool:
        return self.leading in LEADING

    def as_dict(self) -> dict:
        return {"entry_time_s": self.time, "entry_point_m": [float(v) for v in self.point],
                "entry_speed_m_s": self.speed, "entry_angle_deg": self.angle,
                "entry_velocity_angle_deg": self.velocity_angle, "leading_segment": self.leading}


def body_angles(origins, velocity):
    """(deg from straight down of the toe-to-wrist axis, deg between it and velocity) for
    segment frame origins (17,3) m and the centre of mass's velocity (3,) m/s."""
    axis = origins[list(WRISTS)].mean(axis=0) - origins[list(TOES)].mean(axis=0)
    axis = axis / np.linalg.norm(axis)
    down = math.degrees(math.acos(float(np.clip(-axis[2], -1.0, 1.0))))
    u = velocity / max(float(np.linalg.norm(velocity)), 1e-12)
    return down, math.degrees(math.acos(float(np.clip(axis @ u, -1.0, 1.0))))


def entry_from(fig: Figure, level: float) -> Entry:
    """The entry measured on a live figure at the step its lowest point reached ``level``."""
    view = fig.contact_view()
    origins = view.poses()[0]
    vel = fig.momentum() / fig.mass
    low = int(np.argmin(view.centres()[:, 2]))
    down, along = body_angles(origins, vel)
    ahead = origins[list(WRISTS), 0].mean() - origins[list(TOES), 0].mean()
    return Entry(fig.time, view.centres()[low].copy(), float(np.linalg.norm(vel)), down, along,
                 SEGMENTS[low], -down if ahead > 0 else down)


@dataclass
class Trial:
    """A dive flown against still water: entry (None if he never reached the water);
    touched: s of platform contact after take-off; deepest: lowest point (m) reached; rest:
    the centre of mass's speed (m/s) when it was deepest."""
    entry: Entry | None
    touched: float
    deepest: float
    com_speed_at_deepest: float


def fly(fig: Figure, standin, level: float, duration: float, h: float = 2e-3,
        underwater: float = 0.0) -> Trial:
    """Fly a diver (his own pass, as the scheduler runs it: forces cleared, the stand-in
    acting, a coupling step of h s) until ``underwater`` s after his lowest point reaches
    ``level`` (m) or ``duration`` s."""
    entry, touched, deepest, speed, stop = None, 0.0, math.inf, 0.0, duration
    flying = False
    while fig.time < stop - 1e-9:
        fig.clear_forces()
        if standin is not None:
            standin.act(fig)
        fig.advance(h)
        flying = flying or fig.fsm.state.name in ("reach", "pike", "open")
        if flying and entry is None and fig.data.ncon:
            touched += h
        z = fig.lowest_z()
        if entry is None and z < level:
            entry = entry_from(fig, level)
            stop = min(duration, fig.time + underwater)
        if z < deepest:
            deepest, speed = z, float(np.linalg.norm(fig.momentum())) / fig.mass
    return Trial(entry, touched, deepest, speed)


# --- the search (``python -m interplay.control.dive``) ------------------------------------------
BOUNDS = {"lean": (0.0, 0.8), "lead": (0.0, 0.3), "hip": (-0.2, 1.4), "power": (0.5, 2.0),
          "arm_swing": (1.0, 3.0), "reach": (0.0, 0.5), "pike": (1.2, 2.1),
          "open": (1.5, 3.1), "spot": (0.0, 0.6)}
CLEAR = 1.0  # m: the entry at least this far past the platform's edge
NO_ENTRY = 60.0  # the loss of a dive that never reaches the water
NUDGES = ((), (("lean", -0.015),), (("lean", 0.015),), (("lead", -0.01),), (("lead", 0.01),),
          (("power", -0.03),), (("power", 0.03),))


def dive_loss(trial: Trial, edge: float) -> float:
    """What the search minimises: the entry's angle from vertical and its misalignment with
    the flight path (each in units of 10 deg), 2 if the hands do not lead, twice the shortfall
    of the entry's distance past the edge below CLEAR (m), 50 per second of platform contact
    after take-off (at most 20); NO_ENTRY if he never reaches the water, more than any dive
    that does."""
    e = trial.entry
    if e is None:
        return NO_ENTRY
    return (e.angle / 10.0 + 0.5 * e.velocity_angle / 10.0 + (0.0 if e.hands_first else 2.0)
            + 2.0 * max(0.0, CLEAR - (e.point[0] - edge)) + min(50.0 * trial.touched, 20.0))


def nudged_loss(make, p: DiveParams, edge: float, level: float, duration: float = 5.0) -> float:
    """dive_loss averaged over the dive p and its NUDGES, each flown in air to the water (no
    stand-in is needed before the entry), so the optimum is not a knife edge. make(p) ->
    Figure builds the diver on his platform."""
    total = 0.0
    for nudge in NUDGES:
        q = replace(p, **{k: getattr(p, k) + dv for k, dv in nudge})
        total += dive_loss(fly(make(q), None, level, duration), edge)
    return total / len(NUDGES)
