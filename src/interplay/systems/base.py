"""The System protocol: what every simulation offers the scheduler, the interactions and the
outputs.

A system owns its state as float64 NumPy arrays and advances it with ``advance(h, dt)`` under
the forces accumulated since ``clear_forces()``. It describes itself in three ways, and nothing
else in Interplay looks inside it:

* its **role** (``Role``): static (no motion to advance), prescribed (it moves as told and
  ignores forces: keyframes, motion capture, a path) or dynamic (it moves under forces);
* its **contact view** (``contact_view()``, systems/views.py): the collision geometry, the
  velocities and effective masses of its elements, and the one way to apply forces to them;
* its **shapes** (``shapes()``, systems/shape.py): what is drawn and exported, known at build
  time (meshes moved by per-frame poses, deforming points, curves with widths, particles).

Its *generalized state* ``(x, xdot)`` is what a track records and what playback interpolates
(cubic Hermite needs both); ``capture()`` / ``restore()`` hold *all* of its memory, so that a
restore and a rerun repeat bit for bit.
"""
from __future__ import annotations

import enum
from abc import ABC, abstractmethod

import numpy as np

from ..errors import require_positive

GRAVITY = np.array([0.0, 0.0, -9.81])  # m/s^2, +z up


class Role(enum.Enum):
    """How a system takes part in a scene.

    STATIC: nothing to advance (the floor, colliders, set pieces, and fields given as
    functions of time such as the wind): in no pass, usable by every pass.
    PRESCRIBED: moves as told (keyframes, motion capture, a path) and ignores forces: its
    interactions act one-way, whatever their mode.
    DYNAMIC: moves under the forces of its interactions."""
    STATIC = "static"
    PRESCRIBED = "prescribed"
    DYNAMIC = "dynamic"


class System(ABC):
    """Base class of all simulations. Subclasses set ``role`` and implement the state hooks.

    name: unique name within a scene.
    dt: the largest step (s) this system's integrator may take; a coupling step of h is
        advanced in ceil(h / dt) equal substeps.
    """

    role = Role.DYNAMIC
    #: what the integrator is, for summary.json
    integrator: str | None = None

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

    def advance(self, h: float, dt: float | None = None) -> None:
        """Advance one coupling step of h seconds in ceil(h/dt) equal substeps; dt (s) is the
        largest substep allowed (default the system's own ``dt``; the scheduler passes a
        smaller one when it reruns an unstable pass)."""
        n = substeps(h, self.dt if dt is None else dt)
        sub = h / n
        for _ in range(n):
            self.step(sub)
        self.time += h

    # --- how it describes itself -------------------------------------------------------------
    def contact_view(self):
        """What contacts, attachments, fields and aerodynamics see of this system
        (systems/views.py); None when nothing can touch it."""
        return None

    def shapes(self) -> list:
        """Its Shapes for drawing and export (systems/shape.py); empty when it has none."""
        return []

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

    def lowest_z(self) -> float | None:
        """Height (m) of its lowest point, or None where that means nothing."""
        return None

    def strain(self) -> float | None:
        """Largest strain (-) of its deformable elements, or None for rigid systems."""
        return None

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

    def frame_size(self) -> int:
        """How many values an output frame holds, for the run's cost estimate before any step;
        a system whose ``frame`` does more than read its state (a garment certifies itself
        there) answers without it."""
        return sum(np.asarray(v).size for v in self.frame().values())

    def capture(self) -> dict[str, np.ndarray]:
        """All of the system's memory as plain arrays (checkpoints, pass reruns): restoring it
        and advancing repeats the same steps bit for bit. Subclasses with solver memory
        (histories, caches of the last step) extend it."""
        x, v = self.generalized_state()
        return {"x": x.copy(), "xdot": v.copy(), "time": np.array(self.time)}

    def restore(self, snap: dict[str, np.ndarray]) -> None:
        """Return to a state from ``capture()``."""
        self.set_generalized_state(snap["x"], snap["xdot"])
        self.time = float(snap["time"])

    def describe(self) -> dict:
        """Name, type, role, mass, step and integrator, for summary.json."""
        m = self.mass
        return {"name": self.name, "type": type(self).__name__, "role": self.role.value,
                "mass_kg": None if not np.isfinite(m) else float(m), "dt_s": self.dt,
                "integrator": self.integrator}


def substeps(h: float, dt: float) -> int:
    """Equal substeps of at most dt (s) in a coupling step of h (s)."""
    return max(1, int(np.ceil(h / dt - 1e-9)))
