"""Penalty contacts with Coulomb friction, specialised for a sphere (SPEC 2.5 response, the law
in kernels/contact_law.py).

``SphereCordContact``: a rigid sphere against the cords of a spring-mass network. Cords are
segments, so the ball can never slip between two net points; the force acts at the contact
point on the ball's surface, so friction spins it. When the network takes several substeps per
coupling step the contact is sub-cycled inside them (the network's sub-cycling hook).
``SpherePlaneContact``: a rigid sphere on a static plane (the floor).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SceneError, require_nonnegative, require_positive
from ..params import param
from ..kernels.contact import Sphere, colliders, sphere_elements, sphere_plane
from ..kernels.springs import point_forces
from ..systems.base import substeps
from .base import Interaction


@dataclass(frozen=True)
class ContactParams:
    """stiffness c_s (N/m), damping c_d (N s/m), friction mu (-), eps: the slip speed (m/s)
    below which friction is viscous; thickness: contact skin, e.g. a cord's radius (m);
    constraint: include the constraint term f_c; skin (a sphere on a plane): how far above
    the plane a contact is kept, where only the constraint force, lightened, acts, so that a
    resting ball rests inside its contact instead of leaving it every other step."""
    stiffness: float = param(2.0e3, "N/m", ge=1e-6, le=1e9, doc="penalty stiffness c_s")
    damping: float = param(2.0, "N s/m", ge=0.0, le=1e7, doc="penalty damping c_d")
    friction: float = param(0.5, "-", ge=0.0, le=10.0, doc="Coulomb coefficient mu")
    eps: float = param(0.05, "m/s", ge=1e-6, le=100.0, doc="slip speed of full friction")
    thickness: float = param(0.003, "m", ge=0.0, le=1.0, doc="contact skin")
    constraint: bool = param(True, doc="include the constraint force f_c")
    skin: float = param(0.002, "m", ge=0.0, le=1.0, doc="sphere on a plane: contact kept "
                        "this far above it")

    def validated(self, owner: str) -> "ContactParams":
        require_positive(owner, "contact stiffness", self.stiffness, "N/m")
        require_nonnegative(owner, "contact damping", self.damping, "N s/m")
        require_nonnegative(owner, "friction", self.friction)
        require_positive(owner, "friction eps", self.eps, "m/s")
        require_nonnegative(owner, "contact thickness", self.thickness, "m")
        return self

    def law(self) -> np.ndarray:
        """The law's row (kernels/contact.py): thickness, c_s, c_d, mu, eps, constraint."""
        return np.array([self.thickness, self.stiffness, self.damping, self.friction,
                         self.eps, 1.0 if self.constraint else 0.0])


def sphere_of(name, system):
    """(the system's BodiesView, its sphere's radius m), or SceneError when its first part is
    not a sphere."""
    view = system.contact_view()
    prim = view.primitives[0] if view is not None and view.kind == "bodies" else None
    if prim is None or prim.kind != "sphere":
        raise SceneError(f"interaction {name}: {system.name} is not a sphere; this contact "
                         "needs a body whose contact view is one sphere (use MeshContact for "
                         "other shapes)")
    return view, prim.radius


def _ball(view, radius) -> Sphere:
    """The sphere's state now as the contact kernels read it."""
    v, w = view.velocities()
    return Sphere(view.centres()[0], v[0], w[0], radius, float(view.masses[0]),
                  view.free_accelerations()[0])


