"""Penalty contacts with Coulomb friction, specialised for a sphere (SPEC 2.5 response).

``SphereCordContact``: a rigid sphere against the cords of a spring-mass network. Cords are
segments, so the ball can never slip between two net points; the force acts at the contact
point on the ball's surface, so friction spins it.
``SpherePlaneContact``: a rigid sphere on a static plane (the floor).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require_nonnegative, require_positive
from ..kernels.contact import sphere_plane, sphere_segments
from .base import Interaction


@dataclass(frozen=True)
class ContactParams:
    """stiffness c_s (N/m), damping c_d (N s/m), friction mu (-), eps: the slip speed (m/s)
    below which friction is viscous; thickness: contact skin, e.g. a cord's radius (m);
    constraint: include the constraint term f_c."""
    stiffness: float = 2.0e3
    damping: float = 2.0
    friction: float = 0.5
    eps: float = 0.05
    thickness: float = 0.003
    constraint: bool = True

    def validated(self, owner: str) -> "ContactParams":
        require_positive(owner, "contact stiffness", self.stiffness, "N/m")
        require_nonnegative(owner, "contact damping", self.damping, "N s/m")
        require_nonnegative(owner, "friction", self.friction)
        require_positive(owner, "friction eps", self.eps, "m/s")
        require_nonnegative(owner, "contact thickness", self.thickness, "m")
        return self


class SphereCordContact(Interaction):
    """Contact of a rigid sphere (primary) with the springs of a network (secondary)."""

    def __init__(self, name, ball, network, params: ContactParams = ContactParams(),
                 mode="two-way", standin=None, segments=None):
        super().__init__(name, ball, network, mode, standin)
        self.p = params.validated(name)
        self.seg = np.ascontiguousarray(network.segments() if segments is None else segments,
                                        dtype=np.int64)
        ns = len(self.seg)
        self._idx = np.zeros(2 * ns, dtype=np.int64)
        self._f = np.zeros((2 * ns, 3))
        self._dfdx = np.zeros((2 * ns, 3, 3))
        self._dfdv = np.zeros((2 * ns, 3, 3))
        self._vref = np.zeros((2 * ns, 3))
        self._wrench = np.zeros(6)
        self._k = 0
        self._h, self._subcycle, self._slot = 0.0, False, 0
        self._contact6 = (self.p.thickness, self.p.stiffness, self.p.damping, self.p.friction,
                          self.p.eps, 1.0 if self.p.constraint else 0.0)
        self._zero_acc = np.zeros((network.x.shape[0], 3))

    def prepare(self, h):
        """Called once per pass with the coupling step h (s): when the network takes several
        substeps per coupling step, the contact is sub-cycled inside the network's kernel
        against the ball's predicted path, and the ball receives the step's mean force."""
        self._h = h
        self._subcycle = self.secondary.dt < h * (1.0 - 1e-9)

    def exchange(self, to_primary, to_secondary):
        ball, net, p = self.primary, self.secondary, self.p
        if self._subcycle and to_secondary:
            acc = ball.gravity + ball.force / ball.mass
            self._slot = net.add_moving_sphere(self.seg, ball.x.copy(), ball.v.copy(),
                                               ball.w.copy(), acc, ball.radius, ball.mass,
                                               self._contact6)
            return None
        if p.constraint:
            pt_acc = net.internal_forces() / net.m[:, None]
        else:
            pt_acc = self._zero_acc
        self._k = k = sphere_segments(ball.x, ball.v, ball.w, ball.radius, ball.mass, ball.gravity,
                            net.x, net.v, net.m, pt_acc, self.seg, p.thickness, p.stiffness,
                            p.damping, p.friction, p.eps, p.constraint,
                            self._h, self._idx, self._f,
                            self._dfdx, self._dfdv, self._vref, self._wrench)
        if k == 0:
            return self._wrench[:3], self._wrench[3:], False
        if to_primary:
            ball.force += self._wrench[:3]
            ball.torque += self._wrench[3:]
        if to_secondary:
            net.add_point_forces(self._idx[:k], self._f[:k], self._dfdx[:k], self._dfdv[:k],
                                 self._vref[:k])
        return self._wrench[:3].copy(), self._wrench[3:].copy(), True

    def complete(self, to_primary):
        """After the network's sub-cycled advance: the mean force and torque of the step."""
        imp = self.secondary.impulses[self._slot]
        f, tau = imp[:3] / self._h, imp[3:6] / self._h
        if to_primary:
            self.primary.force += f
            self.primary.torque += tau
        return f, tau, bool(imp[6] > 0.0), imp[6]

    def point_forces(self):
        """The last exchange's (indices, forces) on the network's points (for checks)."""
        return self._idx[:self._k], self._f[:self._k]


class SpherePlaneContact(Interaction):
    """A rigid sphere (primary) bouncing and rolling on a static plane (secondary)."""

    def __init__(self, name, ball, plane, params: ContactParams, mode="two-way"):
        super().__init__(name, ball, plane, mode)
        self.p = params.validated(name)
        self._wrench = np.zeros(6)
        self._dfdx = np.zeros((3, 3))
        self._dfdx[2, 2] = -self.p.stiffness
        self._dfdv = np.zeros((3, 3))
        self._dfdv[2, 2] = -self.p.damping
        self._h = 0.0

    def prepare(self, h):
        self._h = h  # the friction cap: the force is held over the whole coupling step

    def exchange(self, to_primary, to_secondary):
        ball, p = self.primary, self.p
        on = sphere_plane(ball.x, ball.v, ball.w, ball.radius, ball.mass, ball.inertia_body[0],
                          ball.gravity[2], self.secondary.height, p.stiffness, p.damping,
                          p.friction, p.eps, self._h, self._wrench)
        if on and to_primary:
            # the normal penalty's Jacobians let the ball integrate the bounce implicitly
            ball.add_wrench(self._wrench[:3], self._wrench[3:], dfdx=self._dfdx,
                            dfdv=self._dfdv)
        return self._wrench[:3].copy(), self._wrench[3:].copy(), on
