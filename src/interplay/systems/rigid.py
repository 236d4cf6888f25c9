"""Free rigid bodies: the basketball, floating balls (SPEC 2.3)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..kernels.rigid import Body, Wrench, generalized, quat_mul, quat_to_matrix, rigid_step
from .base import GRAVITY, System
from ..params import param
from .shape import Shape, split_color
from ..geometry.primitive import Primitive
from .views import BodiesView, RigidParts


@dataclass(frozen=True)
class SphereParams:
    """A sphere. radius in m, mass in kg; shell=True is a hollow shell (a basketball)."""
    radius: float = param(0.12, "m", ge=1e-3, le=10.0, doc="radius")
    mass: float = param(0.68, "kg", ge=1e-4, le=1e6, doc="mass")
    shell: bool = param(True, doc="a hollow shell (I = 2/3 m r^2), else solid (2/5 m r^2)")
    dt: float = param(1e-3, "s", ge=1e-9, le=0.1, doc="largest integrator step")


class RigidBody(System, RigidParts):
    """A free rigid body with linear and angular velocity under gravity.

    State: position x (m), velocity v (m/s), orientation q (unit quaternion w,x,y,z), angular
    velocity w (rad/s, world frame). Forces and torques about the centre of mass accumulate
    through ``add_wrench`` and are held constant over a step. Its contact view is one part:
    ``surface`` (vertices (n,3) m in the body frame, triangles) and an optional analytic
    ``primitive`` (systems/views.Primitive).
    """

    integrator = "exact-ballistic (x += hv + h^2 a/2) with exponential-map rotation"

    def __init__(self, name, mass, inertia_body, dt, position=(0, 0, 0), velocity=(0, 0, 0),
                 angular_velocity=(0, 0, 0), gravity=GRAVITY, surface=None, primitive=None):
        super().__init__(name, dt)
        self._mass = require_positive(name, "mass", mass, "kg")
        self.inertia_body = np.asarray(inertia_body, dtype=float).reshape(3)
        if not np.all(self.inertia_body > 0):
            raise ParameterError(f"{name}: inertia must be positive, got {self.inertia_body}")
        self.x = np.array(position, dtype=float).reshape(3)
        self.v = np.array(velocity, dtype=float).reshape(3)
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.w = np.array(angular_velocity, dtype=float).reshape(3)
        self.gravity = np.array(gravity, dtype=float).reshape(3)
        self.force = np.zeros(3)
        self.torque = np.zeros(3)
        self.kext = np.zeros((3, 3))  # dF/dx (N/m) of the held force, when a contact gives it
        self.dext = np.zeros((3, 3))  # dF/dv (N s/m)
        self._body = Body(self.x, self.v, self.q, self.w, self._mass, self.inertia_body,
                          self.gravity)
        self.carried = np.zeros(4)  # [kg] of points tied to it this step (Wrench.carried)
        self.carried_inertia = np.zeros((3, 3))  # kg m^2 of them about its centre, world
        self._wrench = Wrench(self.force, self.torque, self.kext, self.dext, self.carried,
                              self.carried_inertia)
        self._gx, self._gv = np.zeros(7), np.zeros(7)
        self.surface = surface
        self.color = None  # linear RGB as drawn, or (n,3) one per surface vertex
        self.material = "rubber"
        self._view = BodiesView(self, [name], [surface if surface is not None else
                                               (np.zeros((0, 3)), np.zeros((0, 3), np.int64))],
                                [primitive], [self._mass], movable=True)

    @property
    def mass(self) -> float:
        return self._mass

    def clear_forces(self):
        self.force[:] = 0.0
        self.torque[:] = 0.0
        self.kext[:] = 0.0
        self.dext[:] = 0.0
        self.carried[:] = 0.0
        self.carried_inertia[:] = 0.0

    def add_wrench(self, force, torque=None, point=None, dfdx=None, dfdv=None, carried=None):
        """Add a force (N) at a world point (m; default the centre) and an extra torque (N m).

        dfdx (N/m) and dfdv (N s/m) are the force's 3x3 Jacobians with respect to the body's
        position and velocity; with them a stiff force (a floor contact) is integrated
        implicitly and stays stable at the body's step. carried: (mass kg, inertia (3,3)
        kg m^2 about the centre, world axes) of points tied to the body that it accelerates
        with itself over the step (``SegmentAttachment(carry=True)``)."""
        f = np.asarray(force, dtype=float)
        self.force += f
        if point is not None:
            self.torque += np.cross(np.asarray(point, dtype=float) - self.x, f)
        if torque is not None:
            self.torque += torque
        if dfdx is not None:
            self.kext += dfdx
        if dfdv is not None:
            self.dext += dfdv
        if carried is not None:
            self.carried[0] += carried[0]
            self.carried_inertia += carried[1]

    def step(self, h):
        rigid_step(self._body, self._wrench, h)

    # --- the contact view: one rigid part ------------------------------------------------------
    def contact_view(self):
        return self._view

    def part_poses(self):
        return self.x[None], quat_to_matrix(self.q)[None]

    def part_centres(self):
        return self.x[None]

    def part_velocities(self, parts=None):
        rows = [0] if parts is None else np.zeros(len(parts), np.int64)
        return self.v[None][rows], self.w[None][rows]

    def part_accelerations(self):
        """Free fall: the acceleration with no interaction acting (what a contact's constraint
        term cancels; the same whatever order the interactions are evaluated in)."""
        return self.gravity[None]

    def part_inverse_inertias(self):
        R = quat_to_matrix(self.q)
        return (R @ np.diag(1.0 / self.inertia_body) @ R.T)[None]

    def centre_of_mass(self):
        return self.x

    def add_part_wrench(self, part, force, torque=None, point=None, dfdx=None, dfdv=None,
                        carried=None):
        self.add_wrench(force, torque, point, dfdx, dfdv, carried)

    def shapes(self):
        if self.surface is None:
            return []
        v, t = self.surface
        color, per_point = split_color(self.color)
        return [Shape(self.name, "body", color=color, verts=np.asarray(v, float),
                      tris=np.asarray(t), palette="rigid", point_colors=per_point,
                      material=self.material)]

    # --- measures ------------------------------------------------------------------------------
    def kinetic_energy(self):
        """Translational plus rotational kinetic energy (J). In Python, not a kernel: it is
        sampled once a millisecond, and a kernel of its own cost every first run 0.4 s of
        compiling; the arithmetic is the kernel's it replaced, in its order, to the bit."""
        R = quat_to_matrix(self.q).tolist()
        v, w, inertia = self.v.tolist(), self.w.tolist(), self.inertia_body.tolist()
        e = 0.0
        for i in range(3):
            wb = R[0][i] * w[0] + R[1][i] * w[1] + R[2][i] * w[2]  # (R^T w)_i, body frame
            e += 0.5 * self._mass * v[i] * v[i] + 0.5 * inertia[i] * wb * wb
        return e

    def health(self):
        if not math.isfinite(self.x.sum() + self.v.sum() + self.w.sum() + self.q.sum()):
            return [f"{self.name}: state became non-finite at t={self.time:.4f} s"]
        return []

    def momentum(self):
        return self._mass * self.v.copy()

    # --- state ---------------------------------------------------------------------------------
    def generalized_state(self):
        """(position, quaternion) and their rates; buffers are reused: copy them to keep them."""
        generalized(self.x, self.v, self.q, self.w, self._gx, self._gv)
        return self._gx, self._gv

    def set_generalized_state(self, x, xdot):
        self.x[:] = x[:3]
        self.v[:] = xdot[:3]
        q = np.asarray(x[3:7], dtype=float)
        self.q[:] = q / np.linalg.norm(q)
        conj = self.q * np.array([1.0, -1.0, -1.0, -1.0])
        self.w[:] = 2.0 * quat_mul(np.asarray(xdot[3:7], dtype=float), conj)[1:]

    def capture(self):
        """The body's own state (x, v, q, w: converting to the generalized rates and back
        would not return w bit for bit) and time."""
        return {"x": self.x.copy(), "v": self.v.copy(), "q": self.q.copy(),
                "w": self.w.copy(), "time": np.array(self.time)}

    def restore(self, snap):
        for key in ("x", "v", "q", "w"):
            getattr(self, key)[:] = snap[key]
        self.time = float(snap["time"])

    def frame(self):
        return {"position": self.x.copy(), "orientation": self.q.copy()}


class Sphere(RigidBody):
    """A solid sphere (I = 2/5 m r^2) or a thin shell (I = 2/3 m r^2, a basketball). Its
    contact and drawn surface is an icosphere of ``subdivisions`` (3: 642 vertices)."""

    def __init__(self, name, params: SphereParams = SphereParams(), subdivisions: int = 3,
                 **state):
        from ..geometry.sphere import icosphere
        r = require_positive(name, "radius", params.radius, "m")
        m = require_positive(name, "mass", params.mass, "kg")
        c = 2.0 / 3.0 if params.shell else 2.0 / 5.0
        v, t = icosphere(subdivisions)
        super().__init__(name, m, [c * m * r * r] * 3, params.dt, surface=(v * r, t),
                         primitive=Primitive("sphere", radius=r), **state)
        self.radius = r
        self.params = params

    def lowest_z(self) -> float:
        """Height (m) of the sphere's lowest point."""
        return float(self.x[2] - self.radius)
