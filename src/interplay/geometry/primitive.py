"""Analytic collision primitives in a part's frame (what a body's contact view may offer
beside its mesh: water displacement and stand-in fields read them)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Primitive:
    """kind "sphere" (radius, centre), "ellipsoid" (semi-axes along the part's axes, centre),
    "capsule" (radius, segment ends a and b) or "box" (half extents ``axes``, centre; a
    radius > 0: its edges rounded by it within them, as the part contact sees it); m."""
    kind: str
    radius: float = 0.0
    axes: tuple = (0.0, 0.0, 0.0)
    a: tuple = (0.0, 0.0, 0.0)
    b: tuple = (0.0, 0.0, 0.0)
    centre: tuple = (0.0, 0.0, 0.0)

    @property
    def middle(self) -> np.ndarray:
        """(3,) its centre (a capsule's midpoint), m in the part's frame."""
        if self.kind == "capsule":
            return 0.5 * (np.asarray(self.a, float) + np.asarray(self.b, float))
        return np.asarray(self.centre, float)
