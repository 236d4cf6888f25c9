"""A trampoline bed's stand-in for hybrid coupling (beyond the paper): vertical spring-dampers
under the contact points of a body, fitted to the bed's load-deflection curve.

The bed is pressed down under the body's deepest support point (a box's corners, the
bottoms of a capsule's end spheres, a sphere's bottom), D = max d_i below the bed's rest
surface, and wraps it in a pocket of depth ``pocket``: the points within it (d_i > D -
pocket, the soles of flat feet, not the knees above them) carry a share in proportion to
d_i - (D - pocket) of the bed's vertical force

    F = linear D + quadratic D^2 + cubic D^3 + damping dD/dt   (>= 0),

a polynomial fitted (``fit_curve``) to the full bed's static load-deflection under a load on
a 0.3 m square (scenes/trampoline.load_deflection): not a spring's straight line, since the
bed hangs on horizontal springs and stiffens as it is pressed into a funnel (Kraft 2001).
Tangentially the points cannot slide: a viscous force -friction_damping v per point against
its horizontal velocity (a foot turning in the pocket drags its toes over the bed, as on the
real one), capped at mu times the point's normal share; or, with ``eps`` > 0, the contact
law's regularised Coulomb friction (kernels/contact_law.sliding_friction, the law the full
rigid-parts contact applies on the network's side): mu times the normal share times
min(1, |v_t| / eps), capped at the force that stops the point's slip within the coupling
step (its share of the part's mass), so that the stand-in and the two-way contact hold a
planted foot by the same law; or, with ``stick`` > 0, the grid's springs cannot slide: each
point is held by a tangential spring-damper to where it touched down (its anchor), which
slips, dragging the anchor, only past mu times its normal share, so a foot pushed steadily
comes to rest instead of creeping at the capped law's F h / m. A stand-in has no mass,
no horizontal pull towards the bed's centre and no recoil lag of its own: what the two-way run
adds is measured in docs/trampoline.md.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative
from ..params import param
from .base import StandIn

DEPTH_MAX = 1.5  # m: the depressions over which a curve must rise


@dataclass(frozen=True)
class BedSpringsParams:
    """linear (N/m), quadratic (N/m^2), cubic (N/m^3): the bed's vertical force at depression
    D (``fit_curve``); damping (N s/m) of the depression rate; pocket (m): how far above the
    deepest point a support point still touches the bed; friction_damping (N s/m) per
    point against sliding, friction (-) its cap over the normal share; eps (m/s): when > 0
    the tangential law is the contact law's regularised Coulomb friction instead (full at
    this slip speed; friction_damping is then unused); stick (N/m), stick_damping (N s/m):
    when stick > 0 each touching point's tangential spring and damper to its anchor instead
    (eps and friction_damping unused), capped at friction times its share; enabled: false
    turns the stand-in off (the hybrid primary then falls freely)."""
    # fitted to BedParams() (docs/trampoline.md)
    linear: float = param(1953.0, "N/m", ge=0.0, le=1e7)
    quadratic: float = param(4172.0, "N/m^2", ge=-1e7, le=1e7)
    cubic: float = param(-260.0, "N/m^3", ge=-1e7, le=1e7)
    damping: float = param(40.0, "N s/m", ge=0.0, le=1e5)
    pocket: float = param(0.05, "m", ge=0.0, le=1.0)
    friction_damping: float = param(200.0, "N s/m", ge=0.0, le=1e6)
    friction: float = param(0.8, "-", ge=0.0, le=10.0)
    eps: float = param(0.0, "m/s", ge=0.0, le=10.0,
                       doc="> 0: the contact law's Coulomb friction, full at this slip")
    stick: float = param(0.0, "N/m", ge=0.0, le=1e7, doc="> 0: points anchored where they touched")
    stick_damping: float = param(0.0, "N s/m", ge=0.0, le=1e6)
    enabled: bool = param(True, doc="false: the hybrid primary falls freely")

    def validated(self) -> "BedSpringsParams":
        for name, unit in (("linear", "N/m"), ("damping", "N s/m"), ("pocket", "m"),
                           ("friction_damping", "N s/m"), ("friction", "")):
            require_nonnegative("bed springs", name, getattr(self, name), unit)
        d = np.linspace(0.0, DEPTH_MAX, 31)
        f = self.force(d)
        if not (np.all(np.isfinite(f)) and np.all(np.diff(f) >= 0.0)):
            raise ParameterError(f"bed springs: the curve {self.linear:g} D + "
                                 f"{self.quadratic:g} D^2 + {self.cubic:g} D^3 N must rise "
                                 f"from 0 to {DEPTH_MAX} m of depression; refit it")
        return self

    def force(self, depth):
        """The curve's force (N) at depression(s) ``depth`` (m), without damping."""
        return (self.linear + (self.quadratic + self.cubic * depth) * depth) * depth


def fit_curve(depressions, forces):
    """Least-squares (linear N/m, quadratic N/m^2, cubic N/m^3) of F = a D + b D^2 + c D^3
    through measured (depression m, force N) pairs."""
    d = np.asarray(depressions, float)
    A = np.stack([d, d ** 2, d ** 3], axis=1)
    coef, *_ = np.linalg.lstsq(A, np.asarray(forces, float), rcond=None)
    return tuple(float(c) for c in coef)


