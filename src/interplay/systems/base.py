"""The System protocol: what every simulation offers the scheduler and the interactions.

A system owns its state as float64 NumPy arrays and advances it with ``step(h)`` using the
forces accumulated since ``clear_forces()``. Its *generalized state* ``(x, xdot)`` is what a
track records and what playback interpolates (cubic Hermite needs both): for a rigid body,
position and unit quaternion with their time derivatives; for a network, the point positions
and velocities.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from ..errors import require_positive

GRAVITY = np.array([0.0, 0.0, -9.81])  # m/s^2, +z up


class System(ABC):
    """Base class of all simulations. Subclasses set ``kind`` and implement the state hooks.

    name: unique name within a scene.
    dt: the largest step (s) this system's integrator may take; the scheduler substeps a
        coupling step into ceil(h / dt) equal steps of this system.
    """

    kind = "system"
    #: False for systems that ignore forces (static colliders, playback of a track).
    dynamic = True
    #: False for animation (keyframes, motion capture): it is stepped but nothing can push back
    #: on it, so only one-way coupling applies to its interactions (SPEC 2.3).
    accepts_forces = True

    def __init__(self, name: str, dt: float):
        if not name or not isinstance(name, str):
            raise ValueError("a system needs a non-empty name")
        self.name = name
        self.dt = require_positive(name, "dt", dt, "s")
        self.time = 0.0

    # --- dynamics -------------------------------------------------------------------------
    def clear_forces(self) -> None:
        """Forget the external forces of the last coupling step."""

    @abstractmethod
    def step(self, h: float) -> None:
        """Advance by h seconds under the accumulated forces (held constant over h)."""

    def advance(self, h: float) -> None:
        """Advance one coupling step of h seconds in ceil(h/dt) equal substeps."""
        n = max(1, int(np.ceil(h / self.dt - 1e-9)))
        sub = h / n
        for _ in range(n):
            self.step(sub)
        self.time += h

    # --- measured quantities ---------------------------------------------------------------
    @property
    @abstractmethod
    def mass(self) -> float:
        """Total mass (kg); infinite for immovable systems."""

    def kinetic_energy(self) -> float:
        """Kinetic energy (J)."""
        return 0.0

    def momentum(self) -> np.ndarray:
        """Linear momentum (kg m/s)."""
        return np.zeros(3)

    def extra_diagnostics(self) -> dict:
        """System-specific entries for summary.json's diagnostics (e.g. the water's volume
        drift); merged into the generic ones."""
        return {}

    def health(self) -> list[str]:
        """Warnings about the current state (non-finite values, runaway strain); empty if fine."""
        x, v = self.generalized_state()
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            return [f"{self.name}: state became non-finite at t={self.time:.4f} s"]
        return []

    # --- state for tracks, playback and checkpoints -----------------------------------------
    @abstractmethod
    def generalized_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat (x, xdot) arrays of equal length describing the configuration and its rate.
        They may be views of the live state or reused buffers: copy them to keep them."""

    @abstractmethod
    def set_generalized_state(self, x: np.ndarray, xdot: np.ndarray) -> None:
        """Impose (x, xdot) (used by playback; the system becomes kinematic for that pass)."""

    @abstractmethod
    def frame(self) -> dict[str, np.ndarray]:
        """What an output frame records (positions of a surface, or a pose)."""

    def capture(self) -> dict[str, np.ndarray]:
        """A full copy of the state, for restarting a pass."""
        x, v = self.generalized_state()
        return {"x": x.copy(), "xdot": v.copy(), "time": np.array(self.time)}

    def restore(self, snap: dict[str, np.ndarray]) -> None:
        """Return to a state from ``capture()``."""
        self.set_generalized_state(snap["x"], snap["xdot"])
        self.time = float(snap["time"])

    def describe(self) -> dict:
        """Name, kind, mass and step, for summary.json."""
        m = self.mass
        return {"name": self.name, "kind": self.kind,
                "mass_kg": None if not np.isfinite(m) else float(m), "dt_s": self.dt,
                "integrator": getattr(self, "integrator", None)}
