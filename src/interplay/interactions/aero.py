"""Aerodynamics of a triangle mesh in a wind field (SPEC 2.2): per-triangle drag and lift.

The primary is the wind (``systems.wind.WindField``), the secondary any system whose contact
view is points with triangles (a cloth, a flag, a leaf). The air does not feel the cloth: the
force on the primary is logged (the reaction the air would feel) and never applied.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..kernels import aero as K
from ..params import param
from .base import Interaction


LAWS = ("plate", "delta")
CENTRES = ("triangles", "chord")


@dataclass(frozen=True)
class AeroParams:
    """The air on each triangle: f = -c s |v| (n.v) n - c_t s (v - (n.v) n).

    law: how the normal force's coefficient c (kg/m^3) depends on the triangle's angle of
    attack a (sin a = |n.v| / |v|):

    * ``plate`` (SPEC 2.2): c = drag, constant; the normal force coefficient C_N = 2 c / rho
      = 1.2 sin a, a flat plate's across the flow and a third of a lifting sail's at 10-30
      deg;
    * ``delta``: Polhamus's leading-edge-suction analogy for a sharp-edged delta (NASA TN
      D-3767, 1966), C_N = K_p sin a cos^2 a + K_v sin^2 a cos a (potential flow lift with
      K_p the lift slope per radian, vortex lift with K_v ~ pi), i.e. c = 0.5 density (K_p
      cos^2 a + K_v sin a cos a), up to ``stall``; above it the leading-edge vortex has burst
      and C_N stays at its value there, or the plate's 2 drag / density sin a where that is
      larger (the separated flow across a plate: ESDU 70015, 1970).

    drag: c_n (kg/m^3), 0.5 rho C_D with C_D ~ 1.2 for a flat plate across the flow;
    friction: c_t (kg/(m^2 s)), linear skin friction along the surface; density (kg/m^3),
    potential (K_p, 1/rad), vortex (K_v) and stall (deg): the delta law's.

    centre: where the normal force acts. ``triangles`` (SPEC 2.2): each triangle's at its
    centroid, so a flat sail's centre of pressure is its area centroid at every angle;
    ``chord``: the body is one flat sail whose centre of pressure moves along its chord with
    the angle of attack as a flat plate's does, from a quarter chord at small angles to the
    centroid across the flow (``kernels.aero.chordwise_centre``). A kite's pitch trims on
    that: its towing point picks the angle at which the centre of pressure lies on its line.
    """
    drag: float = param(0.7, "kg/m^3", ge=0.0, le=100.0, doc="c_n, 0.5 rho C_D")
    friction: float = param(0.02, "kg/(m^2 s)", ge=0.0, le=100.0, doc="c_t")
    law: str = param("plate", "-", choices=LAWS, doc="normal force law")
    density: float = param(1.2, "kg/m^3", gt=0.0, le=1500.0, doc="rho (delta law)")
    potential: float = param(2.5, "1/rad", ge=0.0, le=6.3, doc="K_p (delta law)")
    vortex: float = param(3.14, "-", ge=0.0, le=4.0, doc="K_v (delta law)")
    stall: float = param(30.0, "deg", gt=0.0, le=90.0, doc="vortex breakdown (delta law)")
    centre: str = param("triangles", "-", choices=CENTRES, doc="centre of pressure")


class _AirOn(Interaction):
    """What the air's interactions share: one-way (the air does not feel the body), forces on
    every point of the body's view with their velocity Jacobian for implicit bodies, the
    reaction logged on the wind and never applied."""

    def _buffers(self, n):
        self._idx = np.arange(n)
        self._f = np.zeros((n, 3))
        self._dfdx = np.zeros((n, 3, 3))
        self._dfdv = np.zeros((n, 3, 3))

    def exchange(self, to_primary, to_secondary):
        f, dfdv, total = self.forces(self.body.jacobians)
        if to_secondary:
            self.body.apply(self._idx, f, self._dfdx, dfdv)
        return -total, np.zeros(3), True


class Aerodynamics(_AirOn):
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
        self.law = _law(name, params)
        if params.centre not in CENTRES:
            raise ParameterError(f"interaction {name}: unknown centre of pressure "
                                 f"{params.centre!r}; choose one of {', '.join(CENTRES)} "
                                 "(aero.centre)")
        n = len(self.body.x)
        self._buffers(n)
        self._cent = np.zeros((len(self.tris), 3))
        self._info = np.zeros((len(self.tris), 8)) if params.centre == "chord" else None

    def forces(self, with_jacobian=False):
        """(point forces (n,3) N, their velocity Jacobian (n,3,3) N s/m, total force (3,) N)."""
        body = self.body
        K.centroids(body.x, self.tris, self._cent)
        wind = self.primary.velocity(self._cent, body.time)
        self._f[:] = 0.0
        if with_jacobian:
            self._dfdv[:] = 0.0
        total = K.triangle_forces(body.x, body.v, self.tris, wind, self.cn, self.ct, self._f,
                                  self._dfdv, with_jacobian, *self.law, self._info)
        if self._info is not None:
            total = total + K.chordwise_centre(body.x, self.tris, self._cent, self._info,
                                               self._f)
        return self._f, self._dfdv, total


def _law(name, p: AeroParams):
    """The kernel's (law, 0.5 rho K_p, 0.5 rho K_v, sin(stall), 0.5 rho C_N at the stall) for
    ``p`` (the plate law ignores the last four)."""
    if p.law not in LAWS:
        raise ParameterError(f"interaction {name}: unknown aerodynamic law {p.law!r}; choose "
                             f"one of {', '.join(LAWS)} (aero.law)")
    if p.law == "plate":
        return 0, 0.0, 0.0, 1.0, 0.0
    half = 0.5 * require_positive(name, "density", p.density, "kg/m^3")
    kp = require_nonnegative(name, "potential", p.potential, "1/rad")
    kv = require_nonnegative(name, "vortex", p.vortex)
    if not 0.0 < p.stall <= 90.0:
        raise ParameterError(f"interaction {name}: stall {p.stall!r} deg is outside (0, 90]; "
                             "the delta law's vortex bursts at 20-40 deg (aero.stall)")
    a = math.radians(p.stall)
    cs = kp * math.sin(a) * math.cos(a) ** 2 + kv * math.sin(a) ** 2 * math.cos(a)
    return 1, half * kp, half * kv, math.sin(a), half * cs



@dataclass(frozen=True)
class CordDragParams:
    """The air on a cord (a kite's flying line, a tail's string) and on small bluff bodies
    along it (a tail's bows). density: rho (kg/m^3); drag: C_D of a cylinder in cross flow
    (~1.1-1.2 at a line's Reynolds numbers of 1e2-1e3, Hoerner, *Fluid-Dynamic Drag*, 1965,
    ch. 3); friction: C_f along it (skin friction on the wetted circumference); bow_drag: C_D
    of a bow (a crumpled ribbon: ~1); bow_area (m^2): the frontal area of each bow."""
    density: float = param(1.2, "kg/m^3", ge=0.0, le=1500.0)
    drag: float = param(1.1, "-", ge=0.0, le=10.0, doc="C_D across")
    friction: float = param(0.01, "-", ge=0.0, le=1.0, doc="C_f along")
    bow_drag: float = param(1.0, "-", ge=0.0, le=10.0)
    bow_area: float = param(0.0, "m^2", ge=0.0, le=1.0)


class CordDrag(_AirOn):
    """Drag on every segment of ``cord`` (a network seen as points with segments; its
    ``thickness`` is the cord's radius) and on its ``bows`` (point indices), from the wind at
    each segment's middle and each bow, at the cord's own time (``kernels.aero``: cross-flow
    drag on the velocity across the cord, skin friction along it, quadratic drag on bows).
    Like ``Aerodynamics`` it is one-way: the reaction is logged on the wind, never applied;
    implicit cords get the forces' velocity Jacobian."""

    def __init__(self, name, wind, cord, params: CordDragParams = CordDragParams(), bows=(),
                 mode="one-way"):
        super().__init__(name, wind, cord, mode)
        self.body = cord.contact_view()
        if (self.body is None or self.body.kind != "points" or self.body.segments is None
                or not len(self.body.segments)):
            raise ParameterError(f"interaction {name}: {cord.name} has no segments; cord "
                                 "drag needs a network of springs")
        rho = require_nonnegative(name, "density", params.density, "kg/m^3")
        d = 2.0 * self.body.thickness
        self.seg = np.ascontiguousarray(self.body.segments, dtype=np.int64)
        self.cn = 0.5 * rho * require_nonnegative(name, "drag", params.drag) * d
        self.ct = 0.5 * rho * require_nonnegative(name, "friction", params.friction) * np.pi * d
        self.bows = np.asarray(bows, dtype=np.int64).reshape(-1)
        n = len(self.body.x)
        if len(self.bows) and (self.bows.min() < 0 or self.bows.max() >= n):
            raise ParameterError(f"{name}: bows {self.bows.tolist()} must be points 0..{n - 1} "
                                 f"of {cord.name}")
        area = require_nonnegative(name, "bow_area", params.bow_area, "m^2")
        self.cd_area = np.full(len(self.bows), 0.5 * rho * require_nonnegative(
            name, "bow_drag", params.bow_drag) * area)
        self._buffers(n)
        self._mid = np.zeros((len(self.seg), 3))

    def forces(self, with_jacobian=False):
        """(point forces (n,3) N, their velocity Jacobian (n,3,3) N s/m, total force (3,) N)."""
        body, t = self.body, self.body.time
        K.midpoints(body.x, self.seg, self._mid)
        self._f[:] = 0.0
        if with_jacobian:
            self._dfdv[:] = 0.0
        total = K.segment_forces(body.x, body.v, self.seg, self.primary.velocity(self._mid, t),
                                 self.cn, self.ct, self._f, self._dfdv, with_jacobian)
        if len(self.bows):
            total = total + K.point_forces(body.v, self.bows,
                                           self.primary.velocity(body.x[self.bows], t),
                                           self.cd_area, self._f, self._dfdv, with_jacobian)
        return self._f, self._dfdv, total

