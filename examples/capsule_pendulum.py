"""Extending Interplay: a new system and a new interaction, plugged in without editing any of
Interplay's own modules (the worked example of docs/architecture.md; tests/test_extending.py
runs it).

``CapsulePendulum`` is a new system: a rigid rod swinging about a fixed pivot. It says what it
is (a dynamic ``Role``), what contacts see of it (a ``BodiesView`` of one capsule part, through
the ``RigidParts`` methods), what it looks like (a ``Shape``), and how its state is recorded
and restored. Nothing else in Interplay learns its type: ``MeshContact`` collides it with a
cloth, the scheduler runs it, the outputs draw it.

``LinearDrag`` is a new interaction: still air resisting any system seen as rigid parts,
F = -c v at each part's centre of mass, applied through the view.
"""
from __future__ import annotations

import math

import numpy as np

from interplay.geometry.anthropometry import segment_mesh
from interplay.geometry.primitive import Primitive
from interplay.interactions.base import Interaction
from interplay.systems.base import Role, System
from interplay.systems.shape import Shape
from interplay.systems.views import BodiesView, RigidParts


class CapsulePendulum(System, RigidParts):
    """A thin rod of mass m (kg) and length L (m) hanging from a fixed pivot (m), swinging in
    the x-z plane; drawn and collided as a capsule of radius r (m). State: the angle theta
    (rad) from straight down, a right-handed turn about +y (the tip swings towards -x), and
    its rate omega (rad/s). Dynamics:
    I_p theta'' = -m g (L/2) sin theta + tau, I_p = m L^2 / 3 about the pivot, tau the torque
    (N m) of the forces applied to it; semi-implicit Euler at dt (s)."""

    role = Role.DYNAMIC
    integrator = "semi-implicit Euler on the pivot angle"

    def __init__(self, name, pivot, length=0.5, radius=0.03, mass=1.0, theta=0.0, dt=1e-3,
                 g=9.81):
        super().__init__(name, dt)
        self.pivot = np.asarray(pivot, dtype=float)
        self.length, self.radius, self._mass, self.g = float(length), float(radius), float(mass), g
        self.inertia = self._mass * self.length ** 2 / 3.0  # kg m^2, about the pivot
        self.theta, self.omega, self.torque = float(theta), 0.0, 0.0
        mesh = segment_mesh(("capsule", radius, np.zeros(3), np.array([0.0, 0.0, -length])))
        self._mesh = mesh
        self._view = BodiesView(self, [name], [mesh],
                                [Primitive("capsule", radius=radius, b=(0.0, 0.0, -length))],
                                [self._mass], movable=True)

    # --- dynamics ------------------------------------------------------------------------
    @property
    def mass(self):
        return self._mass

    def clear_forces(self):
        self.torque = 0.0

    def step(self, h):
        alpha = (-self._mass * self.g * 0.5 * self.length * math.sin(self.theta)
                 + self.torque) / self.inertia
        self.omega += h * alpha
        self.theta += h * self.omega

    # --- what contacts see: one rigid part -----------------------------------------------------
    def _rotation(self):
        c, s = math.cos(self.theta), math.sin(self.theta)
        return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # about +y

    def contact_view(self):
        return self._view

    def part_poses(self):
        return self.pivot[None], self._rotation()[None]

    def part_centres(self):
        return (self.pivot + self._rotation() @ [0.0, 0.0, -0.5 * self.length])[None]

    def part_velocities(self, parts=None):
        w = np.array([0.0, self.omega, 0.0])
        lin = np.cross(w, self.part_centres()[0] - self.pivot)
        k = 1 if parts is None else len(parts)
        return np.repeat(lin[None], k, axis=0), np.repeat(w[None], k, axis=0)

    def centre_of_mass(self):
        return self.part_centres()[0]

    def add_part_wrench(self, part, force, torque=None, point=None, dfdx=None, dfdv=None):
        """Only the torque about the pivot's axis (+y) moves it; the pivot takes the rest."""
        at = self.part_centres()[0] if point is None else np.asarray(point, dtype=float)
        tau = np.cross(at - self.pivot, np.asarray(force, dtype=float))
        if torque is not None:
            tau = tau + torque
        self.torque += float(tau[1])

    # --- what it looks like, and its state ------------------------------------------------------
    def shapes(self):
        v, t = self._mesh
        return [Shape(self.name, "body", verts=v, tris=t, palette="rigid")]

    def frame(self):
        half = 0.5 * self.theta
        return {"position": self.pivot.copy(),
                "orientation": np.array([math.cos(half), 0.0, math.sin(half), 0.0])}

    def kinetic_energy(self):
        return 0.5 * self.inertia * self.omega ** 2

    def generalized_state(self):
        return np.array([self.theta]), np.array([self.omega])

    def set_generalized_state(self, x, xdot):
        self.theta, self.omega = float(x[0]), float(xdot[0])


class LinearDrag(Interaction):
    """Still air (the primary: any static system, e.g. a WindField) resisting the rigid parts
    of ``body``: F = -c v (c in N s/m) at each part's centre of mass. One-way: the air does
    not move; the force the body feels is logged."""

    def __init__(self, name, air, body, c, mode="one-way"):
        super().__init__(name, air, body, mode)
        self.body = body.contact_view()
        self.c = float(c)

    def exchange(self, to_primary, to_secondary):
        lin, _ = self.body.velocities()
        total = np.zeros(3)
        for part in range(self.body.count):
            f = -self.c * lin[part]
            if to_secondary:
                self.body.apply(part, f)
            total += f
        return -total, np.zeros(3), True
