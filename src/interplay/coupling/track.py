"""Tracks: a system's recorded generalized state (x, xdot) over time, and its playback.

Playback between samples is cubic Hermite in x using xdot as the end tangents, so positions
and velocities stay continuous (C1) and a track replayed at its own sample times is exact.
"""
from __future__ import annotations

import numpy as np


class TrackRecorder:
    """Fills preallocated arrays, one sample per coupling step."""

    def __init__(self, name: str, n_samples: int, dim: int):
        self.name = name
        self.t = np.empty(n_samples)
        self.x = np.empty((n_samples, dim))
        self.xdot = np.empty((n_samples, dim))
        self.n = 0

    def record(self, t, x, xdot):
        i = self.n
        self.t[i] = t
        self.x[i] = x
        self.xdot[i] = xdot
        self.n = i + 1

    def track(self) -> "Track":
        n = self.n
        return Track(self.name, self.t[:n].copy(), self.x[:n].copy(), self.xdot[:n].copy())


class Track:
    """Samples t (k,) s, x (k,d), xdot (k,d) of one system."""

    def __init__(self, name, t, x, xdot):
        self.name, self.t, self.x, self.xdot = name, t, x, xdot

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, xdot) at time t by cubic Hermite interpolation; clamped outside the samples."""
        ts = self.t
        if t <= ts[0]:
            return self.x[0], self.xdot[0]
        if t >= ts[-1]:
            return self.x[-1], self.xdot[-1]
        i = int(np.searchsorted(ts, t, side="right")) - 1
        h = ts[i + 1] - ts[i]
        s = (t - ts[i]) / h
        if s == 0.0:
            return self.x[i], self.xdot[i]
        x0, x1, v0, v1 = self.x[i], self.x[i + 1], self.xdot[i], self.xdot[i + 1]
        s2, s3 = s * s, s * s * s
        h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2
        x = h00 * x0 + h10 * h * v0 + h01 * x1 + h11 * h * v1
        d00, d10, d01, d11 = 6 * s2 - 6 * s, 3 * s2 - 4 * s + 1, -6 * s2 + 6 * s, 3 * s2 - 2 * s
        xdot = (d00 * x0 + d01 * x1) / h + d10 * v0 + d11 * v1
        return x, xdot
