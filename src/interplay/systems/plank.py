"""A plank hinged at one end that drops: the plank of the short's bridge (after Bierce), laid
out over the gap between two ties with the condemned standing on its far end, held level until
it is let go and then swinging down about its hinge under its own weight.

A uniform plank of length L about an end: I = m L^2 / 3, torque m g (L/2) cos(theta), so
theta'' = 3 g cos(theta) / (2 L) - c theta' (theta down from level, c the hinge's friction).
A point at distance r from the hinge starts down at 3 g r / (2 L): faster than free fall for
r > 2 L / 3, so someone standing out there is not carried down but left in the air at once,
which is why the figure's own support can simply vanish at the release (EnvironmentParams
``opens``). Nothing acts back on the plank: it is a set piece that moves.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..geometry.setpieces import box
from ..params import param
from .base import System
from .shape import Shape

GRAVITY = 9.81  # m/s^2


@dataclass(frozen=True)
class PlankParams:
    """hinge (m): the middle of the hinged end's bottom edge; heading (rad about +z): the
    direction from the hinge to the free end; length, width, thickness (m); mass (kg); opens
    (s): the time it is let go; friction (1/s): the hinge's (the plank comes to hang);
    dt (s): its step."""
    hinge: tuple = param((0.0, 0.0, 0.0), "m", ge=-1e4, le=1e4)
    heading: float = param(0.0, "rad", ge=-10.0, le=10.0)
    length: float = param(2.0, "m", gt=0.0, le=100.0)
    width: float = param(0.3, "m", gt=0.0, le=10.0)
    thickness: float = param(0.05, "m", gt=0.0, le=1.0)
    mass: float = param(12.0, "kg", gt=0.0, le=1e4)
    opens: float = param(1.0, "s", ge=0.0, le=1e5)
    friction: float = param(1.5, "1/s", ge=0.0, le=1e3)
    dt: float = param(1e-3, "s", gt=0.0, le=0.1)


class HingedPlank(System):
    """The plank's angle theta (rad, down from level) and its rate; level until ``opens``."""

    integrator = "hinged rigid plank, semi-implicit Euler"

    def __init__(self, name: str, p: PlankParams = PlankParams(), color=(0.42, 0.30, 0.18)):
        super().__init__(name, p.dt)
        self.p = p
        self.theta, self.omega = 0.0, 0.0
        self.color = color
        self.hinge = np.asarray(p.hinge, float)
        self._mesh = box([0.0, -0.5 * p.width, 0.0], [p.length, 0.5 * p.width, p.thickness])

    @property
    def mass(self) -> float:
        return float(self.p.mass)

    def step(self, h):
        """One substep (the coupling step's start time decides whether it is let go yet)."""
        p = self.p
        if self.time < p.opens:
            return
        alpha = 1.5 * GRAVITY * math.cos(self.theta) / p.length - p.friction * self.omega
        self.omega += h * alpha
        self.theta += h * self.omega

    def rotation(self) -> np.ndarray:
        """Body frame (x along the plank from the hinge, z up when level) to world."""
        c, s = math.cos(self.p.heading), math.sin(self.p.heading)
        yaw = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        ct, st = math.cos(self.theta), math.sin(self.theta)
        pitch = np.array([[ct, 0.0, st], [0.0, 1.0, 0.0], [-st, 0.0, ct]])  # x goes down
        return yaw @ pitch

    def quaternion(self) -> np.ndarray:
        """(w, x, y, z) of ``rotation()``: the yaw about z after the pitch about y."""
        cy, sy = math.cos(0.5 * self.p.heading), math.sin(0.5 * self.p.heading)
        cp, sp = math.cos(0.5 * self.theta), math.sin(0.5 * self.theta)
        return np.array([cy * cp, -sy * sp, cy * sp, sy * cp])

    def kinetic_energy(self) -> float:
        return 0.5 * self.p.mass * self.p.length ** 2 / 3.0 * self.omega ** 2

    def lowest_z(self) -> float:
        v = self._mesh[0] @ self.rotation().T + self.hinge
        return float(v[:, 2].min())

    def shapes(self):
        v, t = self._mesh
        return [Shape(self.name, "body", color=self.color, verts=v, tris=t, palette="rigid",
                      material="wood")]

    def generalized_state(self):
        return np.array([self.theta]), np.array([self.omega])

    def set_generalized_state(self, x, xdot):
        self.theta, self.omega = float(x[0]), float(xdot[0])

    def frame(self):
        return {"position": self.hinge.copy(), "orientation": self.quaternion()}

    def capture(self):
        return {"time": np.array(self.time), "state": np.array([self.theta, self.omega])}

    def restore(self, snap):
        self.time = float(snap["time"])
        self.theta, self.omega = (float(v) for v in snap["state"])
