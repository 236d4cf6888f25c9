"""Points on the ground: a penalty plane with Coulomb friction for cloth and leaves (the one
contact law, per kilogram of point mass: ``kernels.contact.points_on_plane``).

Every point below the plane (plus a thickness) is pushed up by a spring-damper scaled by its
own mass (so a 10 mg leaf point and a 10 g cloth point sink equally: sag = g / stiffness) and
held by friction mu f_n against its sliding velocity, regularized below ``eps`` so a resting
point does not chatter. The forces carry their Jacobians for implicit networks. A point that
would pass the plane within the coming coupling step is stopped on it (a speculative contact:
the penalty alone would let it sink up to its speed times the step).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SceneError, require_nonnegative, require_positive
from ..params import param
from ..kernels.contact import points_on_plane
from ..kernels.springs import point_forces
from .base import Interaction


@dataclass(frozen=True)
class GroundParams:
    """stiffness (N/m per kg of point mass, 1/s^2): 1e5 sags g/1e5 = 0.1 mm; damping (N s/m
    per kg, 1/s): 300 is about half critical at that stiffness; friction: mu; eps (m/s):
    sliding speed below which friction is viscous; thickness (m): contact offset above the
    plane (half a leaf's thickness, so it does not look sunk)."""
    stiffness: float = param(1.0e5, "1/s^2", ge=1e-6, le=1e10, doc="per kg of point mass")
    damping: float = param(300.0, "1/s", ge=0.0, le=1e7, doc="per kg of point mass")
    friction: float = param(0.6, "-", ge=0.0, le=10.0)
    eps: float = param(0.01, "m/s", ge=1e-6, le=100.0)
    thickness: float = param(0.001, "m", ge=0.0, le=1.0)


class GroundContact(Interaction):
    """A plane (primary: a static system whose contact view has a height) under the points of
    ``body`` (secondary: a system seen as points)."""

    def __init__(self, name, plane, body, params: GroundParams = GroundParams(), mode="one-way"):
        super().__init__(name, plane, body, mode)
        k = require_positive(name, "stiffness", params.stiffness, "1/s^2")
        c = require_nonnegative(name, "damping", params.damping, "1/s")
        mu = require_nonnegative(name, "friction", params.friction)
        eps = require_positive(name, "eps", params.eps, "m/s")
        height = plane.contact_view().height
        self.body = body.contact_view()
        if height is None or self.body is None or self.body.kind != "points":
            raise SceneError(f"interaction {name}: needs a plane ({plane.name}) under a system "
                             f"of points ({body.name})")
        self.level = height + require_nonnegative(name, "thickness", params.thickness, "m")
        self._law = np.array([0.0, k, c, mu, eps, 0.0])
        self._out = point_forces(len(self.body.x))
        self._h = 0.0

    def prepare(self, h, dts=None):
        self._h = h  # the step a speculative contact looks ahead over

    def exchange(self, to_primary, to_secondary):
        o = self._out
        k = points_on_plane(self.body.points, self.level, self._law, self._h, o,
                            self.body.jacobians)
        if k == 0:
            return np.zeros(3), np.zeros(3), False
        if to_secondary:
            self.body.apply(o.idx[:k], o.f[:k], o.dfdx[:k], o.dfdv[:k], o.vref[:k])
        return -o.f[:k].sum(axis=0), np.zeros(3), True
