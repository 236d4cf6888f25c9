"""Attachments: stiff damped zero-length springs between network points and points fixed on
the rigid parts of another system (a cord's two ankle straps tied to a figure's ankles).
Equal and opposite forces; two-way or one-way. One interaction carries all the ties between a
network and a body, so its force log is the whole pull of the network on it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..params import param
from .base import Interaction


@dataclass(frozen=True)
class AttachmentParams:
    """stiffness (N/m) and damping (N s/m) of each tie."""
    stiffness: float = param(2.0e4, "N/m", ge=1e-6, le=1e9, doc="each tie")
    damping: float = param(100.0, "N s/m", ge=0.0, le=1e7, doc="each tie")


class SegmentAttachment(Interaction):
    """Ties network points to ``local`` (m, in the part's frame) on parts of a body: ``ties`` is
    a sequence of (network point index, part name), each tie a spring of the given stiffness
    and damping. The body (a figure, a rigid body: anything seen as rigid parts) is the
    primary, the network (seen as points) the secondary."""

    def __init__(self, name, body, network, ties, local=(0.0, 0.0, 0.0),
                 params: AttachmentParams = AttachmentParams(), mode="two-way"):
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
        self.local = np.asarray(local, dtype=float)
        n = len(ties)
        self._jac = np.broadcast_to(-self.k * np.eye(3), (n, 3, 3)).copy()
        self._djac = np.broadcast_to(-self.c * np.eye(3), (n, 3, 3)).copy()
        self._f = np.zeros((n, 3))
        self._p = np.zeros((n, 3))
        self._v = np.zeros((n, 3))
        self._h = 0.0

    def _tie_points(self):
        """World positions (m) and velocities (m/s) of the tie points, from the body's current
        state (a figure's advance leaves its kinematics and velocities current)."""
        pos, R = self.body.poses()
        lin, ang = self.body.velocities(self.parts)
        com = self.body.centres()
        for k, part in enumerate(self.parts):
            self._p[k] = pos[part] + R[part] @ self.local
            self._v[k] = lin[k] + np.cross(ang[k], self._p[k] - com[part])

    def prepare(self, h, dts=None):
        self._h = h

    def exchange(self, to_primary, to_secondary):
        """Pull the network points toward the tie points now and defer the body's side: the
        network advances first, with each tie point moving on at its current velocity through
        the step (``vref``), and ``complete`` gives the body the force the network felt."""
        self._tie_points()
        net, i = self.net, self.index
        self._f[:] = self.k * (net.x[i] - self._p) + self.c * (net.v[i] - self._v)
        if to_secondary:
            net.apply(i, -self._f, self._jac, self._djac, self._v)
            return None
        return self._finish(to_primary)

    def complete(self, to_primary):
        """After the network's step: the tie force at its end, the network points where the
        implicit step put them and the tie points carried on at their velocities, i.e. what
        the network was pulled with over the step. For a massless network end it is what the
        rest of the network transmits, so a slack light cord leaves the body alone (no
        added mass of k h^2 + c h from a tie force lagging the body's acceleration)."""
        net, i = self.net, self.index
        target = self._p + self._h * self._v
        self._f[:] = self.k * (net.x[i] - target) + self.c * (net.v[i] - self._v)
        return self._finish(to_primary)

    def _finish(self, to_primary):
        com = self.body.centre_of_mass()
        torque = np.zeros(3)
        for k, part in enumerate(self.parts):
            if to_primary:
                self.body.apply(int(part), self._f[k], point=self._p[k])
            torque += np.cross(self._p[k] - com, self._f[k])
        return self._f.sum(axis=0), torque, True
