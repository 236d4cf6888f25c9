"""State-machine controllers, as data (frozen dataclasses a scene file can hold).

A ``Controller`` is a set of ``State``s and a start state. Each state names desired joint angles
(rad) and velocities (rad/s) for some joints (the rest keep their previous targets), the servo
frequency w (rad/s) and damping ratio of any joints it retunes, whether the legs carry the body
(``support``: leg gains then use the supported inertia), centre-of-mass balance gains, entry
actions, and transitions fired by sensor events.

Joint keys: a joint name (``l_knee``), a name without its side for both sides (``knee``,
``hip_flex``), or a prefix for a group (``hip``, ``l_``, ``shoulder``).

Events (``Transition.on``), each with its ``value``:
  ``time``            seconds spent in the state >= value
  ``foot_contact`` / ``no_foot_contact``   a foot or toe touches the environment, or none does
  ``hand_contact``    a hand touches the environment
  ``com_falling`` / ``com_rising``         the centre of mass's vertical velocity is < 0 / > 0
  ``com_below`` / ``com_above``            the centre of mass's height (m) is below / above value
  ``com_ahead``       the centre of mass is more than value (m) ahead of the middle of the feet,
                      along the pelvis's facing direction (a lean far enough to dive)
  ``pitch_above``     the trunk has turned forward more than value (rad) from upright, about
                      the figure's starting left-right axis, or will have within the
                      transition's ``lookahead`` (s) at its present rate (a diver spotting
                      the water: the faster he turns, the sooner he opens)
Entry actions: ``hold_pose`` (every target becomes the current angle before the state's pose
applies), ``neutral`` (every target becomes 0, the rest pose).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

EVENTS = ("time", "foot_contact", "no_foot_contact", "hand_contact", "com_falling",
          "com_rising", "com_below", "com_above", "com_ahead", "pitch_above")
ENTRY_ACTIONS = ("hold_pose", "neutral")


@dataclass(frozen=True)
class Transition:
    """Go to state ``to`` when event ``on`` happens (with threshold ``value``; ``lookahead``
    (s) for pitch_above)."""
    on: str
    to: str
    value: float = 0.0
    lookahead: float = 0.0


@dataclass(frozen=True)
class State:
    """pose / velocity: ((joint key, rad or rad/s), ...); gains: ((joint key, w rad/s), ...);
    zeta: damping ratio of the retuned joints; support: the legs carry the body; balance:
    (kp rad/m, kd rad s/m) feedback of the centre of mass's offset from the support polygon's
    centre onto the ankles and hips, () for none."""
    name: str
    pose: tuple = ()
    velocity: tuple = ()
    gains: tuple = ()
    zeta: float | None = None
    support: bool = False
    balance: tuple = ()
    entry: tuple = ()
    transitions: tuple = ()
    blend: float = 0.2  # s


@dataclass(frozen=True)
class Controller:
    """A state machine: its states and the name of the first."""
    states: tuple = ()
    start: str = ""


def resolve(key: str, names: list[str]) -> np.ndarray:
    """Indices of the joints a key names (see the module docstring)."""
    hits = [i for i, n in enumerate(names)
            if n == key or n in (f"l_{key}", f"r_{key}") or n.startswith(key + "_")
            or n.startswith(f"l_{key}_") or n.startswith(f"r_{key}_")
            or (key.endswith("_") and n.startswith(key))]
    if not hits:
        raise ParameterError(f"controller: joint key {key!r} names no joint; joints are "
                             f"{', '.join(names)}")
    return np.array(hits, dtype=np.int64)


def pose_vector(pairs, names) -> np.ndarray:
    """Joint values (rad) of a pose given as (joint key, value) pairs, as a state's pose is:
    one per joint in ``names``, 0 for joints the pose leaves out."""
    q = np.zeros(len(names))
    idx, val = _pairs(pairs, list(names), "pose", "pose")
    q[idx] = val
    return q


@dataclass
class _Compiled:
    name: str
    pose_idx: np.ndarray
    pose_val: np.ndarray
    vel_idx: np.ndarray
    vel_val: np.ndarray
    gain_idx: np.ndarray
    gain_val: np.ndarray
    zeta: float | None
    support: bool
    balance: tuple
    entry: tuple
    transitions: list  # (event, value, target index, lookahead s)
    blend: float


def _pairs(pairs, names, what, state):
    idx, val = [], []
    for item in pairs:
        if len(item) != 2:
            raise ParameterError(f"controller state {state!r}: {what} entries are (joint, "
                                 f"value) pairs, got {item!r}")
        key, v = item
        ii = resolve(key, names)
        idx.append(ii)
        val.append(np.full(len(ii), float(v)))
    if not idx:
        return np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(idx), np.concatenate(val)


class StateMachine:
    """A controller bound to a figure's joint names; ``update`` runs one control tick."""

    def __init__(self, controller: Controller, names: list[str]):
        states = controller.states
        if not states:
            raise ParameterError("controller: needs at least one state")
        index = {s.name: i for i, s in enumerate(states)}
        if len(index) != len(states):
            raise ParameterError("controller: state names must be unique")
        start = controller.start or states[0].name
        if start not in index:
            raise ParameterError(f"controller: start state {start!r} is not one of "
                                 f"{', '.join(index)}")
        self.states = []
        for s in states:
            for a in s.entry:
                if a not in ENTRY_ACTIONS:
                    raise ParameterError(f"controller state {s.name!r}: unknown entry action "
                                         f"{a!r}; choose from {', '.join(ENTRY_ACTIONS)}")
            if s.balance and len(s.balance) != 2:
                raise ParameterError(f"controller state {s.name!r}: balance is (kp rad/m, kd "
                                     f"rad s/m), got {s.balance!r}")
            trans = []
            for t in s.transitions:
                if t.on not in EVENTS:
                    raise ParameterError(f"controller state {s.name!r}: unknown event "
                                         f"{t.on!r}; choose from {', '.join(EVENTS)}")
                if t.to not in index:
                    raise ParameterError(f"controller state {s.name!r}: transition to unknown "
                                         f"state {t.to!r}")
                trans.append((t.on, float(t.value), index[t.to], float(t.lookahead)))
            self.states.append(_Compiled(
                s.name, *_pairs(s.pose, names, "pose", s.name),
                *_pairs(s.velocity, names, "velocity", s.name),
                *_pairs(s.gains, names, "gains", s.name), s.zeta, s.support,
                tuple(float(b) for b in s.balance), tuple(s.entry), trans,
                max(float(s.blend), 0.0)))
        self.names = names
        self.start = index[start]
        self.current = self.start
        self.entered = 0.0

    @property
    def state(self) -> _Compiled:
        return self.states[self.current]

    def fired(self, time: float, sensors: dict) -> int | None:
        """The index of the state the first firing transition leads to, or None."""
        for event, value, target, lookahead in self.state.transitions:
            if event == "time":
                hit = time - self.entered >= value - 1e-9
            elif event == "foot_contact":
                hit = sensors["foot_contact"]
            elif event == "no_foot_contact":
                hit = not sensors["foot_contact"]
            elif event == "hand_contact":
                hit = sensors["hand_contact"]
            elif event == "com_falling":
                hit = sensors["com_vel"][2] < 0.0
            elif event == "com_rising":
                hit = sensors["com_vel"][2] > 0.0
            elif event == "com_below":
                hit = sensors["com"][2] < value
            elif event == "com_ahead":
                hit = sensors["com_ahead"] > value
            elif event == "pitch_above":
                hit = sensors["pitch"] + lookahead * sensors["pitch_rate"] > value
            else:  # com_above
                hit = sensors["com"][2] > value
            if hit:
                return target
        return None

    def enter(self, index: int, time: float, targets: np.ndarray, vtargets: np.ndarray,
              angles: np.ndarray, omega: np.ndarray, zeta: np.ndarray, omega_default: float,
              zeta_default: float):
        """Switch to state ``index``: run its entry actions and write its targets and gains
        into the figure's arrays (in place); joints the state does not retune return to the
        default frequency and damping ratio."""
        self.current, self.entered = index, time
        s = self.state
        if "hold_pose" in s.entry:
            targets[:] = angles
        if "neutral" in s.entry:
            targets[:] = 0.0
        vtargets[:] = 0.0
        targets[s.pose_idx] = s.pose_val
        vtargets[s.vel_idx] = s.vel_val
        omega[:] = omega_default
        zeta[:] = zeta_default
        omega[s.gain_idx] = s.gain_val
        if s.zeta is not None:
            zeta[s.gain_idx] = s.zeta
