"""A set of springs between points (SPEC 2.1): what a spring-mass network is built from."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Springs:
    """A set of springs between points i and j.

    rest: rest length (m); stiffness: N/m; tension_only: cords that go slack when compressed.
    A negative rest length is a preloaded extension spring (a coil spring wound with initial
    tension, as a trampoline's): it pulls k (l - rest) at every length l, k |rest| even at
    zero length, so it is never slack; only springs that are not tension-only may have one,
    and the strain measure leaves them out.
    """
    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    stiffness: np.ndarray
    tension_only: np.ndarray

    @staticmethod
    def from_ratio(x, pairs, stress_strain: float, tension_only: bool = False) -> "Springs":
        """Springs on index pairs at their current lengths, k = (stress/strain ratio) / l0.

        stress_strain: force per unit strain (N), e.g. E*A for a cord; independent of resolution.
        """
        pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        rest = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
        with np.errstate(divide="ignore"):  # zero lengths are reported by SpringNetwork
            k = stress_strain / rest
        return Springs(pairs[:, 0].copy(), pairs[:, 1].copy(), rest, k,
                       np.full(len(pairs), bool(tension_only)))

    @staticmethod
    def concat(*parts: "Springs") -> "Springs":
        return Springs(*(np.concatenate([getattr(p, f) for p in parts])
                         for f in ("i", "j", "rest", "stiffness", "tension_only")))
