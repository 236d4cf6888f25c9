"""Systems without motion of their own: the floor, colliders, set pieces and fields that are
functions of time. They take part in interactions but are never stepped or recorded
(Role.STATIC)."""
from __future__ import annotations

import numpy as np

from .base import Role, System
from .shape import Shape
from .views import ShapeView


class Stateless(System):
    """Base of static systems: infinitely massive, no generalized state, empty frames; the
    scheduler never steps them."""

    role = Role.STATIC

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
    """The plane z = height (m), infinitely massive; normal +z. size (m): its half-extent as
    drawn."""

    def __init__(self, name="ground", height=0.0, size=10.0):
        super().__init__(name)
        self.height = float(height)
        self.size = float(size)
        self._view = ShapeView(self, self.distance, height=self.height)

    def distance(self, points):
        """Signed distance (n,) m above the plane and the normals (n,3) (all +z)."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        n = np.zeros_like(p)
        n[:, 2] = 1.0
        return p[:, 2] - self.height, n

    def contact_view(self):
        return self._view

    def surface(self):
        s, z = self.size, self.height
        v = np.array([[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]])
        return v, np.array([[0, 1, 2], [0, 2, 3]])

    def shapes(self):
        v, t = self.surface()
        return [Shape(self.name, "static", verts=v, tris=t, palette="static")]
