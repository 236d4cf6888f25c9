"""Stand-ins for hybrid coupling: cheap fields that act on the primary alone (SPEC 1, 4)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require_nonnegative
from ..params import param
from ..kernels.contact import sphere_segment_overlap
from ..kernels.lids import submerged
from .base import StandIn
from .contact import sphere_of
from .immersion import ImmersedParts

#: kg/m^3: the form drag's fluid when the field leaves buoyancy out (density 0)
WATER_DENSITY = 1000.0


@dataclass(frozen=True)
class DampingFieldParams:
    """Coefficients of the net's damping field.

    linear: N s/m per unit overlap, angular: N m s per unit overlap; overlap is the sum over the
    rest-shape cords the ball penetrates of (penetration depth / ball radius). The defaults are
    fitted to the default two-way basketball (``interplay fit-standin basketball``).
    """
    # fitted: `interplay fit-standin basketball` (docs/coupling.md)
    linear: float = param(0.2342, "N s/m", ge=0.0, le=1e6, doc="per unit overlap")
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
    quadratic (N s^2/m^2) drag on each part at full submersion, scaled by its submerged
    fraction; density (kg/m^3): > 0 adds buoyancy density g V_sub (Archimedes at the still
    surface), 0 leaves it out (a pure damping field); gravity (m/s^2)."""
    surface: float = param(0.0, "m", ge=-1e4, le=1e4, doc="still surface height")
    linear: float = param(2.0, "N s/m", ge=0.0, le=1e6)
    quadratic: float = param(20.0, "N s^2/m^2", ge=0.0, le=1e6)
    density: float = param(0.0, "kg/m^3", ge=0.0, le=1e5, doc="0: no buoyancy")
    gravity: float = param(9.81, "m/s^2", ge=0.0, le=100.0)
    enabled: bool = True


#: chords sampled across each part's shadow for its volume below the still surface (16 x 16:
#: the submerged fraction of a part half under is exact by symmetry, elsewhere within ~1 %)
FIELD_SAMPLES = 16


class ViscousDragField(StandIn):
    """Drag and buoyancy on the submerged parts of a body below a flat surface (hybrid
    coupling with water), acting on every part of its BodiesView that has a sphere,
    ellipsoid, capsule or box primitive (a ball, a figure's segments):

        F_k = -(linear + quadratic |v_k|) f_k v_k + density g V_k f_k z_hat  [+ form drag]

    with f_k the part's submerged fraction (its chords cut by the surface: the same solids
    the water's columns see) and the buoyancy at its centre of buoyancy. ``form``: a
    BuoyancyParams whose shape drag (interactions/immersion.py) the field adds against the
    still water, the law the two-way interaction applies against the moving water (None:
    only the linear and quadratic terms)."""

    name = "viscous drag field"

    def __init__(self, params: ViscousDragFieldParams, form=None):
        require_nonnegative("viscous drag field", "linear", params.linear, "N s/m")
        require_nonnegative("viscous drag field", "quadratic", params.quadratic, "N s^2/m^2")
        require_nonnegative("viscous drag field", "density", params.density, "kg/m^3")
        self.p = params
        self.form = form.validated("viscous drag field") if form is not None else None
        self._parts = {}
        self._zero = np.zeros(3)

    def _of(self, body):
        view = body.contact_view()
        if view.name not in self._parts:
            parts = ImmersedParts(view)
            self._parts[view.name] = parts, np.zeros((parts.count, 4))
        return self._parts[view.name]

    def act(self, body):
        p = self.p
        if not p.enabled:
            return self._zero, self._zero, False
        parts, sub = self._of(body)
        solids = parts.update()
        submerged(solids, p.surface, FIELD_SAMPLES, sub)
        vsub = sub[:, 0]
        wet = vsub > 0.0
        if not wet.any():
            return self._zero, self._zero, False
        frac = vsub / parts.volume
        v = parts.velocity
        speed = np.linalg.norm(v, axis=1)
        force = -((p.linear + p.quadratic * speed) * frac)[:, None] * v
        torque = np.zeros_like(v)
        if self.form is not None:
            rho = p.density or WATER_DENSITY
            force += parts.drag(v, frac, rho, self.form.form)
            torque += parts.rotational_drag(parts.spin, frac, rho, self.form.normal_drag,
                                            self.form.rotational_drag)
        torque += np.cross(solids.centre - parts.com, force)
        buoy = np.zeros_like(v)
        buoy[:, 2] = p.density * p.gravity * vsub
        force += buoy
        torque += np.cross(sub[:, 1:4] - parts.com, buoy)
        f, t = parts.exert(wet, force, torque)
        return f, t, True
