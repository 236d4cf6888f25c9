"""Reusable behaviours: each returns a ``State`` (control/fsm.py) a controller strings together.

Angles are in rad, in the anatomical sense of each joint (flexion positive; ankle flexion is
dorsiflexion, toes up). ``next`` names the state a behaviour hands over to; ``after`` (s) is how
long timed behaviours last.
"""
from __future__ import annotations

from .fsm import State, Transition

STANCE_BALANCE = (0.5, 0.2)  # rad/m, rad s/m: centre-of-mass feedback while standing


def stand(name="stand", next=None, after=1.0, balance=STANCE_BALANCE, blend=0.6) -> State:
    """Upright on both feet, knees soft, centre of mass kept over the feet; ``blend`` (s) is
    how long rising into it takes (from a crouch: quicker is a hop)."""
    trans = (Transition("time", next, after),) if next else ()
    return State(name, pose=(("hip", 0.0), ("knee", 0.05), ("ankle", 0.0), ("waist", 0.0),
                             ("neck", 0.0), ("shoulder", 0.0), ("elbow", 0.1), ("wrist", 0.0),
                             ("toe", 0.0)),
                 support=True, balance=balance, transitions=trans, blend=blend)


def crouch(name="crouch", next=None, after=0.6, depth=1.0, lean=0.3) -> State:
    """Bend hips, knees and ankles (depth scales the bend, 1 = a deep preparatory crouch) and
    pitch the trunk forward by ``lean`` (rad); arms swing back."""
    trans = (Transition("time", next, after),) if next else ()
    return State(name, pose=(("hip_flex", 0.8 * depth + lean), ("knee", 1.3 * depth),
                             ("ankle", 0.45 * depth), ("waist_flex", 0.3 * depth),
                             ("shoulder_flex", -0.6), ("elbow", 0.3)),
                 support=True, balance=STANCE_BALANCE, transitions=trans, blend=0.5 * after)


def tip(name="tip", next=None, ankle=0.0, lead=0.0, after=1.5) -> State:
    """Lean out over the toes on the feet (``ankle`` rad): hands over when the centre of mass
    is ``lead`` m ahead of them, or after ``after`` s even if the lean never gets that far."""
    return State(name, pose=(("ankle", ankle),), support=True, blend=0.1,
                 transitions=(Transition("com_ahead", next, lead),
                              Transition("time", next, after)))


def leap(name="leap", next=None, after=0.35, power=1.0, arm_swing=2.6, hip=-0.1) -> State:
    """Extend hips (to ``hip`` rad of flexion: below 0 a vertical jump, above 0 a forward
    dive), knees and ankles together (a timed push, velocity targets scaled by power) while the
    arms swing forward and up to ``arm_swing`` (rad); hands over when both feet leave the
    ground, or after ``after`` s."""
    trans = ((Transition("no_foot_contact", next), Transition("time", next, after))
             if next else ())
    return State(name, pose=(("hip_flex", hip), ("knee", 0.0), ("ankle", -0.6),
                             ("waist_flex", 0.0), ("shoulder_flex", arm_swing), ("elbow", 0.0),
                             ("toe", 0.3)),
                 velocity=(("hip_flex", -8.0 * power), ("knee", -12.0 * power),
                           ("ankle", -8.0 * power), ("shoulder_flex", 10.0)),
                 gains=(("hip", 30.0), ("knee", 30.0), ("ankle", 30.0)),
                 support=True, transitions=trans, blend=0.0)


def layout(name="layout", next=None, after=None, arms=3.0) -> State:
    """Straight body in flight, toes pointed, arms overhead (``arms`` rad of shoulder flexion)."""
    trans = (Transition("time", next, after),) if next and after else ()
    return State(name, pose=(("hip", 0.0), ("knee", 0.0), ("ankle", -0.6), ("waist", 0.0),
                             ("shoulder_flex", arms), ("shoulder_abd", 0.2), ("elbow", 0.0),
                             ("toe", 0.0)),
                 support=False, transitions=trans)


def tuck(name="tuck", next=None, after=None) -> State:
    """Knees to the chest, hands on the shins."""
    trans = (Transition("time", next, after),) if next and after else ()
    return State(name, pose=(("hip_flex", 2.0), ("knee", 2.2), ("ankle", -0.3),
                             ("waist_flex", 0.4), ("shoulder_flex", 0.6), ("elbow", 1.4)),
                 support=False, transitions=trans)


def pike(name="pike", next=None, after=None) -> State:
    """Legs straight, folded at the hips, arms reaching for the toes."""
    trans = (Transition("time", next, after),) if next and after else ()
    return State(name, pose=(("hip_flex", 1.9), ("knee", 0.0), ("ankle", -0.5),
                             ("waist_flex", 0.3), ("shoulder_flex", 1.6), ("elbow", 0.0)),
                 support=False, transitions=trans)


def land(name="land", next=None, after=0.6, softness=0.35) -> State:
    """Absorb a landing: legs bend and their servos soften to ``softness`` of the default
    frequency (a compliant spring-damper of the same damping ratio); hands over after
    ``after`` s."""
    trans = (Transition("time", next, after),) if next else ()
    w = 20.0 * softness
    return State(name, pose=(("hip_flex", 0.6), ("knee", 1.0), ("ankle", 0.35),
                             ("shoulder_flex", 0.6), ("elbow", 0.3)),
                 gains=(("hip", w), ("knee", w), ("ankle", w)), support=True,
                 entry=("hold_pose",), transitions=trans)
