"""Scene: systems, interactions between them, and ``simulate()``."""
from __future__ import annotations

import time as wallclock

from .coupling.forcelog import ForceLog
from .coupling.modes import MODES
from .coupling.scheduler import as_array_frames, plan
from .errors import SceneError, require_positive
from .systems.base import Role


class Scene:
    """A set of separate simulations joined by interactions, each with a coupling mode.

    duration: simulated time (s); fps: output frames per second; coupling_dt: the step (s) at
    which interactions exchange forces (default: each pass's smallest system dt); primary: the
    system whose motion the animator tunes (its pass time is the primary debug-cycle time);
    main: the name of the interaction Table I and the advisor are about (default: the first
    between two moving systems, else the first acting on a moving system); checkpoints:
    {system name: times (s)} at which the summary reports its state.
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
        self.main: str | None = None
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
        """Set every interaction between two moving (non-static) systems to ``mode``."""
        if mode not in MODES:
            raise SceneError(f"unknown coupling {mode!r}; choose one of {', '.join(MODES)}")
        for it in self.interactions:
            if it.primary.role is not Role.STATIC and it.secondary.role is not Role.STATIC:
                it.mode = mode

    @property
    def coupling(self) -> str:
        """The scene's coupling mode: that of every interaction acting on a moving secondary,
        counted as one-way when the primary is not dynamic (nothing can push back on it)."""
        modes = sorted({it.effective_mode for it in self.interactions
                        if it.secondary.role is not Role.STATIC})
        return modes[0] if len(modes) == 1 else ("mixed" if modes else "none")

    @property
    def main_interaction(self):
        """The interaction Table I and the advisor are about (see ``main``)."""
        if self.main is not None:
            for it in self.interactions:
                if it.name == self.main:
                    return it
            raise SceneError(f"scene {self.name}: main interaction {self.main!r} is not one of "
                             f"{', '.join(it.name for it in self.interactions)}")
        moving = [it for it in self.interactions if it.secondary.role is not Role.STATIC]
        for it in moving:
            if it.primary.role is not Role.STATIC:
                return it
        return moving[0] if moving else None

    def simulate(self, progress=None, refine_unstable: bool = True, primary_only: bool = False,
                 force: bool = False, checkpointer=None, resume=None):
        """Run all passes and return a Result (tracks, force logs, timings, diagnostics, the
        systems' shapes: data only, no live object).

        primary_only: stop after the pass that contains the primary (the animator's fast
        preview of the primary under one-way or hybrid coupling). The run's cost is estimated
        first and refused over the scheduler's BUDGET (CostError) unless ``force``.
        checkpointer: a coupling.checkpoint.Checkpointer saving the run as it goes; resume:
        (header, arrays) of a checkpoint of this same scene to continue from."""
        from .coupling.scheduler import Runner, check_budget, estimate
        from .result import Result
        t0 = wallclock.perf_counter()
        passes = plan(self.systems, self.interactions)
        if primary_only and self.primary is not None:
            keep = next(i for i, p in enumerate(passes) if self.primary in p.live)
            passes = passes[: keep + 1]
        check_budget(estimate(passes, self.duration, self.fps, self.coupling_dt), self.name,
                     force)
        logs = {it.name: ForceLog(it.name, it.primary.name, it.secondary.name, it.mode,
                                  it.primary.mass, it.period_from) for it in self.interactions}
        runner = Runner(self.systems, self.interactions, passes, self.duration, self.fps,
                        self.coupling_dt, logs, progress, refine_unstable,
                        checkpointer=checkpointer)
        runner.extra["initial_ke"] = {s.name: s.kinetic_energy() for s in self.systems}
        if resume is not None:
            runner.restore(*resume)
        tracks, frames, warnings, monitors = runner.run()
        total = wallclock.perf_counter() - t0
        return Result.of(self, passes, logs, tracks, as_array_frames(frames), warnings,
                         monitors, runner.extra["initial_ke"], total)
