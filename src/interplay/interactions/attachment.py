"""Attachments: a stiff damped zero-length spring between a network point and a point fixed on
a figure segment (a cord tied to an ankle). Equal and opposite forces; two-way or one-way."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require_nonnegative, require_positive
from .base import Interaction


@dataclass(frozen=True)
class AttachmentParams:
    """stiffness (N/m) and damping (N s/m) of the tie."""
    stiffness: float = 2.0e4
    damping: float = 100.0


class SegmentAttachment(Interaction):
    """Ties network point ``index`` to ``local`` (m, segment frame) on figure segment
    ``segment``. The figure is the primary, the network the secondary."""

    def __init__(self, name, figure, network, index: int, segment: str, local=(0.0, 0.0, 0.0),
                 params: AttachmentParams = AttachmentParams(), mode="two-way"):
        super().__init__(name, figure, network, mode)
        self.k = require_positive(name, "stiffness", params.stiffness, "N/m")
        self.c = require_nonnegative(name, "damping", params.damping, "N s/m")
        self.index = int(index)
        self.segment = segment
        self.local = np.asarray(local, dtype=float)
        self._vel = np.zeros(6)
        self._jac = np.zeros((1, 3, 3))
        self._jac[0] = -self.k * np.eye(3)
        self._djac = np.zeros((1, 3, 3))
        self._djac[0] = -self.c * np.eye(3)

    def point(self):
        """World position (m) and velocity (m/s) of the tie point on the segment."""
        fig = self.primary
        from ..geometry.anthropometry import SEGMENTS
        b = fig.seg_body[SEGMENTS.index(self.segment)]
        d = fig.data
        R = d.xmat[b].reshape(3, 3)
        p = d.xpos[b] + R @ self.local
        fig._mj.mj_objectVelocity(fig.model, d, fig._mj.mjtObj.mjOBJ_BODY, b, self._vel, 0)
        v = self._vel[3:] + np.cross(self._vel[:3], p - d.xipos[b])
        return p, v

    def exchange(self, to_primary, to_secondary):
        net = self.secondary
        p, v = self.point()
        x, u = net.x[self.index], net.v[self.index]
        f = self.k * (x - p) + self.c * (u - v)  # on the figure, toward the cord point
        if to_primary:
            self.primary.add_wrench(f, point=p, body=self.segment)
        if to_secondary:
            net.add_point_forces([self.index], -f[None, :], self._jac, self._djac, v[None, :])
        return f, np.cross(p - self.primary.com(), f), True
