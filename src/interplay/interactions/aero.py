"""Aerodynamics of a triangle mesh in a wind field (SPEC 2.2): per-triangle drag and lift.

The primary is the wind (``systems.wind.WindField``), the secondary any system whose contact
view is points with triangles (a cloth, a flag, a leaf). The air does not feel the cloth: the
force on the primary is logged (the reaction the air would feel) and never applied.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative
from ..params import param
from ..kernels import aero as K
from .base import Interaction


@dataclass(frozen=True)
class AeroParams:
    """Coefficients of f = -c_n s |v| (n.v) n - c_t s (v - (n.v) n).

    drag: c_n (kg/m^3), 0.5 rho C_D with C_D ~ 1.2 for a flat plate across the flow;
    friction: c_t (kg/(m^2 s)), linear skin friction along the surface."""
    drag: float = param(0.7, "kg/m^3", ge=0.0, le=100.0, doc="c_n, 0.5 rho C_D")
    friction: float = param(0.02, "kg/(m^2 s)", ge=0.0, le=100.0, doc="c_t")


class Aerodynamics(Interaction):
    """Drag and lift on every triangle of ``body`` from the ``wind`` at its centroid, sampled at
    the body's own time. For implicit bodies the force carries its velocity Jacobian, so a
    light leaf in a strong gust stays stable at large steps."""

    def __init__(self, name, wind, body, params: AeroParams = AeroParams(), mode="one-way"):
        super().__init__(name, wind, body, mode)
        self.body = body.contact_view()
        if self.body is None or self.body.kind != "points" or self.body.triangles is None:
            raise ParameterError(f"interaction {name}: {body.name} has no triangles; "
                                 "aerodynamics needs a surface mesh (SpringNetwork.from_mesh)")
        self.tris = np.ascontiguousarray(self.body.triangles, dtype=np.int64)
        self.cn = require_nonnegative(name, "drag", params.drag, "kg/m^3")
        self.ct = require_nonnegative(name, "friction", params.friction, "kg/(m^2 s)")
        n = len(self.body.x)
        self._idx = np.arange(n)
        self._f = np.zeros((n, 3))
        self._dfdx = np.zeros((n, 3, 3))
        self._dfdv = np.zeros((n, 3, 3))
        self._cent = np.zeros((len(self.tris), 3))

    def forces(self, with_jacobian=False):
        """(point forces (n,3) N, their velocity Jacobian (n,3,3) N s/m, total force (3,) N)."""
        body = self.body
        K.centroids(body.x, self.tris, self._cent)
        wind = self.primary.velocity(self._cent, body.time)
        self._f[:] = 0.0
        if with_jacobian:
            self._dfdv[:] = 0.0
        total = K.triangle_forces(body.x, body.v, self.tris, wind, self.cn, self.ct, self._f,
                                  self._dfdv, with_jacobian)
        return self._f, self._dfdv, total

    def exchange(self, to_primary, to_secondary):
        f, dfdv, total = self.forces(self.body.jacobians)
        if to_secondary:
            self.body.apply(self._idx, f, self._dfdx, dfdv)
        return -total, np.zeros(3), True
