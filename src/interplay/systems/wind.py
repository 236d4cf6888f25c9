"""Wind fields (SPEC 2.2): a sum of flow primitives, each possibly drifting, riding along a
``Path`` (a bicyclist's wake) and gusting. The field ignores forces: objects do not disturb
the wind, so every interaction with it is one-way."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..kernels import wind as K
from .static import Stateless

KINDS = {"uniform": K.UNIFORM, "source": K.SOURCE, "sink": K.SOURCE, "vortex": K.VORTEX,
         "turbulence": K.TURBULENCE, "boundary_layer": K.BOUNDARY_LAYER}
TURBULENCE_MODES = 12  # Fourier modes of a turbulence primitive


@dataclass(frozen=True)
class FlowPrimitive:
    """One primitive. kind: uniform | source | sink | vortex | turbulence | boundary_layer
    (formulas in ``kernels.wind``).

    position (m) of the centre at t = 0; axis: the flow direction (uniform) or the vortex
    axis (normalized here); strength: U m/s, q m^3/s (a sink draws in q), Gamma m^2/s, or the
    turbulence's rms speed per component (m/s); core (m): the regularizing core radius r_c,
    or the turbulence's length scale (its modes' wavelengths run from core/4 to 2 core, their
    amplitudes following Kolmogorov's k^-5/3 spectrum); velocity (m/s): a constant drift (the
    mean wind a turbulence is carried by); gust: the
    relative amplitude of the strength's fluctuation, gust_period (s) its main period and
    phase (rad) its offset, so several primitives need not gust in step. With a ``path``,
    position and axis are in the path's moving frame (x forward, z up) and ride along it.
    A boundary_layer is the wind over the ground at position's height: strength (m/s) is its
    speed at ``height`` (m) above that ground, along axis (horizontal), growing with height by
    the logarithmic law of the surface layer with roughness length ``core`` (m).
    """
    kind: str = "uniform"
    position: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (1.0, 0.0, 0.0)
    strength: float = 1.0
    core: float = 0.1
    velocity: tuple = (0.0, 0.0, 0.0)
    gust: float = 0.0
    gust_period: float = 3.0
    phase: float = 0.0
    path: object = None
    height: float = 10.0

    def checked(self, owner: str) -> "FlowPrimitive":
        if self.kind not in KINDS:
            raise ParameterError(f"{owner}: unknown flow primitive {self.kind!r}; choose one of "
                                 f"{', '.join(KINDS)}")
        a = np.asarray(self.axis, dtype=float)
        if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0.0:
            raise ParameterError(f"{owner}: {self.kind} axis must be a non-zero 3-vector, got "
                                 f"{self.axis}")
        for name, unit in (("core", "m"), ("gust", ""), ("gust_period", "s")):
            require_nonnegative(owner, f"{self.kind} {name}", getattr(self, name), unit)
        if self.kind == "boundary_layer":
            require_positive(owner, "boundary_layer core (roughness length)", self.core, "m")
            require_positive(owner, "boundary_layer height (reference height)", self.height,
                             "m")
        if self.gust_period == 0.0 and self.gust > 0.0:
            raise ParameterError(f"{owner}: a gusting {self.kind} needs gust_period > 0 s")
        if not math.isfinite(self.strength):
            raise ParameterError(f"{owner}: {self.kind} strength must be finite, got "
                                 f"{self.strength}")
        return self

    def gust_factor(self, t: float) -> float:
        """1 + gust g(t), g a sum of three incommensurate sines scaled into [-1, 1]: smooth
        and irregular enough to read as gusts without a random state to carry."""
        if self.gust == 0.0:
            return 1.0
        w = 2.0 * math.pi * t / self.gust_period
        g = (math.sin(w + self.phase) + 0.6 * math.sin(1.73 * w + 2.1 + self.phase)
             + 0.35 * math.sin(3.31 * w + 4.2 + self.phase)) / 1.95
        return 1.0 + self.gust * g

    def modes(self) -> np.ndarray:
        """(TURBULENCE_MODES, 7) rows [k (1/m), A (unit rms per component), phi (rad)] of a
        turbulence primitive: wavenumbers log-spaced over 2 pi / (2 core) .. 2 pi / (core / 4)
        in random directions, each amplitude perpendicular to its wavevector (divergence-free)
        and weighted k^-1/3 (a k^-5/3 energy spectrum over log-spaced bands), seeded by phase
        so a scene repeats."""
        rng = np.random.default_rng(int(round(1e6 * self.phase)) % (2 ** 32))
        n = TURBULENCE_MODES
        k = 2.0 * math.pi / max(self.core, 1e-9) * np.geomspace(0.5, 4.0, n)
        d = rng.normal(size=(n, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        a = rng.normal(size=(n, 3))
        a -= np.sum(a * d, axis=1, keepdims=True) * d
        a /= np.linalg.norm(a, axis=1, keepdims=True)
        w = k ** (-1.0 / 3.0)
        w *= math.sqrt(6.0 / np.sum(w * w))  # each component's rms: sqrt(sum w^2 / 6) = 1
        return np.concatenate([k[:, None] * d, a * w[:, None],
                               rng.uniform(0.0, 2.0 * math.pi, (n, 1))], axis=1)


class WindField(Stateless):
    """The air: a stateless system (never stepped by the scheduler, infinitely massive) whose
    ``velocity(points, t)`` any interaction may sample; it is a function of time."""

    def __init__(self, name="wind", primitives=()):
        super().__init__(name)
        self.primitives = [p.checked(name) for p in primitives]
        rows = [np.c_[np.full(TURBULENCE_MODES, q), p.modes()]
                for q, p in enumerate(self.primitives) if p.kind == "turbulence"]
        self._modes = np.concatenate(rows) if rows else np.zeros((0, 8))
        self._at = (None, None)  # (t, arrays): every interaction of a coupling step asks at t

    def arrays(self, t: float):
        """(kind, centre, axis, strength, core) arrays of the primitives at time t (s): a
        function of t alone (the primitives are frozen, their paths functions of time), so
        the last time's are kept for the next interaction that samples the field then."""
        if self._at[0] == t:
            return self._at[1]
        n = len(self.primitives)
        kind = np.empty(n, np.int64)
        centre, axis = np.empty((n, 3)), np.empty((n, 3))
        strength, core = np.empty(n), np.empty(n)
        for q, p in enumerate(self.primitives):  # a handful of primitives, not per point
            c = np.asarray(p.position, float)
            a = np.asarray(p.axis, float) / np.linalg.norm(p.axis)
            if p.path is not None:
                origin, R = p.path.frame(t)
                c, a = origin + R @ c, R @ a
            centre[q] = c + np.asarray(p.velocity, float) * t
            axis[q] = a
            kind[q] = KINDS[p.kind]
            strength[q] = (-1.0 if p.kind == "sink" else 1.0) * p.strength * p.gust_factor(t)
            if p.kind == "boundary_layer":  # the kernel's profile is ln(1 + z/z0)
                strength[q] /= math.log1p(p.height / p.core)
            core[q] = p.core
        self._at = (t, (kind, centre, axis, strength, core))
        return kind, centre, axis, strength, core

    def velocity(self, points, t: float) -> np.ndarray:
        """Wind velocity (m/s) at points (n,3) m at time t (s)."""
        pts = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
        out = np.empty_like(pts)
        K.sample(pts, *self.arrays(t), self._modes, out)
        return out
