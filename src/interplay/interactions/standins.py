"""Stand-ins for hybrid coupling: cheap fields that act on the primary alone (SPEC 1, 4)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require_nonnegative, require_positive
from ..params import param
from ..kernels.contact import sphere_segment_overlap
from .base import StandIn
from .contact import sphere_of


@dataclass(frozen=True)
class DampingFieldParams:
    """Coefficients of the net's damping field.

    linear: N s/m per unit overlap, angular: N m s per unit overlap; overlap is the sum over the
    rest-shape cords the ball penetrates of (penetration depth / ball radius). The defaults are
    fitted to the default two-way basketball (``interplay fit-standin basketball``).
    """
    # fitted: `interplay fit-standin basketball` (docs/coupling.md)
    linear: float = param(0.2062, "N s/m", ge=0.0, le=1e6, doc="per unit overlap")
    # the default ball enters without spin; a field cannot create spin
    angular: float = param(0.0, "N m s", ge=0.0, le=1e6, doc="per unit overlap")
    enabled: bool = True


class DampingField(StandIn):
    """A damping field co-located with a network's rest shape: while a sphere overlaps the rest
    cords, it damps the sphere's linear and angular velocity in proportion to the overlap:
    F = -linear * overlap * v, tau = -angular * overlap * w."""

    name = "damping field"

    def __init__(self, rest_points, segments, params: DampingFieldParams, thickness=0.0):
        require_nonnegative("damping field", "linear", params.linear, "N s/m")
        require_nonnegative("damping field", "angular", params.angular, "N m s")
        self.rest = np.array(rest_points, dtype=float)
        self.seg = np.ascontiguousarray(segments, dtype=np.int64)
        self.p = params
        self.thickness = float(thickness)
        self._zero = np.zeros(3)

    def act(self, ball):
        if not self.p.enabled:
            return self._zero, self._zero, False
        view, radius = sphere_of(self.name, ball)
        c = view.centres()[0]
        overlap = sphere_segment_overlap(c, radius, self.rest, self.seg, radius + self.thickness)
        if overlap <= 0.0:
            return self._zero, self._zero, False
        lin, ang = view.velocities()
        f = -self.p.linear * overlap * lin[0]
        tau = -self.p.angular * overlap * ang[0]
        view.apply(0, f, tau)
        return f, tau, True


@dataclass(frozen=True)
class ViscousDragFieldParams:
    """A still-water stand-in. surface: height of the still surface (m); linear (N s/m) and
    quadratic (N s^2/m^2) drag at full submersion, scaled by the submerged fraction;
    density (kg/m^3): > 0 adds buoyancy density g V_sub (Archimedes at the still surface),
    0 leaves it out (a diver's damping field); gravity (m/s^2)."""
    surface: float = param(0.0, "m", ge=-1e4, le=1e4, doc="still surface height")
    linear: float = param(2.0, "N s/m", ge=0.0, le=1e6)
    quadratic: float = param(20.0, "N s^2/m^2", ge=0.0, le=1e6)
    density: float = param(0.0, "kg/m^3", ge=0.0, le=1e5, doc="0: no buoyancy")
    gravity: float = param(9.81, "m/s^2", ge=0.0, le=100.0)
    enabled: bool = True


class ViscousDragField(StandIn):
    """Drag on the submerged part of a body below a flat surface (hybrid coupling with water):
    F = -(linear + quadratic |v|) f v + density g V f z_hat, with f the submerged fraction of
    an upright ellipsoid of half-height ``half_height`` (m) and volume ``volume`` (m^3):
    f = t^2 (3 - 2 t), t the immersed share of its height (exact for a sphere's cap)."""

    name = "viscous drag field"

    def __init__(self, params: ViscousDragFieldParams, half_height: float, volume: float):
        require_nonnegative("viscous drag field", "linear", params.linear, "N s/m")
        require_nonnegative("viscous drag field", "quadratic", params.quadratic, "N s^2/m^2")
        require_nonnegative("viscous drag field", "density", params.density, "kg/m^3")
        self.p = params
        self.half_height = require_positive("viscous drag field", "half_height", half_height,
                                            "m")
        self.volume = require_nonnegative("viscous drag field", "volume", volume, "m^3")
        self._zero = np.zeros(3)

    def act(self, body):
        p = self.p
        view = body.contact_view()
        t = min(max((p.surface - view.centres()[0][2] + self.half_height)
                    / (2.0 * self.half_height), 0.0), 1.0)
        if not p.enabled or t <= 0.0:
            return self._zero, self._zero, False
        f = t * t * (3.0 - 2.0 * t)
        v = view.velocities()[0][0]
        force = -(p.linear + p.quadratic * float(np.linalg.norm(v))) * f * v
        force[2] += p.density * p.gravity * self.volume * f
        view.apply(0, force)
        return force, self._zero, True
