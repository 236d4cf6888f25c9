"""Attachments: stiff damped zero-length springs between network points and points fixed on
the rigid parts of another system (a cord's two ankle straps tied to a figure's ankles, a kite's
sail tied along its spars, its bridle to the frame, its lines to a pilot's handles). Two-way or
one-way. One interaction carries all the ties between a network and a body, so its force log
is the whole pull of the network on it; the ties are evaluated together, in one kernel call
per stage (``kernels.attachment``: no Python per tie), and each tied part gets one wrench, the
sum of its ties'."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..kernels import attachment as K
from ..params import param
from .base import Interaction


@dataclass(frozen=True)
class AttachmentParams:
    """stiffness (N/m) and damping (N s/m) of each tie."""
    stiffness: float = param(2.0e4, "N/m", ge=1e-6, le=1e9, doc="each tie")
    damping: float = param(100.0, "N s/m", ge=0.0, le=1e7, doc="each tie")


class SegmentAttachment(Interaction):
    """Ties network points to points ``local`` (m, in the part's frame: one (3,) for every tie
    or one row (n,3) per tie) on parts of a body: ``ties`` is a sequence of (network point
    index, part name), each tie a spring of the given stiffness and damping. The body (a
    figure, a rigid body: anything seen as rigid parts) is the primary, the network (seen as
    points) the secondary.

    carry=False: the body feels each tie's force, equal and opposite to the network's, held
    over the coupling step: explicit on the body's side. That is stable while the ties are
    soft beside the mass they drag along in a step (k h^2 < m: a flying line, a tail), but a
    network tied stiffly to a body lighter than about twice itself is unstable at any step
    (the added-mass instability of partitioned schemes: Causin, Gerbeau & Nobile, CMAME 194,
    2005): a sail sewn to its spars. carry=True (one tied part, of a body that carries points:
    a free rigid body): the part carries the whole network, as a frame carries its sail. The
    network's mass and inertia are added to the part's over the step and the part feels every
    force on the network's points at the step's end except the ties' (their weight, the air,
    the ground: the springs between them cancel, and so do their moments), while the network
    moves on its own, held to the part by the ties. The part then moves as the body and
    network would if rigidly joined, under the network's loads as its shape makes them: the
    mean-axis approximation of flexible flight dynamics, which neglects the inertial
    coupling of the deformation (Waszak & Schmidt, J. Aircraft 25(6), 1988). Momentum is
    exact for the composite; the true momentum differs from it by the network's momentum
    relative to the part, which stays bounded. Stable for any mass ratio."""

    def __init__(self, name, body, network, ties, local=(0.0, 0.0, 0.0),
                 params: AttachmentParams = AttachmentParams(), mode="two-way",
                 carry: bool = False):
        super().__init__(name, body, network, mode)
        self.k = require_positive(name, "stiffness", params.stiffness, "N/m")
        self.c = require_nonnegative(name, "damping", params.damping, "N s/m")
        self.body = body.contact_view()
        self.net = network.contact_view()
        ties = [(int(i), str(part)) for i, part in ties]
        unknown = [part for _, part in ties if part not in self.body.names]
        if unknown or not ties:
            raise ParameterError(f"{name}: ties {unknown or ties!r} name no part of "
                                 f"{body.name}; choose from {', '.join(self.body.names)}")
        self.index = np.array([i for i, _ in ties], dtype=np.int64)
        if self.index.min() < 0 or self.index.max() >= len(self.net.x):
            raise ParameterError(f"{name}: tie points {self.index.tolist()} must be points "
                                 f"0..{len(self.net.x) - 1} of {network.name}")
        self.parts = np.array([self.body.part(part) for _, part in ties], dtype=np.int64)
        n = len(ties)
        local = np.asarray(local, dtype=float)
        if local.shape not in ((3,), (n, 3)) or not np.all(np.isfinite(local)):
            raise ParameterError(f"{name}: local tie points must be one finite (3,) point or "
                                 f"one per tie ({n},3) m, got shape {local.shape}")
        self.local = np.broadcast_to(local, (n, 3)).copy()
        # the parts tied, once each: velocities are asked for once per part, wrenches summed
        self._uniq, self._inv = np.unique(self.parts, return_inverse=True)
        self.carry = bool(carry)
        if self.carry and len(self._uniq) > 1:
            raise ParameterError(f"{name}: a carried network is tied to one part, not "
                                 f"{len(self._uniq)}; tie {network.name} to one part or use "
                                 "carry=False")
        self._jac = np.broadcast_to(-self.k * np.eye(3), (n, 3, 3)).copy()
        self._djac = np.broadcast_to(-self.c * np.eye(3), (n, 3, 3)).copy()
        self._f = np.zeros((n, 3))
        self._held = np.zeros((n, 3))  # the tie forces held on the network over the step
        self._last = np.full(3, np.nan)  # m/s: the carrying part's velocity a step ago
        self._p = np.zeros((n, 3))
        self._v = np.zeros((n, 3))
        self._force = np.zeros((len(self._uniq), 3))  # per tied part: N
        self._moment = np.zeros((len(self._uniq), 3))  # N m
        m = len(self.net.x)
        self._r = np.zeros((m, 3))  # a carried network's points from the part's centre (m)
        self._load = np.zeros((m, 3))  # their loads but the ties' (N)
        self._h = 0.0

    def _tie_points(self):
        """World positions (m) and velocities (m/s) of the tie points, from the body's current
        state (a figure's advance leaves its kinematics and velocities current)."""
        pos, R = self.body.poses()
        lin, ang = self.body.velocities(self._uniq)
        K.tie_points(pos, R, self.body.centres(), lin, ang, self.parts, self._inv, self.local,
                     self._p, self._v)

    def prepare(self, h, dts=None):
        self._h = h

    def exchange(self, to_primary, to_secondary):
        """Pull the network points toward the tie points now and defer the body's side: the
        network advances first, with each tie point moving on at its current velocity through
        the step (``vref``), and ``complete`` gives the body the force the network felt."""
        self._tie_points()
        net, i = self.net, self.index
        K.tie_forces(net.x, net.v, i, self._p, self._v, 0.0, self.k, self.c, self._f)
        if to_secondary:
            self._held[:] = -self._f
            net.apply(i, self._held, self._jac, self._djac, self._v)
            return None
        self._held[:] = 0.0
        return self._finish(to_primary)

    def complete(self, to_primary):
        """After the network's step. Not carried: the tie force at its end, the network points
        where the implicit step put them and the tie points carried on at their velocities,
        i.e. what the network was pulled with over the step (for a massless network end, what
        the rest of the network transmits: a slack light cord leaves the body alone). Carried:
        the network's load (``_carry``)."""
        net, i = self.net, self.index
        if self.carry:
            return self._carry(to_primary)
        K.tie_forces(net.x, net.v, i, self._p, self._v, self._h, self.k, self.c, self._f)
        return self._finish(to_primary)

    def capture(self) -> dict:
        return {"last": self._last.copy()}

    def restore(self, snap: dict) -> None:
        self._last[:] = snap["last"]

    def _finish(self, to_primary):
        """Each tied part gets the sum of its ties' forces at its centre of mass and the sum
        of their moments about it (the same wrench as each force at its own point)."""
        total, torque = K.tie_wrenches(self._p, self._f, self.body.centres(), self.parts,
                                       self._inv, self.body.centre_of_mass(), self._force,
                                       self._moment)
        if to_primary:
            for u, part in enumerate(self._uniq):  # once per part, not per tie
                self.body.apply(int(part), self._force[u], torque=self._moment[u])
        return total, torque, True

    def _carry(self, to_primary):
        """Give the part the network to carry: its mass, its inertia about the part's centre
        of mass and every force on its points at the step's end but the ties' (the sum of
        each point's mass times its acceleration, less the ties' held forces), with their
        moment about the part's centre at the points' own positions. The part's centre is
        not the composite's: its turning also answers the network's mass moment S = sum m r
        dragged at the part's acceleration a (I alpha = tau - S x a; without it a sail's
        weight would turn a falling frame), taken over the last step (explicit: S is
        centimetre-kilograms beside the inertia)."""
        net, part = self.net, int(self._uniq[0])
        c = self.body.centres()[part]
        force, moment, mass_moment = K.carried_load(net.x, net.accelerations(), net.masses,
                                                    self.index, self._held, c, self._r,
                                                    self._load)
        lin = self.body.velocities(self._uniq)[0][0]
        if np.all(np.isfinite(self._last)) and self._h > 0.0:
            moment -= _cross(mass_moment, (lin - self._last) / self._h)
        self._last[:] = lin
        if to_primary:
            m, r = net.masses, self._r
            inertia = (m * np.einsum("ki,ki->k", r, r)).sum() * np.eye(3) - np.einsum(
                "k,ki,kj->ij", m, r, r)
            self.body.apply(part, force, torque=moment, carried=(m.sum(), inertia))
        torque = moment + _cross(c - self.body.centre_of_mass(), force)
        return force, torque, True


def _cross(a, b):
    """a x b of two 3-vectors as np.cross computes it, without its general-shape overhead
    (several microseconds; twice per coupling step of a carried network)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])
