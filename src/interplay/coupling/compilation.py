"""The time this process spends getting Numba kernels ready: compiling them on a first run
(an empty on-disk cache), loading them from the cache afterwards.

A first run of a scene compiles its kernels once (15-35 s for some scenes); that is the
install's cost, not the simulation's, so the scheduler takes it out of every pass's wall time
(the primary debug-cycle time) and reports it beside it (``compile_s``). Measured with
Numba's event API: the time the compiler lock is held (every compile and every cache load
takes it; nested takes are counted once), and the ``numba:compile`` events, which fire only
when a kernel is really compiled (a cache miss).
"""
from __future__ import annotations

import time

from numba.core import event


class _Clock(event.Listener):
    """Seconds the compiler lock was held (outermost takes only), since the process began."""

    def __init__(self):
        self.depth, self.since, self.total = 0, 0.0, 0.0

    def on_start(self, ev):
        if self.depth == 0:
            self.since = time.perf_counter()
        self.depth += 1

    def on_end(self, ev):
        self.depth -= 1
        if self.depth == 0:
            self.total += time.perf_counter() - self.since


class _Compiles(event.Listener):
    """Kernels really compiled (cache misses): each one's name and seconds (a kernel's time
    includes the kernels it compiles on the way), and who wants to hear of each."""

    def __init__(self):
        self.count, self.stack, self.log, self.watchers = 0, [], [], []

    def on_start(self, ev):
        name = getattr(ev.data["dispatcher"], "__qualname__", "?")
        self.stack.append((name, time.perf_counter()))
        for w in list(self.watchers):
            w(name, len(self.stack) == 1, False)

    def on_end(self, ev):
        name, since = self.stack.pop()
        self.count += 1
        self.log.append((name, len(self.stack), time.perf_counter() - since))
        for w in list(self.watchers):
            w(name, not self.stack, True)


_CLOCK, _COMPILES = _Clock(), _Compiles()
event.register("numba:compiler_lock", _CLOCK)
event.register("numba:compile", _COMPILES)


def seconds() -> float:
    """(s) time spent compiling or loading kernels in this process so far, including one
    under way."""
    open_s = time.perf_counter() - _CLOCK.since if _CLOCK.depth else 0.0
    return _CLOCK.total + open_s


def compiled() -> int:
    """Kernels (type specialisations) compiled in this process so far: cache misses."""
    return _COMPILES.count


def compile_log() -> list:
    """(qualified name, nesting depth, seconds) of every kernel compiled in this process."""
    return list(_COMPILES.log)


class watching:
    """``with watching(fn):`` calls fn(name, outermost, ended) as kernels compile: at the start
    of each (its qualified name; outermost False for a kernel compiled because another one
    calls it) and at its end."""

    def __init__(self, fn):
        self.fn = fn

    def __enter__(self):
        _COMPILES.watchers.append(self.fn)
        return self

    def __exit__(self, *exc):
        _COMPILES.watchers.remove(self.fn)
