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


class Prop:
    """A rig of one rigid part: vertices (n,3) m and triangles (m,3) in the frame of travel
    (x forward, z up), that a PathFollower carries unchanged. color: linear RGB."""

    PART_NAMES = ("body",)
    PARENTS = (-1,)

    def __init__(self, vertices, triangles, color=(0.55, 0.55, 0.57)):
        self.parts = [(np.asarray(vertices, float), np.asarray(triangles, np.int64))]
        self.COLORS = (tuple(color),)

    def pose(self, s: float):
        return np.zeros((1, 3)), np.eye(3)[None]

    def mesh(self):
        return self.parts[0]


class PathFollower(System, RigidParts):
    """A rig of rigid parts carried along a ``Path`` (x forward along the direction of travel).

    rig: what it carries, with ``parts`` [(vertices (n,3) m, triangles)] in their own frames,
    ``PART_NAMES``, ``PARENTS``, ``COLORS`` and ``pose(s) -> (origins (k,3) m, rotations
    (k,3,3))`` in the rig's frame after s (m) travelled (geometry/bicycle.py: wheels turn,
    legs pedal); ``mesh()`` the whole rig at rest. mass (kg) is what the analysis divides
    forces by; dt (s) its output step (the motion is a function of time: any step is exact).
    Forces are ignored. Generalized state: (x, y, z, yaw) and its rate. Its contact view: one
    prescribed part, the whole rig at rest."""

    role = Role.PRESCRIBED
    integrator = "path (monotone cubic Hermite)"

    def __init__(self, name, path: Path, rig, mass=80.0, dt=1.0 / 60.0):
        super().__init__(name, dt)
        self.path, self.rig = path, rig
        body, tris = rig.mesh()
        self._mass = require_positive(name, "mass", mass, "kg")
        # distance travelled (m) against time: the path's speed integrated on a fine grid
        ts = np.linspace(path.t0, path.t1, 2001)
        speed = np.linalg.norm(np.array([path.velocity(t) for t in ts]), axis=1)
        self._dist = (ts, np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1])
                                                           * np.diff(ts))]))
        self.q = np.zeros(4)
        self.qd = np.zeros(4)
        self._place(0.0)
        self._view = BodiesView(self, [name], [(body, tris)], [None], [np.inf], movable=False)

    def _place(self, t):
        self.q[:3] = self.path.position(t)
        self.q[3] = self.path.yaw(t)
        self.qd[:3] = self.path.velocity(t)
        self.qd[3] = 0.0  # heading rate is not needed by anything downstream

    def distance(self, t: float) -> float:
        """Distance (m) travelled along the path by time t (s)."""
        return float(np.interp(t, *self._dist))

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
        rig = self.rig
        return [Shape(self.name, "parts", color=tuple(np.mean(rig.COLORS, axis=0)),
                      parts=[(np.asarray(v, float), np.asarray(t, np.int64))
                             for v, t in rig.parts],
                      part_names=rig.PART_NAMES, part_parents=rig.PARENTS,
                      part_colors=np.asarray(rig.COLORS, float), palette="rigid",
                      material="paint")]

    def world_parts(self):
        """(origins (k,3) m, rotations (k,3,3)) of the rig's parts in the world now."""
        pos, rot = self.rig.pose(self.distance(self.time))
        R = self._rotation()
        return pos @ R.T + self.q[:3], np.einsum("ij,kjl->kil", R, rot)

    def lowest_z(self):
        pos, rot = self.world_parts()
        return float(min((v @ r.T + p)[:, 2].min() for (v, _), p, r in
                         zip(self.rig.parts, pos, rot)))

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
        from scipy.spatial.transform import Rotation
        pos, rot = self.world_parts()
        q = Rotation.from_matrix(rot).as_quat()  # x, y, z, w
        return {"segment_positions": pos, "segment_orientations": np.roll(q, 1, axis=1)}