class SphereCordContact(Interaction):
    """Contact of a rigid sphere (primary) with the springs of a network (secondary); segments
    (s,2): the cords that collide (default all of its springs)."""

    def __init__(self, name, ball, network, params: ContactParams = ContactParams(),
                 mode="two-way", standin=None, segments=None):
        super().__init__(name, ball, network, mode, standin)
        self.p = params.validated(name)
        self.ball, self.radius = sphere_of(name, ball)
        self.net = network.contact_view()
        self.seg = np.ascontiguousarray(self.net.segments if segments is None else segments,
                                        dtype=np.int64)
        self._out = point_forces(2 * len(self.seg))
        self._wrench = np.zeros(6)
        self._law = self.p.law()
        self._cols = colliders(1)
        self._k = 0
        self._h, self._subcycle = 0.0, False
        self._zero_acc = np.zeros((len(self.net.x), 3))

    def prepare(self, h, dts=None):
        """When the network takes several substeps per coupling step, the contact is
        sub-cycled inside its kernel against the ball's predicted path, and the ball receives
        the step's mean force; an implicit network (one that takes Jacobians) always takes
        it there, to solve the ball's velocity with its points."""
        self._h = h
        dt = (dts or {}).get(self.secondary.name, self.secondary.dt)
        self._subcycle = substeps(h, dt) > 1 or self.net.jacobians

    def exchange(self, to_primary, to_secondary):
        ball = _ball(self.ball, self.radius)
        if self._subcycle and to_secondary:
            c = self._cols
            c.centres[0], c.velocities[0], c.spins[0], c.accels[0] = ball.c, ball.v, ball.w, ball.acc
            c.radii[0], c.masses[0], c.law[0] = ball.radius, ball.mass, self._law
            if self.net.subcycle(c, self.seg):
                return None
        pt_acc = self.net.accelerations() if self.p.constraint else self._zero_acc
        self._k = k = sphere_elements(ball, self.net.points, pt_acc, self.seg, self._law,
                                      self._h, self._out, True, self._wrench)
        if k == 0:
            return self._wrench[:3], self._wrench[3:], False
        if to_primary:
            self.ball.apply(0, self._wrench[:3], self._wrench[3:])
        if to_secondary:
            o = self._out
            self.net.apply(o.idx[:k], o.f[:k], o.dfdx[:k], o.dfdv[:k], o.vref[:k])
        return self._wrench[:3].copy(), self._wrench[3:].copy(), True

    def complete(self, to_primary):
        """After the network's sub-cycled advance: the mean force and torque of the step."""
        imp = self._cols.impulses[0]
        f, tau = imp[:3] / self._h, imp[3:6] / self._h
        if to_primary:
            self.ball.apply(0, f, tau)
        return f, tau, bool(imp[6] > 0.0), imp[6]

    def point_forces(self):
        """The last lock-step exchange's (indices, forces) on the network's points."""
        return self._out.idx[:self._k], self._out.f[:self._k]


class SpherePlaneContact(Interaction):
    """A rigid sphere (primary) bouncing and rolling on a static plane (secondary)."""

    def __init__(self, name, ball, plane, params: ContactParams, mode="two-way"):
        super().__init__(name, ball, plane, mode)
        self.p = params.validated(name)
        self.ball, self.radius = sphere_of(name, ball)
        self.height = plane.contact_view().height
        if self.height is None:
            raise SceneError(f"interaction {name}: {plane.name} is not a plane")
        self._law = self.p.law()
        self._wrench = np.zeros(6)
        self._dfdx = np.zeros((3, 3))
        self._dfdx[2, 2] = -self.p.stiffness
        self._dfdv = np.zeros((3, 3))
        self._dfdv[2, 2] = -self.p.damping
        self._h = 0.0

    def prepare(self, h, dts=None):
        self._h = h  # the friction cap: the force is held over the whole coupling step

    def exchange(self, to_primary, to_secondary):
        inertia = 1.0 / self.ball.inverse_inertias()[0, 0, 0]  # a sphere's is isotropic
        on = sphere_plane(_ball(self.ball, self.radius), inertia, self.height, self._law,
                          self._h, self.p.skin, self._wrench)
        if on and to_primary:
            # the normal penalty's Jacobians let the ball integrate the bounce implicitly
            self.ball.apply(0, self._wrench[:3], self._wrench[3:], dfdx=self._dfdx,
                            dfdv=self._dfdv)
        return self._wrench[:3].copy(), self._wrench[3:].copy(), on
