"""A progress bar per pass (rich), shown only once a pass has run for more than a second."""
from __future__ import annotations


class PassProgress:
    """Callable given to ``Scene.simulate(progress=...)``: progress(pass, t, wall_s, done)."""

    def __init__(self, duration: float, quiet: bool = False, after_s: float = 1.0):
        self.duration, self.quiet, self.after_s = duration, quiet, after_s
        self._bar = None
        self._task = None

    def __call__(self, p, t, wall_s, done=False):
        if self.quiet:
            return
        if self._bar is None and not done and wall_s > self.after_s:
            from rich.progress import (BarColumn, Progress, TextColumn, TimeRemainingColumn)
            self._bar = Progress(TextColumn("{task.description}"), BarColumn(),
                                 TextColumn("{task.fields[sim]:.3f} s simulated"),
                                 TextColumn("{task.fields[rate]:,.0f} steps/s"),
                                 TimeRemainingColumn())
            self._bar.start()
            self._task = self._bar.add_task(f"pass {p.label}", total=self.duration, sim=0.0,
                                            rate=0.0)
        if self._bar is not None:
            steps = t / p.h if p.h else 0.0
            self._bar.update(self._task, completed=t, sim=t, rate=steps / max(wall_s, 1e-9))
            if done:
                self._bar.stop()
                self._bar = None
