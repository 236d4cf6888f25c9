"""Linear blend skinning: points carried by the segments of a figure in proportion to their
weights (a body surface's vertices, a garment's points cut in the A-pose).

The weights (n, 17) are kept sparse, since a point is carried by a few segments (2-5 of 17 on
the body surface): posing 24k skin vertices every cloth step then costs a pass over their
~65k weights, not 17 passes over all of them (kernels/skinning.py).
"""
from __future__ import annotations

import numpy as np

from ..kernels.skinning import blend_positions, blend_velocities


class Skinning:
    """A-pose points x0 (n,3) m and their weights (n, segments), rows summing to 1."""

    def __init__(self, x0, weights):
        self.x0 = np.ascontiguousarray(x0, float)
        w = np.asarray(weights, float)
        rows, seg = np.nonzero(w)  # row-major: each point's segments in order
        self.seg, self.w = seg.astype(np.int64), np.ascontiguousarray(w[rows, seg])
        self.start = np.searchsorted(rows, np.arange(len(w) + 1)).astype(np.int64)

    def positions(self, A, b) -> np.ndarray:
        """(n,3) m: the points at the segments' transforms x = A x0 + b (A (k,3,3), b (k,3))."""
        out = np.empty_like(self.x0)
        blend_positions(self.x0, self.start, self.seg, self.w, np.ascontiguousarray(A),
                        np.ascontiguousarray(b), out)
        return out

    def velocities(self, A, b, lin, ang, centres) -> np.ndarray:
        """(n,3) m/s: the points' velocities for segment velocities lin (k,3) m/s at centres
        (k,3) m and ang (k,3) rad/s."""
        out = np.empty_like(self.x0)
        blend_velocities(self.x0, self.start, self.seg, self.w, np.ascontiguousarray(A),
                         np.ascontiguousarray(b), np.ascontiguousarray(lin, dtype=float),
                         np.ascontiguousarray(ang, dtype=float),
                         np.ascontiguousarray(centres, dtype=float), out)
        return out
