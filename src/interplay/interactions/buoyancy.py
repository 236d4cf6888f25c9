"""A body in water (SPEC 2.4, objects in water): buoyancy and drag on the body, external
pressure on the water.

The body (primary: any system whose contact view's first part is a sphere or an ellipsoid
primitive: a rigid Sphere, a KeyframedBody foot) is cut by the water's columns at every
coupling step (``add_ellipsoid``).
Water rising into it meets an external pressure that holds it down (kernels/water.py
``heads``), so the water under it is pushed away and rises around it; the volume that
pressure keeps out, V_sub, is what the body displaces. The water acts back with

* buoyancy rho g V_sub (up) at the centre of buoyancy;
* drag -1/2 rho C_d A |v_rel| v_rel, A the frontal area times the submerged fraction and
  v_rel the body's velocity relative to the water around it (the column flow velocity, and the
  surface's vertical speed);
* rotational drag -C_r rho r^5 f |w| w on a spinning body (f the submerged fraction; r the
  body's mean radius), so waves that tip the centre of buoyancy do not spin a ball forever;
* optionally added mass -C_a rho V_sub a_body, with a_body lagged one coupling step (explicit:
  stable only while C_a rho V_body < m_body, which the constructor checks).

Two-way applies both sides; one-way only the pressure on the water (the log still records
what the body would feel).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SceneError, require_nonnegative
from ..params import param
from .base import Interaction

#: fewer columns than this across a body and the grid cannot resolve it
MIN_COLUMNS_ACROSS = 2
#: columns across a body the resolution warning recommends
GOOD_COLUMNS_ACROSS = 4


class ResolutionWarning(UserWarning):
    """The water's columns are too coarse for a body."""


@dataclass(frozen=True)
class BuoyancyParams:
    """drag: C_d (-); rotational_drag: C_r (-); added_mass: C_a (-, 0.5 for a sphere, 0 off)."""
    drag: float = param(0.47, "-", ge=0.0, le=100.0, doc="drag coefficient C_d")
    rotational_drag: float = param(0.5, "-", ge=0.0, le=100.0, doc="C_r")
    added_mass: float = param(0.0, "-", ge=0.0, le=10.0, doc="C_a (0.5 for a sphere)")

    def validated(self, owner):
        require_nonnegative(owner, "drag coefficient", self.drag)
        require_nonnegative(owner, "rotational drag coefficient", self.rotational_drag)
        require_nonnegative(owner, "added-mass coefficient", self.added_mass)
        return self


def body_ellipsoid(view):
    """(semi-axes (3,) m, rotation (3, 3), whether it turns with the body) of the ellipsoid of
    a BodiesView's first part: its sphere or ellipsoid primitive (a sphere's rotation does not
    matter: the identity)."""
    prim = view.primitives[0] if view is not None and view.kind == "bodies" else None
    if prim is not None and prim.kind == "sphere":
        return np.full(3, float(prim.radius)), np.eye(3), False
    if prim is not None and prim.kind == "ellipsoid":
        return np.asarray(prim.axes, dtype=float), view.poses()[1][0], True
    raise SceneError(f"{view.name if view is not None else 'the body'} has no shape the water "
                     "can displace (its contact view needs a sphere or ellipsoid primitive)")


class BodyInWater(Interaction):
    """Buoyancy and drag between a body (primary) and a Water system (secondary)."""

    def __init__(self, name, body, water, params: BuoyancyParams = BuoyancyParams(),
                 mode="two-way", standin=None):
        super().__init__(name, body, water, mode, standin)
        self.p = params.validated(name)
        self.body = body.contact_view()
        axes, R, self._turns = body_ellipsoid(self.body)
        self.axes = np.asarray(axes, dtype=float)
        self.volume = 4.0 / 3.0 * math.pi * float(np.prod(self.axes))  # m^3
        self.radius = float(np.prod(self.axes)) ** (1.0 / 3.0)  # m, of the equal-volume sphere
        self.area = math.pi * self.radius ** 2  # m^2, frontal area used by the drag
        self._set_rotation(R)
        across = 2.0 * min(math.sqrt(self._M[0, 0]), math.sqrt(self._M[1, 1]))
        l = water.spacing
        if across < MIN_COLUMNS_ACROSS * l:
            warnings.warn(
                f"{name}: {body.name} is {across:.3g} m across but the water's columns are "
                f"{l:.3g} m wide, too coarse to resolve it; use columns of at most "
                f"{across / GOOD_COLUMNS_ACROSS:.3g} m ({GOOD_COLUMNS_ACROSS} across it)",
                ResolutionWarning, stacklevel=2)
        m_added = self.p.added_mass * water.rho * self.volume
        if m_added >= self.body.masses[0]:
            raise ParameterError(
                f"{name}: added mass {m_added:.3g} kg (C_a {self.p.added_mass}) is not below "
                f"{body.name}'s mass {body.mass:.3g} kg; the lagged added-mass force would be "
                f"unstable: use added_mass < {body.mass / (water.rho * self.volume):.3g} or 0")
        self._out = np.zeros(7)
        self._h = 0.0
        self._v_prev = self.body.velocities()[0][0].copy()
        self._zero = np.zeros(3)

    def _set_rotation(self, R):
        a2 = self.axes ** 2
        self._M = np.ascontiguousarray(R @ np.diag(a2) @ R.T)
        self._A = np.ascontiguousarray(R @ np.diag(1.0 / a2) @ R.T)

    def prepare(self, h, dts=None):
        self._h = h
        self._v_prev[:] = self.body.velocities()[0][0]

    def capture(self):
        return {"v_prev": self._v_prev.copy()}

    def restore(self, snap):
        self._v_prev[:] = snap["v_prev"]

    def exchange(self, to_primary, to_secondary):
        body, water, p = self.body, self.secondary, self.p
        if self._turns:
            self._set_rotation(body.poses()[1][0])
        x = body.centres()[0]
        lin, ang = body.velocities()
        v, w = lin[0], ang[0]
        lids = water.add_ellipsoid(x, float(v[2]), self._A, self._M, self.volume,
                                   keep=to_secondary)
        out = water.body_load(lids, self._out)
        vsub = out[0]
        acc = (v - self._v_prev) / self._h if self._h > 0.0 else self._zero
        self._v_prev[:] = v
        if vsub <= 0.0:
            return self._zero, self._zero, False
        rho = water.rho
        frac = vsub / self.volume
        buoy = np.array([0.0, 0.0, rho * water.g * vsub])
        vrel = v - out[4:7]
        force = buoy - 0.5 * rho * p.drag * self.area * frac * np.linalg.norm(vrel) * vrel
        if p.added_mass > 0.0:
            force -= p.added_mass * rho * vsub * acc
        torque = np.cross(out[1:4] - x, buoy)
        torque -= p.rotational_drag * rho * self.radius ** 5 * frac * np.linalg.norm(w) * w
        if to_primary:
            body.apply(0, force, torque)
        return force, torque, True

    def submerged(self):
        """The last exchange's submerged volume (m^3) and centre of buoyancy (m)."""
        return float(self._out[0]), self._out[1:4].copy()
