"""Kinematic motion along a path: a prop (the bicyclist) that follows timed waypoints and
ignores forces, and the ``Path`` itself, which wind primitives can ride along with it."""
from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, require_positive
from .base import Role, System
from .shape import Shape
from .views import BodiesView, RigidParts


class Path:
    """Timed waypoints: times (k,) s, strictly increasing; points (k,3) m. Positions follow a
    monotone cubic Hermite curve (PCHIP: velocity continuous, no overshoot); before the first
    time and after the last the path holds still. The heading is the direction of travel in
    the horizontal plane (yaw about +z, rad)."""

    def __init__(self, times, points, name="path"):
        from scipy.interpolate import PchipInterpolator
        t = np.asarray(times, dtype=float)
        p = np.asarray(points, dtype=float)
        if t.ndim != 1 or len(t) < 2 or not np.all(np.isfinite(t)) or not np.all(np.diff(t) > 0):
            raise ParameterError(f"{name}: needs at least 2 strictly increasing times, got "
                                 f"{tuple(np.ravel(times))}")
        if p.size != 3 * len(t) or not np.all(np.isfinite(p)):
            raise ParameterError(f"{name}: points must hold x, y, z for each of the {len(t)} "
                                 f"times ({3 * len(t)} numbers), got {p.size}")
        self.t0, self.t1 = float(t[0]), float(t[-1])
        self._pos = PchipInterpolator(t, p.reshape(-1, 3), axis=0)
        self._vel = self._pos.derivative()

    def position(self, t: float) -> np.ndarray:
        return self._pos(min(max(t, self.t0), self.t1))

    def velocity(self, t: float) -> np.ndarray:
        return self._vel(t) if self.t0 < t < self.t1 else np.zeros(3)

    def yaw(self, t: float) -> float:
        # the end tangents give the heading while the path holds still
        d = self._vel(min(max(t, self.t0), self.t1))
        return math.atan2(d[1], d[0]) if d[0] * d[0] + d[1] * d[1] > 0.0 else 0.0

    def frame(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(origin (3,) m, rotation (3,3) path frame to world: x forward, z up) at time t."""
        c, s = math.cos(self.yaw(t)), math.sin(self.yaw(t))
        return self.position(t), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class PathFollower(System, RigidParts):
    """A rigid mesh carried along a ``Path`` (x forward along the direction of travel).

    vertices (n,3) m in the body frame and triangles (m,3); mass (kg) is what the analysis
    divides forces by; dt (s) its output step (the motion is a function of time: any step is
    exact). Forces are ignored. Generalized state: (x, y, z, yaw) and its rate. Its contact view:
    one prescribed part, its mesh."""

    role = Role.PRESCRIBED
    integrator = "path (monotone cubic Hermite)"

    def __init__(self, name, path: Path, vertices, triangles, mass=80.0, dt=1.0 / 60.0):
        super().__init__(name, dt)
        self.path = path
        self.body = np.asarray(vertices, dtype=float)
        self.triangles = np.asarray(triangles, dtype=np.int64)
        self._mass = require_positive(name, "mass", mass, "kg")
        self.q = np.zeros(4)
        self.qd = np.zeros(4)
        self._place(0.0)
        self.color = None
        self._view = BodiesView(self, [name], [(self.body, self.triangles)], [None], [np.inf],
                                movable=False)

    def _place(self, t):
        self.q[:3] = self.path.position(t)
        self.q[3] = self.path.yaw(t)
        self.qd[:3] = self.path.velocity(t)
        self.qd[3] = 0.0  # heading rate is not needed by anything downstream

    @property
    def mass(self):
        return self._mass

    def step(self, h):
        self.time += h
        self._place(self.time)

    def advance(self, h, dt=None):
        self.step(h)

    def _rotation(self):
        c, s = math.cos(self.q[3]), math.sin(self.q[3])
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def points(self) -> np.ndarray:
        """The mesh's vertices in the world (m)."""
        return self.body @ self._rotation().T + self.q[:3]

    def contact_view(self):
        return self._view

    def part_poses(self):
        return self.q[None, :3], self._rotation()[None]

    def part_centres(self):
        return self.q[None, :3]

    def part_velocities(self, parts=None):
        k = 1 if parts is None else len(parts)
        return np.repeat(self.qd[None, :3], k, axis=0), np.zeros((k, 3))

    def centre_of_mass(self):
        return self.q[:3]

    def shapes(self):
        return [Shape(self.name, "surface", color=self.color, triangles=self.triangles,
                      palette="other")]

    def lowest_z(self):
        return float(self.points()[:, 2].min())

    def kinetic_energy(self):
        return 0.5 * self._mass * float(self.qd[:3] @ self.qd[:3])

    def momentum(self):
        return self._mass * self.qd[:3].copy()

    def generalized_state(self):
        return self.q, self.qd

    def set_generalized_state(self, x, xdot):
        self.q[:] = x
        self.qd[:] = xdot

    def frame(self):
        return {"points": self.points()}
