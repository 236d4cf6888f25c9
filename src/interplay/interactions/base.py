"""The Interaction protocol and coupling modes (SPEC 1).

An interaction joins a *primary* (the active system: a ball, a figure) and a *secondary* (the
passive one: a net, water). ``exchange(to_primary, to_secondary)`` computes the forces from
both systems' current states, applies them to the sides asked for, and returns the force
(N) and torque (N m, about the primary's centre) the interaction exerts on the primary,
whether or not it was applied, so the analysis can measure what the primary would feel.

Modes: ``two-way`` applies both sides in lock step; ``one-way`` runs the primary alone first and
applies forces to the secondary only, against playback of the primary's track; ``hybrid`` is
one-way with a ``StandIn`` acting on the primary in its own pass.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from ..coupling.modes import MODES
from ..errors import SceneError
from ..systems.base import Role


class StandIn(ABC):
    """A cheap substitute for an interaction that acts on the primary alone (hybrid coupling)."""

    name = "stand-in"

    @abstractmethod
    def act(self, primary) -> tuple[np.ndarray, np.ndarray, bool]:
        """Apply the stand-in force to the primary; return (force N, torque N m, active)."""


class Interaction(ABC):
    """Base class: a named force exchange between ``primary`` and ``secondary``.

    two_way_supported: False for interactions whose two-way form is not implemented (the
    advisor then looks for a stand-in). period_from (s): Table I reports the first period of
    contact that starts at or after it (0: the very first); a scene sets it where light
    contact before its event is not what the row is about (the noose lying on the shoulders
    before the drop)."""

    two_way_supported = True
    period_from = 0.0

    def __init__(self, name: str, primary, secondary, mode: str = "two-way",
                 standin: StandIn | None = None):
        self.name = name
        self.primary = primary
        self.secondary = secondary
        self.standin = standin
        self.mode = mode

    @property
    def mode(self) -> str:
        return self._mode

    @mode.setter
    def mode(self, mode: str):
        if mode not in MODES:
            raise SceneError(f"interaction {self.name}: unknown coupling {mode!r}; "
                             f"choose one of {', '.join(MODES)}")
        if mode == "hybrid" and self.standin is None:
            raise SceneError(f"interaction {self.name}: hybrid coupling needs a stand-in "
                             "(none is defined for it); use two-way or one-way")
        self._mode = mode

    @property
    def effective_mode(self) -> str:
        """The mode as it acts: one-way whenever the primary is not dynamic (static, a field,
        animation), since nothing can push back on it."""
        if self.primary.role is not Role.DYNAMIC:
            return "one-way"
        return self.mode

    def prepare(self, h: float, dts: dict | None = None) -> None:
        """Called at the start of each pass with its coupling step h (s) and the largest
        substep (s) of each system in the pass, by name (an interaction sub-cycled inside its
        secondary's substeps checks whether there are any); None: each system's own dt."""

    def capture(self) -> dict:
        """The interaction's own memory (friction anchors, lagged velocities) as plain arrays,
        for checkpoints; empty for stateless interactions."""
        return {}

    def restore(self, snap: dict) -> None:
        """Return to a state from ``capture()``."""

    @abstractmethod
    def exchange(self, to_primary: bool, to_secondary: bool):
        """Compute the forces, apply them where asked; return (force, torque, in_contact).

        An interaction that integrates its force over the secondary's substeps returns None
        instead; the scheduler then advances the secondary first and calls ``complete``."""

    def complete(self, to_primary: bool):
        """Finish a deferred exchange after the secondary advanced; return as ``exchange``."""
        raise TypeError(f"{type(self).__name__} never defers its exchange")

    def describe(self) -> dict:
        """What the analysis needs after the run: the names, the mode (and how it acted), the
        primary's mass and role, the stand-in, whether two-way is implemented."""
        return {"name": self.name, "type": type(self).__name__, "primary": self.primary.name,
                "secondary": self.secondary.name, "mode": self.mode,
                "effective_mode": self.effective_mode, "primary_role": self.primary.role.value,
                "primary_mass_kg": float(self.primary.mass), "standin": (
                    None if self.standin is None else self.standin.name),
                "two_way_supported": self.two_way_supported}
