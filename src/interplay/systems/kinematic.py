"""Animation-driven systems (SPEC 2.3, last point): bodies that follow keyframes and ignore
forces. Nothing pushes back on them, so they are primaries of one-way interactions."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..params import param
from ..geometry.primitive import Primitive
from ..geometry.sphere import icosphere
from .base import Role, System
from .shape import Shape
from .views import BodiesView, RigidParts


@dataclass(frozen=True)
class KeyframedBodyParams:
    """times (s, increasing) and positions (m, flat x, y, z per key) of the body's centre;
    semi_axes (m) of its ellipsoid shape in the body frame (x forward); yaw (rad) about +z;
    mass (kg: what the analysis divides interaction forces by); dt (s): its step (any step is
    exact: the path is a function of time)."""
    times: tuple = param((0.0, 1.0), "s", ge=0.0, le=1e5, length=None,
                         doc="key times, increasing")
    positions: tuple = param((0.0, 0.0, 0.0, 1.0, 0.0, 0.0), "m", ge=-1e4, le=1e4, length=None,
                             doc="x, y, z of each key")
    semi_axes: tuple = param((0.13, 0.05, 0.045), "m", ge=1e-3, le=10.0)
    yaw: float = param(0.0, "rad", ge=-100.0, le=100.0)
    mass: float = param(1.1, "kg", ge=1e-3, le=1e4)
    dt: float = param(0.01, "s", ge=1e-9, le=1.0)

    def __post_init__(self):
        t = self.times
        if len(t) < 2 or any(b <= a for a, b in zip(t, t[1:])):
            raise ParameterError(f"key times must increase strictly (at least 2 keys), got {t}")
        if len(self.positions) != 3 * len(t):
            raise ParameterError(f"positions must hold x, y, z for each of the {len(t)} keys "
                                 f"({3 * len(t)} numbers), got {len(self.positions)}")


class KeyframedBody(System, RigidParts):
    """An ellipsoid whose centre follows keyframes by monotone cubic Hermite interpolation
    (PCHIP: positions and velocities continuous, no overshoot between keys, so a foot planted
    by two equal keys stays still). Before the first key and after the last it holds still.

    State: position x (m) and velocity v (m/s); orientation q (w, x, y, z) is fixed. Forces
    are ignored. Its contact view: one prescribed part, an ellipsoid (primitive) drawn and
    collided as an icosphere scaled to its semi-axes."""

    role = Role.PRESCRIBED
    integrator = "keyframes (monotone cubic Hermite)"

    def __init__(self, name, params: KeyframedBodyParams = KeyframedBodyParams()):
        super().__init__(name, params.dt)
        from scipy.interpolate import PchipInterpolator
        t = np.asarray(params.times, dtype=float)
        p = np.asarray(params.positions, dtype=float)
        if t.ndim != 1 or len(t) < 2 or not np.all(np.isfinite(t)):
            raise ParameterError(f"{name}: needs at least 2 key times, got {params.times}")
        if not np.all(np.diff(t) > 0.0):
            raise ParameterError(f"{name}: key times must increase strictly, got {tuple(t)}")
        if p.size != 3 * len(t) or not np.all(np.isfinite(p)):
            raise ParameterError(f"{name}: positions must hold x, y, z for each of the {len(t)} "
                                 f"keys ({3 * len(t)} numbers), got {p.size}")
        self.semi_axes = np.array([require_positive(name, "semi-axis", a, "m")
                                   for a in params.semi_axes])
        if self.semi_axes.size != 3:
            raise ParameterError(f"{name}: semi_axes needs 3 lengths, got {params.semi_axes}")
        self._mass = require_positive(name, "mass", params.mass, "kg")
        self.params = params
        self._path = PchipInterpolator(t, p.reshape(-1, 3), axis=0, extrapolate=False)
        self._vel = self._path.derivative()
        self._t0, self._t1 = float(t[0]), float(t[-1])
        c, s = math.cos(0.5 * params.yaw), math.sin(0.5 * params.yaw)
        self.q = np.array([c, 0.0, 0.0, s])
        self.rotation = np.array([[math.cos(params.yaw), -math.sin(params.yaw), 0.0],
                                  [math.sin(params.yaw), math.cos(params.yaw), 0.0],
                                  [0.0, 0.0, 1.0]])
        self.x = np.zeros(3)
        self.v = np.zeros(3)
        self._place(0.0)
        self.color = None
        v, t = icosphere(3)
        self._mesh = (v * self.semi_axes, t)
        self._view = BodiesView(self, [name], [self._mesh],
                                [Primitive("ellipsoid", axes=tuple(self.semi_axes))], [np.inf],
                                movable=False)

    def _place(self, t):
        tc = min(max(t, self._t0), self._t1)
        self.x[:] = self._path(tc)
        self.v[:] = self._vel(tc) if self._t0 < t < self._t1 else 0.0

    @property
    def mass(self):
        return self._mass

    def step(self, h):
        """Move along the keyframes by h seconds (a kinematic body has no substeps)."""
        self.time += h
        self._place(self.time)

    def advance(self, h, dt=None):
        self.step(h)

    def contact_view(self):
        return self._view

    def part_poses(self):
        return self.x[None], self.rotation[None]

    def part_centres(self):
        return self.x[None]

    def part_velocities(self, parts=None):
        k = 1 if parts is None else len(parts)
        return np.repeat(self.v[None], k, axis=0), np.zeros((k, 3))

    def centre_of_mass(self):
        return self.x

    def shapes(self):
        v, t = self._mesh
        return [Shape(self.name, "body", color=self.color, verts=v, tris=t, palette="rigid")]

    def lowest_z(self):
        """Height (m) of the body's lowest point."""
        M = self.rotation @ np.diag(self.semi_axes ** 2) @ self.rotation.T
        return float(self.x[2] - math.sqrt(M[2, 2]))

    def kinetic_energy(self):
        return 0.5 * self._mass * float(self.v @ self.v)

    def momentum(self):
        return self._mass * self.v.copy()

    def generalized_state(self):
        return self.x, self.v

    def set_generalized_state(self, x, xdot):
        self.x[:] = x
        self.v[:] = xdot

    def frame(self):
        return {"position": self.x.copy(), "orientation": self.q.copy()}
