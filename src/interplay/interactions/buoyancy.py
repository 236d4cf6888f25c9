"""A body in water (SPEC 2.4, objects in water): buoyancy and drag on the body, external
pressure on the water.

The body (primary: any system whose contact view is a BodiesView with sphere, ellipsoid,
capsule or box primitives: a rigid Sphere, a KeyframedBody foot, a figure's 17 segments) is
cut by the water's columns at every coupling step (``Water.add_solids``; its parts are
interactions/immersion.py ``ImmersedParts``). Water rising into a part meets an external
pressure that holds it down (kernels/water.py ``heads``), so the water under it is pushed away
and rises around it; the volume that pressure keeps out, V_sub, is what the part displaces.
The water acts back on every part with

* buoyancy rho g V_sub (up) at its centre of buoyancy;
* drag by the part's shape (immersion.py), scaled by its submerged fraction, relative to the
  water around it (the column flow velocity, and the surface's vertical speed);
* rotational drag, so waves that tip the centre of buoyancy do not spin a ball forever and a
  limb swung under water is resisted;
* optionally added mass -C_a rho V_sub a_part, with a_part lagged one coupling step (explicit:
  stable only while C_a rho V_part < m_part, which the constructor checks).

Two-way applies both sides; one-way only the pressure on the water (the log still records
what the body would feel).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative
from ..params import param
from .base import Interaction
from .immersion import ImmersedParts

#: fewer columns than this across a body and the grid cannot resolve it
MIN_COLUMNS_ACROSS = 2
#: columns across a body the resolution warning recommends
GOOD_COLUMNS_ACROSS = 4


_ZERO = np.zeros(3)


class ResolutionWarning(UserWarning):
    """The water's columns are too coarse for a body."""


@dataclass(frozen=True)
class BuoyancyParams:
    """Drag coefficients (-) of the parts' shapes (interactions/immersion.py): drag C_d of a
    sphere or ellipsoid; normal_drag C_n of a capsule broadside and of a box's faces (a blunt
    body); axial_drag C_a of a capsule end-on (a rounded nose); rotational_drag C_r of a
    spinning sphere; added_mass C_a (-, 0.5 for a sphere, 0 off)."""
    drag: float = param(0.47, "-", ge=0.0, le=100.0, doc="C_d of a sphere or ellipsoid")
    normal_drag: float = param(1.0, "-", ge=0.0, le=100.0, doc="C_n of a capsule broadside")
    axial_drag: float = param(0.3, "-", ge=0.0, le=100.0, doc="C_a of a capsule end-on")
    rotational_drag: float = param(0.5, "-", ge=0.0, le=100.0, doc="C_r")
    added_mass: float = param(0.0, "-", ge=0.0, le=10.0, doc="C_a (0.5 for a sphere)")

    def validated(self, owner):
        for name in ("drag", "normal_drag", "axial_drag", "rotational_drag", "added_mass"):
            require_nonnegative(owner, name.replace("_", " ") + " coefficient",
                                getattr(self, name))
        return self

    @property
    def form(self) -> tuple:
        """(C_d, C_n, C_a): what ``ImmersedParts.drag`` takes."""
        return self.drag, self.normal_drag, self.axial_drag


class BodyInWater(Interaction):
    """Buoyancy and drag between a body (primary) and a Water system (secondary)."""

    def __init__(self, name, body, water, params: BuoyancyParams = BuoyancyParams(),
                 mode="two-way", standin=None):
        super().__init__(name, body, water, mode, standin)
        self.p = params.validated(name)
        self.body = body.contact_view()
        self.parts = ImmersedParts(self.body)
        across = float(self.parts.width.max())
        l = water.spacing
        if across < MIN_COLUMNS_ACROSS * l:
            warnings.warn(
                f"{name}: {body.name} is {across:.3g} m across but the water's columns are "
                f"{l:.3g} m wide, too coarse to resolve it; use columns of at most "
                f"{across / GOOD_COLUMNS_ACROSS:.3g} m ({GOOD_COLUMNS_ACROSS} across it)",
                ResolutionWarning, stacklevel=2)
        m_added = self.p.added_mass * water.rho * self.parts.volume
        bad = np.flatnonzero(m_added >= self.parts.masses)
        if len(bad):
            k = bad[0]
            part = self.body.names[self.parts.parts[k]]
            raise ParameterError(
                f"{name}: added mass {m_added[k]:.3g} kg (C_a {self.p.added_mass}) is not "
                f"below {part}'s mass {self.parts.masses[k]:.3g} kg; the lagged added-mass "
                "force would be unstable: use added_mass < "
                f"{float((self.parts.masses / (water.rho * self.parts.volume)).min()):.3g} or 0")
        self._out = np.zeros((self.parts.count, 7))
        self._h = 0.0
        self.parts.update()
        self._v_prev = self.parts.velocity.copy()

    def prepare(self, h, dts=None):
        self._h = h
        self.parts.update()
        self._v_prev[:] = self.parts.velocity

    def capture(self):
        return {"v_prev": self._v_prev.copy()}

    def restore(self, snap):
        self._v_prev[:] = snap["v_prev"]

    def exchange(self, to_primary, to_secondary):
        water, p, parts = self.secondary, self.p, self.parts
        solids = parts.update()
        v = parts.velocity
        acc = (v - self._v_prev) / self._h if self._h > 0.0 else np.zeros_like(v)
        self._v_prev[:] = v
        if not to_secondary:
            return _ZERO, _ZERO, False  # the water's push is only known once it is pressed
        out = water.solid_loads(water.add_solids(solids), self._out)
        vsub = out[:, 0]
        wet = vsub > 0.0
        if not wet.any():
            return _ZERO, _ZERO, False
        rho = water.rho
        frac = vsub / parts.volume
        buoy = np.zeros_like(v)
        buoy[:, 2] = rho * water.g * vsub
        force = buoy + parts.drag(v - out[:, 4:7], frac, rho, p.form)
        if p.added_mass > 0.0:
            force -= p.added_mass * rho * vsub[:, None] * acc
        torque = np.cross(out[:, 1:4] - parts.com, buoy) + np.cross(
            solids.centre - parts.com, force - buoy)
        torque += parts.rotational_drag(parts.spin, frac, rho, p.normal_drag,
                                        p.rotational_drag)
        f, t = parts.exert(wet, force, torque, apply=to_primary)
        return f, t, True

    def submerged(self):
        """The last exchange's submerged volume (m^3) and centre of buoyancy (m) of the body
        (all its parts)."""
        out = self._out
        v = float(out[:, 0].sum())
        if v <= 0.0:
            return 0.0, self.parts.com.mean(axis=0)
        return v, (out[:, 0:1] * out[:, 1:4]).sum(axis=0) / v