def support_points(primitive):
    """(m,3) points of a primitive (part frame, m) that can be lowest: a box's corners, the
    two end centres of a capsule and a sphere's centre, with their radii (m,) (0 for
    corners); the lowest world point of each is its centre minus its radius along z."""
    if primitive.kind == "box":
        c, h = np.asarray(primitive.centre, float), np.asarray(primitive.axes, float)
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
        return c + corners * h, np.zeros(8)
    if primitive.kind == "capsule":
        return np.array([primitive.a, primitive.b], float), np.full(2, primitive.radius)
    if primitive.kind == "sphere":
        return np.array([primitive.centre], float), np.array([primitive.radius])
    raise ParameterError(f"bed springs: a {primitive.kind} primitive has no support points; "
                         "use spheres, capsules or boxes")


class BedSprings(StandIn):
    """The bed stand-in acting on a body seen as rigid parts (a figure)."""

    name = "bed springs"

    def __init__(self, params: BedSpringsParams, body, surface: float, step: float = 1e-3):
        self.p = params.validated()
        self.surface = float(surface)  # m: the resting bed's top, where the springs begin
        self.step = float(step)  # s: the coupling step the force is held for (eps > 0)
        view = body.contact_view()
        pts, rad, part = [], [], []
        for j, prim in enumerate(view.primitives):
            if prim is None:
                continue
            q, r = support_points(prim)
            pts.append(q)
            rad.append(r)
            part.append(np.full(len(q), j))
        self.local = np.concatenate(pts)
        self.radius = np.concatenate(rad)
        self.part = np.concatenate(part)
        self.masses = np.asarray(view.masses, float)
        self._zero = np.zeros(3)
        self.anchor = np.zeros((len(self.local), 2))  # m: where each point touched down
        self.held = np.zeros(len(self.local), bool)  # touching at the last call

    def capture(self) -> dict:
        return {"anchor": self.anchor.copy(), "held": self.held.copy()}

    def restore(self, snap: dict):
        self.anchor[:], self.held[:] = snap["anchor"], snap["held"]

    def act(self, body):
        p = self.p
        if not p.enabled:
            return self._zero, self._zero, False
        view = body.contact_view()
        origin, R = view.poses()
        x = np.einsum("kij,kj->ki", R[self.part], self.local) + origin[self.part]
        x[:, 2] -= self.radius  # each point's lowest world point
        depth = self.surface - x[:, 2]
        D = depth.max()
        if D <= 0.0:
            self.held[:] = False
            return self._zero, self._zero, False
        on = np.flatnonzero(depth > max(D - p.pocket, 0.0))
        part, xs, d = self.part[on], x[on], depth[on] - max(D - p.pocket, 0.0)
        # velocities of the touching parts only (a figure asks MuJoCo once per part)
        touched, slot = np.unique(part, return_inverse=True)
        lin, ang = view.velocities(touched)
        com = view.centres()
        r = xs - com[part]
        v = lin[slot] + np.cross(ang[slot], r)
        deep = int(np.argmax(d))
        fz = max(p.force(D) - p.damping * v[deep, 2], 0.0)  # dD/dt = -v_z
        share = fz * d / d.sum()
        f = np.zeros((len(on), 3))
        f[:, 2] = share
        vt = v[:, :2]
        speed = np.linalg.norm(vt, axis=1)
        if p.stick > 0.0:
            f[:, :2] = self._anchored(on, xs[:, :2], vt, p.friction * share)
        else:
            if p.eps > 0.0:
                # the contact law's friction (kernels/contact_law.sliding_friction), with each
                # point's share of its part's mass as the effective mass of the cap
                m = self.masses[part] / np.bincount(slot)[slot]
                fmag = np.minimum(p.friction * share * np.minimum(1.0, speed / p.eps),
                                  m * speed / self.step)
                cap = fmag / np.maximum(speed, 1e-12)
            else:
                cap = np.minimum(p.friction_damping,
                                 p.friction * share / np.maximum(speed, 1e-12))
            f[:, :2] = -cap[:, None] * vt
        tau = np.cross(r, f)
        for j in touched:
            sel = part == j
            view.apply(int(j), f[sel].sum(axis=0), tau[sel].sum(axis=0))
        view.touched(touched)
        total = f.sum(axis=0)
        torque = np.cross(xs - view.centre_of_mass(), f).sum(axis=0)
        return total, torque, True

    def _anchored(self, on, xy, vt, limit):
        """(m,2) N: the touching points' (``on``, at xy m, slipping at vt m/s) springs and
        dampers to their anchors, each capped at ``limit`` N; a point that just touched down
        is anchored where it is, a capped one drags its anchor to where the cap holds."""
        p = self.p
        anchor = self.anchor[on]
        new = ~self.held[on]
        anchor[new] = xy[new]
        ft = -p.stick * (xy - anchor) - p.stick_damping * vt
        mag = np.linalg.norm(ft, axis=1)
        slip = mag > limit
        ft[slip] *= (limit[slip] / mag[slip])[:, None]
        anchor[slip] = xy[slip] + (ft[slip] + p.stick_damping * vt[slip]) / p.stick
        self.anchor[on] = anchor
        self.held[:] = False
        self.held[on] = True
        return ft
