"""Points on the ground: a penalty plane with Coulomb friction for cloth and leaves.

Every point below the plane (plus a thickness) is pushed up by a spring-damper scaled by its
own mass (so a 10 mg leaf point and a 10 g cloth point sink equally: sag = g / stiffness) and
held by friction mu f_n against its sliding velocity, regularized below ``eps`` so a resting
point does not chatter. The forces carry their Jacobians for implicit networks.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require_nonnegative, require_positive
from .base import Interaction


@dataclass(frozen=True)
class GroundParams:
    """stiffness (N/m per kg of point mass, 1/s^2): 1e5 sags g/1e5 = 0.1 mm; damping (N s/m
    per kg, 1/s): 300 is about half critical at that stiffness; friction: mu; eps (m/s):
    sliding speed below which friction is viscous; thickness (m): contact offset above the
    plane (half a leaf's thickness, so it does not look sunk)."""
    stiffness: float = 1.0e5
    damping: float = 300.0
    friction: float = 0.6
    eps: float = 0.01
    thickness: float = 0.001


class GroundContact(Interaction):
    """A ``StaticPlane`` (primary) under the points of ``body`` (secondary)."""

    def __init__(self, name, plane, body, params: GroundParams = GroundParams(), mode="one-way"):
        super().__init__(name, plane, body, mode)
        self.k = require_positive(name, "stiffness", params.stiffness, "1/s^2")
        self.c = require_nonnegative(name, "damping", params.damping, "1/s")
        self.mu = require_nonnegative(name, "friction", params.friction)
        self.eps = require_positive(name, "eps", params.eps, "m/s")
        self.level = plane.height + require_nonnegative(name, "thickness", params.thickness, "m")

    def exchange(self, to_primary, to_secondary):
        body = self.secondary
        x, v, m = body.x, body.v, body.m
        idx = np.flatnonzero(x[:, 2] < self.level)
        if len(idx) == 0:
            return np.zeros(3), np.zeros(3), False
        mi, vi = m[idx], v[idx]
        fn = np.maximum(mi * (self.k * (self.level - x[idx, 2]) - self.c * vi[:, 2]), 0.0)
        slide = np.maximum(np.hypot(vi[:, 0], vi[:, 1]), self.eps)
        mu_v = self.mu * fn / slide  # N s/m: friction as a damper that saturates at mu f_n
        f = np.zeros((len(idx), 3))
        f[:, 0] = -mu_v * vi[:, 0]
        f[:, 1] = -mu_v * vi[:, 1]
        f[:, 2] = fn
        if to_secondary:
            if getattr(body, "integrator", "explicit") != "explicit":
                pressing = fn > 0.0
                dfdx = np.zeros((len(idx), 3, 3))
                dfdv = np.zeros((len(idx), 3, 3))
                dfdx[:, 2, 2] = np.where(pressing, -mi * self.k, 0.0)
                dfdv[:, 2, 2] = np.where(pressing, -mi * self.c, 0.0)
                dfdv[:, 0, 0] = dfdv[:, 1, 1] = -mu_v
                body.add_point_forces(idx, f, dfdx, dfdv)
            else:
                body.add_point_forces(idx, f)
        return -f.sum(axis=0), np.zeros(3), True
