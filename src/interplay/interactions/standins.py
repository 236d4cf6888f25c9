"""Stand-ins for hybrid coupling: cheap fields that act on the primary alone (SPEC 1, 4)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require_nonnegative
from ..kernels.contact import sphere_segment_overlap
from .base import StandIn


@dataclass(frozen=True)
class DampingFieldParams:
    """Coefficients of the net's damping field.

    linear: N s/m per unit overlap, angular: N m s per unit overlap; overlap is the sum over the
    rest-shape cords the ball penetrates of (penetration depth / ball radius). The defaults are
    fitted to the default two-way basketball (``interplay fit-standin basketball``).
    """
    linear: float = 0.2062  # fitted: `interplay fit-standin basketball` (docs/coupling.md)
    angular: float = 0.0  # the default ball enters without spin; a field cannot create spin
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
        overlap = sphere_segment_overlap(ball.x, ball.radius, self.rest, self.seg,
                                         ball.radius + self.thickness)
        if overlap <= 0.0:
            return self._zero, self._zero, False
        f = -self.p.linear * overlap * ball.v
        tau = -self.p.angular * overlap * ball.w
        ball.force += f
        ball.torque += tau
        return f, tau, True
