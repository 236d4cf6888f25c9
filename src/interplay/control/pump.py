"""Pumping a swing from the seated position: a two-state controller switched by the sign of
the swing's angular velocity.

On the forward swing she leans back and stretches her legs out; on the backward swing she
sits up and tucks her legs under the seat. The mechanism (Case & Swanson, "The pumping of a
swing from the seated position", Am. J. Phys. 58, 463 (1990); Wirkus, Rand & Ruina, "How to
pump a swing", College Math. J. 29, 266 (1998)): rotating her body against the chains, which
her hands hold and her seat turns with, is a torque between her and the swing; its reaction
drives the swing as an oscillator forced at its own frequency, the switch at each end of the
swing putting the forcing in phase with the motion. (Her centre of mass also moves along the
chains twice a cycle, a small parametric part.) Air drag on her body, which grows as the
square of the speed, against a forcing whose work per cycle grows only with the amplitude,
sets the steady swing.

It is a Figure ``feedback``: the offsets it returns are added to the seated pose's targets
at every control tick, blended between the two poses at a finite rate (a child takes a few
tenths of a second to lean back), so the servo reference never jumps.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..params import param
from .fsm import pose_vector

#: lean back with the legs out (rad), relative to the seated pose (systems/swing.SEATED):
#: the hips open so the trunk tips back on the seat, the knees straighten, the arms straighten
#: up the chains as the shoulders go back (the trunk ends ~0.95 rad behind the chains); her
#: hands on the chains at her chest turn her against them
LEAN = (("hip_flex", -0.18), ("knee", -0.6), ("shoulder_flex", 0.8), ("elbow", -1.0))
#: sit up with the legs tucked under the seat: the trunk forward, the knees bent back, the
#: elbows bent as the hands come to the chest
TUCK = (("hip_flex", 0.09), ("knee", 0.27), ("shoulder_flex", -0.03), ("elbow", 0.15))


@dataclass(frozen=True)
class PumpParams:
    """enabled: pump (false: she sits still, the swing a passive compound pendulum);
    blend (s): the time to move from one pose to the other; scale (-): how far into each
    pose she goes (1: LEAN and TUCK in full); deadband (rad/s): the swing's rate below which
    she holds her pose (near rest a sign change would be noise)."""
    enabled: bool = param(True, doc="false: she sits still")
    blend: float = param(0.35, "s", gt=0.0, le=5.0)
    scale: float = param(1.0, "-", ge=0.0, le=1.5)
    deadband: float = param(0.005, "rad/s", ge=0.0, le=1.0)


class Pump:
    """The pumping feedback for a SwingFigure: offsets(figure, sensors) -> (joints,) rad."""

    def __init__(self, p: PumpParams, joints):
        if p.blend <= 0:
            raise ParameterError(f"pump: blend {p.blend} s must be > 0 (the time she takes "
                                 "from one pose to the other), e.g. 0.35")
        self.p = p
        self.tuck = p.scale * pose_vector(TUCK, joints)
        self.delta = p.scale * pose_vector(LEAN, joints) - self.tuck  # lean minus tuck
        self.s = 0.0  # 0 tucked .. 1 leaning back
        self.leaning = False

    def offsets(self, figure, sensors) -> np.ndarray:
        if not self.p.enabled:
            return np.zeros(len(self.delta))
        w = figure.swing_rate()
        if abs(w) > self.p.deadband and (w > 0) != self.leaning:
            self.leaning = w > 0
        step = figure.control_dt / self.p.blend
        self.s = float(np.clip(self.s + (step if self.leaning else -step), 0.0, 1.0))
        u = 3 * self.s ** 2 - 2 * self.s ** 3  # smoothstep: no kick at either end
        return self.tuck + u * self.delta

    def capture(self) -> dict:
        return {"s": np.array([self.s, float(self.leaning)])}

    def restore(self, snap):
        self.s, self.leaning = float(snap["s"][0]), bool(snap["s"][1])
