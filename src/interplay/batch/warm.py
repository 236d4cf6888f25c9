"""Filling Numba's on-disk cache before anyone waits for it: each scene's kernels compiled in
worker processes, one per core (docs/first-run.md).

A kernel compiles the first time a run calls it; building a scene and running two output
frames of it in each of its couplings (or on to its ``warm_time``, where its contacts first
act) calls them all, so ``interplay warm`` (which ``make`` runs after installing) leaves a
user's first ``interplay run`` loading kernels instead of compiling them. The sweep warms its
first variant the same way before its workers start.
"""
from __future__ import annotations

import time
from dataclasses import dataclass


@dataclass(frozen=True)
class WarmTask:
    """One scene in one coupling (None: its default)."""
    scene: str
    coupling: str | None = None


def warm_request(request) -> dict:
    """Build and run two output frames of a batch.variants.RunRequest in this process;
    returns {"compile_s": time compiling or loading kernels (s), "kernels": compiled,
    "wall_s"}."""
    from ..coupling import compilation
    t0, c0, n0 = time.perf_counter(), compilation.seconds(), compilation.compiled()
    spec, coupling, kw = request.resolve()
    # two frames, or on to where the scene's contacts first act: a contact kernel that no
    # warm run reaches is compiled by the user's first run (the basketball's, 4 s)
    warm = max(2.0 / kw["fps"], spec.warm_time or 0.0)
    spec.build(coupling, **dict(kw, duration=min(kw["duration"], warm))).simulate()
    return {"compile_s": compilation.seconds() - c0, "kernels": compilation.compiled() - n0,
            "wall_s": time.perf_counter() - t0}


def warm_scene(task: WarmTask) -> dict:
    """``warm_request`` of a scene with its defaults (a module-level function: the executor's
    workers import it)."""
    from .variants import RunRequest
    return warm_request(RunRequest(task.scene, task.coupling))


def tasks(scenes=None) -> list[WarmTask]:
    """Every coupling of every scene named (default: all scenes), every scene's default
    first: workers that start together then compile different scenes' kernels (two
    couplings of one scene compile mostly the same ones)."""
    from ..scenes import all_specs, spec
    specs = [spec(s) for s in scenes] if scenes else list(all_specs())
    return ([WarmTask(s.name, s.couplings[0]) for s in specs]
            + [WarmTask(s.name, c) for s in specs for c in s.couplings[1:]])
