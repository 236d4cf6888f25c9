"""Attachments: stiff damped zero-length springs between network points and points fixed on
figure segments (a cord's two ankle straps tied to the ankles). Equal and opposite forces;
two-way or one-way. One interaction carries all the ties between a network and a figure, so
its force log is the whole pull of the network on the figure."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..geometry.anthropometry import SEGMENTS
from .base import Interaction


@dataclass(frozen=True)
class AttachmentParams:
    """stiffness (N/m) and damping (N s/m) of each tie."""
    stiffness: float = 2.0e4
    damping: float = 100.0


class SegmentAttachment(Interaction):
    """Ties network points to ``local`` (m, segment frame) on figure segments: ``ties`` is a
    sequence of (network point index, segment name), each tie a spring of the given stiffness
    and damping. The figure is the primary, the network the secondary."""

    def __init__(self, name, figure, network, ties, local=(0.0, 0.0, 0.0),
                 params: AttachmentParams = AttachmentParams(), mode="two-way"):
        super().__init__(name, figure, network, mode)
        self.k = require_positive(name, "stiffness", params.stiffness, "N/m")
        self.c = require_nonnegative(name, "damping", params.damping, "N s/m")
        ties = [(int(i), str(seg)) for i, seg in ties]
        unknown = [seg for _, seg in ties if seg not in SEGMENTS]
        if unknown or not ties:
            raise ParameterError(f"{name}: ties {unknown or ties!r} name no figure segment; "
                                 f"choose from {', '.join(SEGMENTS)}")
        self.index = np.array([i for i, _ in ties], dtype=np.int64)
        self.segments = [seg for _, seg in ties]
        self.bodies = [int(figure.seg_body[SEGMENTS.index(seg)]) for seg in self.segments]
        self.local = np.asarray(local, dtype=float)
        self._vel = np.zeros(6)
        n = len(ties)
        self._jac = np.broadcast_to(-self.k * np.eye(3), (n, 3, 3)).copy()
        self._djac = np.broadcast_to(-self.c * np.eye(3), (n, 3, 3)).copy()
        self._f = np.zeros((n, 3))
        self._p = np.zeros((n, 3))
        self._v = np.zeros((n, 3))
        self._h = 0.0

    def point(self, body: int):
        """World position (m) and velocity (m/s) of the tie point on a segment's body, from the
        figure's current state (Figure.advance leaves its kinematics and velocities current)."""
        fig = self.primary
        d = fig.data
        R = d.xmat[body].reshape(3, 3)
        p = d.xpos[body] + R @ self.local
        fig._mj.mj_objectVelocity(fig.model, d, fig._mj.mjtObj.mjOBJ_BODY, body, self._vel, 0)
        v = self._vel[3:] + np.cross(self._vel[:3], p - d.xipos[body])
        return p, v

    def prepare(self, h):
        self._h = h

    def exchange(self, to_primary, to_secondary):
        """Pull the network points toward the tie points now and defer the figure's side: the
        network advances first, with each tie point moving on at its current velocity through
        the step (``vref``), and ``complete`` gives the figure the force the network felt."""
        net = self.secondary
        for k, b in enumerate(self.bodies):
            self._p[k], self._v[k] = self.point(b)
        i = self.index
        self._f[:] = self.k * (net.x[i] - self._p) + self.c * (net.v[i] - self._v)
        if to_secondary:
            net.add_point_forces(i, -self._f, self._jac, self._djac, self._v)
            return None
        return self._finish(to_primary)

    def complete(self, to_primary):
        """After the network's step: the tie force at its end, the network points where the
        implicit step put them and the tie points carried on at their velocities, i.e. what
        the network was pulled with over the step. For a massless network end it is what the
        rest of the network transmits, so a slack light cord leaves the figure alone (no
        added mass of k h^2 + c h from a tie force lagging the figure's acceleration)."""
        net, i = self.secondary, self.index
        target = self._p + self._h * self._v
        self._f[:] = self.k * (net.x[i] - target) + self.c * (net.v[i] - self._v)
        return self._finish(to_primary)

    def _finish(self, to_primary):
        fig = self.primary
        com = fig.com()
        torque = np.zeros(3)
        for k, seg in enumerate(self.segments):
            if to_primary:
                fig.add_wrench(self._f[k], point=self._p[k], body=seg)
            torque += np.cross(self._p[k] - com, self._f[k])
        return self._f.sum(axis=0), torque, True
