"""Scene: systems, interactions between them, and ``simulate()``."""
from __future__ import annotations

import time as wallclock

from .coupling.scheduler import as_array_frames, plan, run_passes
from .errors import SceneError, require_positive
from .coupling.forcelog import ForceLog
from .interactions.base import MODES


class Scene:
    """A set of separate simulations joined by interactions, each with a coupling mode.

    duration: simulated time (s); fps: output frames per second; coupling_dt: the step (s) at
    which interactions exchange forces (default: each pass's smallest system dt); primary: the
    system whose motion the animator tunes (its pass time is the primary debug-cycle time).
    """

    def __init__(self, name: str, duration: float = 1.5, fps: float = 60.0,
                 coupling_dt: float | None = None):
        self.name = name
        self.duration = require_positive(f"scene {name}", "duration", duration, "s")
        self.fps = require_positive(f"scene {name}", "fps", fps, "frames/s")
        self.coupling_dt = (None if coupling_dt is None
                            else require_positive(f"scene {name}", "coupling_dt", coupling_dt, "s"))
        self.systems: list = []
        self.interactions: list = []
        self.primary = None
        self.checkpoints: dict[str, list[float]] = {}
        self.meta: dict = {}

    def add(self, system):
        """Add a system; names must be unique. Returns the system."""
        if any(s.name == system.name for s in self.systems):
            raise SceneError(f"scene {self.name}: a system named {system.name!r} already exists")
        self.systems.append(system)
        return system

    def connect(self, interaction):
        """Add an interaction between two systems already in the scene. Returns it."""
        for s in (interaction.primary, interaction.secondary):
            if s not in self.systems:
                raise SceneError(f"interaction {interaction.name}: system {s.name!r} is not in "
                                 f"scene {self.name}; add it first")
        self.interactions.append(interaction)
        return interaction

    def set_coupling(self, mode: str):
        """Set every interaction between two dynamic systems to ``mode``."""
        if mode not in MODES:
            raise SceneError(f"unknown coupling {mode!r}; choose one of {', '.join(MODES)}")
        for it in self.interactions:
            if it.primary.dynamic and it.secondary.dynamic:
                it.mode = mode

    @property
    def coupling(self) -> str:
        """The scene's coupling mode: that of every interaction acting on a dynamic secondary,
        counted as one-way when the primary is prescribed (nothing can push back on it)."""
        modes = sorted({it.effective_mode for it in self.interactions if it.secondary.dynamic})
        return modes[0] if len(modes) == 1 else ("mixed" if modes else "none")

    @property
    def main_interaction(self):
        """The interaction Table I and the advisor are about: the first between two dynamic
        systems, else the first driving a dynamic secondary from a moving primary (a wind)."""
        for it in self.interactions:
            if it.primary.dynamic and it.secondary.dynamic:
                return it
        for it in self.interactions:
            if it.secondary.dynamic and it.primary.kind != "static":
                return it
        return None

    def simulate(self, progress=None, refine_unstable: bool = True, primary_only: bool = False):
        """Run all passes and return a Result (tracks, force logs, timings, diagnostics).

        primary_only: stop after the pass that contains the primary (the animator's fast
        preview of the primary under one-way or hybrid coupling)."""
        from .result import Result
        t0 = wallclock.perf_counter()
        passes = plan(self.systems, self.interactions)
        if primary_only and self.primary is not None:
            keep = next(i for i, p in enumerate(passes) if self.primary in p.live)
            passes = passes[: keep + 1]
        logs = {it.name: ForceLog(it.name, it.primary.name, it.secondary.name, it.mode,
                                  it.primary.mass) for it in self.interactions}
        initial_ke = {s.name: s.kinetic_energy() for s in self.systems}
        tracks, frames, warnings, monitors = run_passes(
            passes, self.duration, self.fps, self.coupling_dt, logs, progress, refine_unstable)
        total = wallclock.perf_counter() - t0
        return Result(self, passes, logs, tracks, as_array_frames(frames), warnings, monitors,
                      initial_ke, total)
