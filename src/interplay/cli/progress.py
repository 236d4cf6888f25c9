"""A progress bar per pass (rich), shown only once a pass has run for more than a second."""
from __future__ import annotations

import sys


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


class CompileNotice:
    """Given to ``coupling.compilation.watching``: a first run (an empty Numba cache) says
    that it is compiling kernels, then a line every ``every_s`` seconds while it goes on, and
    a last line from ``finish()``, so it is not a silent wait."""

    def __init__(self, quiet: bool = False, every_s: float = 5.0):
        self.quiet, self.every_s = quiet, every_s
        self.started = self.last = None
        self.count = 0

    def __call__(self, name: str, outermost: bool, ended: bool):
        import time
        if self.quiet:
            return
        now = time.perf_counter()
        if self.started is None:
            self.started = self.last = now
            print("interplay: compiling kernels (first run only; later runs load them from "
                  "the cache)...", file=sys.stderr, flush=True)
        if ended and outermost:
            self.count += 1
        if not ended and now - self.last >= self.every_s:
            self.last = now
            print(f"interplay:   {self.count} kernels compiled in {now - self.started:.0f} s; "
                  f"now {name}", file=sys.stderr, flush=True)

    def finish(self, compile_s: float):
        """compile_s (s): the run's compile time as measured (coupling.compilation)."""
        if self.started is not None and not self.quiet:
            print(f"interplay: {self.count} kernels compiled; {compile_s:.1f} s compiling, "
                  "not counted in the debug-cycle time", file=sys.stderr, flush=True)
