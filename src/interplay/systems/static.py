"""Systems without state of their own: the floor and other immovable colliders, fields that
are functions of time. They take part in interactions but are never stepped or recorded."""
from __future__ import annotations

import numpy as np

from .base import System


class Stateless(System):
    """Base of stateless systems: infinitely massive, no generalized state, empty frames; the
    scheduler never steps them (dynamic = False)."""

    kind = "static"
    dynamic = False

    def __init__(self, name):
        super().__init__(name, dt=1.0)  # never stepped: the step is irrelevant

    @property
    def mass(self):
        return np.inf

    def step(self, h):
        self.time += h

    def generalized_state(self):
        return np.zeros(0), np.zeros(0)

    def set_generalized_state(self, x, xdot):
        pass

    def frame(self):
        return {}


class StaticPlane(Stateless):
    """The plane z = height (m), infinitely massive; normal +z."""

    def __init__(self, name="ground", height=0.0, size=10.0):
        super().__init__(name)
        self.height = float(height)
        self.size = float(size)  # m, half-extent used only for drawing

    def surface(self):
        s, z = self.size, self.height
        v = np.array([[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]])
        return v, np.array([[0, 1, 2], [0, 2, 3]])
