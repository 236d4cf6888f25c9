"""Systems without motion of their own: the floor, colliders, set pieces and fields that are
functions of time. They take part in interactions but are never stepped or recorded
(Role.STATIC)."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
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
    """The plane z = height (m), infinitely massive; normal +z. As drawn: the square of
    half-extent size (m) about the origin, or the rectangle extent = (x0, x1, y0, y1) m (a
    road along a path); drawn=False: a collider only (another shape draws that surface);
    color (linear RGB 0..1) and material (systems/shape.py) as drawn."""

    def __init__(self, name="ground", height=0.0, size=10.0, extent=None, drawn=True,
                 color=None, material="ground"):
        super().__init__(name)
        self.height = float(height)
        self.size = float(size)
        if extent is None:
            extent = (-self.size, self.size, -self.size, self.size)
        x0, x1, y0, y1 = (float(e) for e in extent)
        if not (x1 > x0 and y1 > y0):
            raise ParameterError(f"{name}: extent (x0, x1, y0, y1) = {tuple(extent)} m must "
                                 "have x1 > x0 and y1 > y0")
        self.extent = (x0, x1, y0, y1)
        self.drawn, self.color, self.material = bool(drawn), color, material
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
        x0, x1, y0, y1 = self.extent
        z = self.height
        v = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])
        return v, np.array([[0, 1, 2], [0, 2, 3]])

    def shapes(self):
        if not self.drawn:
            return []
        v, t = self.surface()
        return [Shape(self.name, "static", color=self.color, verts=v, tris=t, palette="static",
                      material=self.material)]
