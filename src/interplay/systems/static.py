"""Immovable colliders (the floor). They take part in interactions but never move or record."""
from __future__ import annotations

import numpy as np

from .base import System


class StaticPlane(System):
    """The plane z = height (m), infinitely massive; normal +z."""

    kind = "static"
    dynamic = False

    def __init__(self, name="ground", height=0.0, size=10.0):
        super().__init__(name, dt=1.0)  # never stepped
        self.height = float(height)
        self.size = float(size)  # m, half-extent used only for drawing

    @property
    def mass(self):
        return np.inf

    def step(self, h):
        pass

    def generalized_state(self):
        return np.zeros(0), np.zeros(0)

    def set_generalized_state(self, x, xdot):
        pass

    def frame(self):
        return {}

    def surface(self):
        s, z = self.size, self.height
        v = np.array([[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]])
        return v, np.array([[0, 1, 2], [0, 2, 3]])
