"""The scheduler: split a scene into passes by coupling mode, and run them (SPEC 1, DESIGN).

* Systems joined by two-way interactions form a group that advances in lock step.
* For one-way and hybrid interactions the primary's group runs first (hybrid: with the
  stand-in acting on the primary) and its motion is recorded as a track; the secondary's group
  runs afterwards with the primary *played back* from that track (cubic Hermite).
* Static systems (the floor, the wind) join no group; any pass may use them. Prescribed
  systems (animation) run in passes of their own like dynamic ones, but nothing pushes them.

Within a pass the coupling step h is the scene's ``coupling_dt`` or else the smallest ``dt`` of
the pass's systems. At each coupling step every interaction is evaluated once from the current
states and its forces are held constant while each system advances h in ceil(h/dt) substeps;
an interaction may instead defer (``exchange`` returns None): its secondary advances first,
integrating the interaction at every substep inside its kernel, and ``complete`` hands the
primary the step's mean force before the primary advances.

The scheduler never changes a system: a pass holds its own table of largest substeps (each
system's ``dt`` unless an instability made it rerun at a smaller one, which is reported).
"""
from __future__ import annotations

import time as wallclock
from dataclasses import dataclass, field

import numpy as np

from ..errors import SceneError, StabilityError
from ..systems.base import Role
from .forcelog import ForceLog
from .track import Track, TrackRecorder

#: generalized states this small are always recorded at full rate (rigid bodies), for checkpoints
_SMALL_STATE = 64


@dataclass
class Pass:
    """One run over the whole duration: live systems step, played systems follow tracks."""
    live: list
    played: list = field(default_factory=list)
    actions: list = field(default_factory=list)  # (interaction, role) role: both|secondary|standin
    record: list = field(default_factory=list)   # live systems whose full-rate track is kept
    wall_s: float = 0.0
    steps: int = 0
    h: float = 0.0
    dts: dict = field(default_factory=dict)      # system name -> largest substep (s)

    @property
    def label(self) -> str:
        return "+".join(s.name for s in self.live)

    def describe(self) -> dict:
        """The pass as data (summary.json's timings)."""
        return {"systems": [s.name for s in self.live], "played": [s.name for s in self.played],
                "wall_s": self.wall_s, "steps": self.steps, "coupling_dt_s": self.h,
                "substep_s": dict(self.dts)}


def _moving(s) -> bool:
    return s.role is not Role.STATIC


def plan(systems, interactions) -> list[Pass]:
    """Order the scene into passes; raise SceneError on a contradictory coupling graph."""
    dynamic = [s for s in systems if _moving(s)]
    parent = {s.name: s.name for s in dynamic}

    def root(n):
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for it in interactions:
        a, b = it.primary, it.secondary
        if it.mode == "two-way" and _moving(a) and _moving(b):
            parent[root(a.name)] = root(b.name)
    groups: dict[str, list] = {}
    for s in dynamic:
        groups.setdefault(root(s.name), []).append(s)
    # one-way/hybrid edges: the primary's group must run before the secondary's
    after: dict[str, set] = {g: set() for g in groups}
    for it in interactions:
        if it.mode == "two-way" or not (_moving(it.primary) and _moving(it.secondary)):
            continue
        ga, gb = root(it.primary.name), root(it.secondary.name)
        if ga == gb:
            raise SceneError(
                f"interaction {it.name} is {it.mode}, but {it.primary.name} and "
                f"{it.secondary.name} are also coupled two-way through other interactions; "
                "make them all two-way or break the two-way chain")
        after[gb].add(ga)
    order, done = [], set()
    while len(order) < len(groups):
        ready = [g for g in groups if g not in done and after[g] <= done]
        if not ready:
            raise SceneError("the one-way/hybrid interactions form a cycle: no system can run "
                             "first; make one of them two-way")
        for g in ready:
            order.append(g)
            done.add(g)
    passes, earlier = [], set()
    needed_later = {it.primary.name for it in interactions
                    if it.mode != "two-way" and _moving(it.primary) and _moving(it.secondary)}
    for g in order:
        live = groups[g]
        names = {s.name for s in live}
        p = Pass(live=live, dts={s.name: s.dt for s in live})
        for it in interactions:
            a, b = it.primary.name, it.secondary.name
            if it.mode == "two-way":
                if a in names or b in names:
                    p.actions.append((it, "both"))
            elif b in names and (a in earlier or not _moving(it.primary)):
                p.actions.append((it, "secondary"))
                if _moving(it.primary) and it.primary not in p.played:
                    p.played.append(it.primary)
            elif a in names and it.mode == "hybrid":
                p.actions.append((it, "standin"))
        p.record = [s for s in live if s.name in needed_later
                    or s.generalized_state()[0].size <= _SMALL_STATE]
        passes.append(p)
        earlier |= names
    return passes


class _Unstable(Exception):
    def __init__(self, system, warnings):
        super().__init__("; ".join(warnings))
        self.system, self.warnings = system, warnings


class Monitor:
    """Diagnostics per system sampled every ~1 ms of simulated time and at each output frame."""

    def __init__(self, systems):
        self.ke = {s.name: [s.kinetic_energy()] for s in systems}
        self.lowest = {s.name: [] for s in systems}
        self.strain = {s.name: [] for s in systems}

    def sample(self, systems):
        for s in systems:
            self.ke[s.name].append(s.kinetic_energy())
            z = s.lowest_z()
            if z is not None:
                self.lowest[s.name].append(z)
            e = s.strain()
            if e is not None:
                self.strain[s.name].append(e)


def run_pass(p: Pass, duration, h, fps, logs, tracks, frames, monitor, progress=None):
    """Run one pass; fill logs, tracks (of recorded systems) and output frames in place."""
    n = int(round(duration / h))
    p.h, p.steps = h, n
    recs = [TrackRecorder(s.name, n + 1, s.generalized_state()[0].size) for s in p.record]
    for s, r in zip(p.record, recs):
        r.record(0.0, *s.generalized_state())
    for it, role in p.actions:
        if role == "standin":
            it_log = logs[it.name]
            it_log.standin = ForceLog(it.standin.name, it.primary.name, it.primary.name,
                                      "stand-in", it.primary.mass)
            it_log.standin.allocate(n)
        else:
            logs[it.name].allocate(n)
    played_tracks = [(s, tracks[s.name]) for s in p.played]
    frame_dt = 1.0 / fps
    next_frame = 0
    fr = {s.name: frames.setdefault(s.name, {"t": [], "data": []}) for s in p.live}
    check_every = max(1, int(round(1e-3 / h)))
    live = p.live
    actions = [(it, role, logs[it.name] if role != "standin" else logs[it.name].standin)
               for it, role in p.actions]
    for it, role in p.actions:
        it.prepare(h, p.dts)
    deferred = []
    dts = p.dts
    t0 = wallclock.perf_counter()
    for k in range(n + 1):
        t = k * h
        if t >= next_frame * frame_dt - 1e-9 * h or k == n:
            while next_frame * frame_dt <= t + 0.5 * h:
                next_frame += 1
            for s in live:
                fr[s.name]["t"].append(t)
                fr[s.name]["data"].append(s.frame())
        if k == n:
            break
        for s, tr in played_tracks:
            s.set_generalized_state(*tr.sample(t))
            s.time = t
        for s in live:
            s.clear_forces()
        for it, role, log in actions:
            if role == "standin":
                res = it.standin.act(it.primary)
            else:
                res = it.exchange(role == "both", True)
            if res is None:
                deferred.append((it, role, log))
            else:
                log.record(t, *res)
        if deferred:
            # secondaries first: their sub-cycled advance yields the impulse on the primaries
            waiting = {it.primary.name for it, _, _ in deferred}
            for s in live:
                if s.name not in waiting:
                    s.advance(h, dts[s.name])
            for it, role, log in deferred:
                log.record(t, *it.complete(role == "both"))
            for s in live:
                if s.name in waiting:
                    s.advance(h, dts[s.name])
            deferred.clear()
        else:
            for s in live:
                s.advance(h, dts[s.name])
        for s, r in zip(p.record, recs):
            r.record(t + h, *s.generalized_state())
        if (k + 1) % check_every == 0:
            monitor.sample(live)
            for s in live:
                w = s.health()
                if w:
                    raise _Unstable(s, w)
        if progress is not None and k % 500 == 0:
            progress(p, t, wallclock.perf_counter() - t0)
    p.wall_s = wallclock.perf_counter() - t0
    if progress is not None:
        progress(p, duration, p.wall_s, done=True)
    for s, r in zip(p.record, recs):
        tracks[s.name] = r.track()
    for it, role in p.actions:
        (logs[it.name].standin if role == "standin" else logs[it.name]).trim()


def run_passes(passes, duration, fps, coupling_dt, logs, progress=None, refine_unstable=True,
               max_refinements=2):
    """Run every pass in order. An unstable pass is rerun from its start with the offending
    system's largest substep divided by 10 (in the pass's own step table, up to
    ``max_refinements`` times), each rerun reported in the returned warnings; past that a
    StabilityError says what blew up and what to try."""
    tracks: dict[str, Track] = {}
    frames: dict[str, dict] = {}
    warnings: list[str] = []
    monitors = {}
    for p in passes:
        snaps = {s.name: s.capture() for s in p.live}
        for attempt in range(max_refinements + 1):
            h = coupling_dt or min(p.dts.values())
            monitor = Monitor(p.live)
            try:
                run_pass(p, duration, h, fps, logs, tracks, frames, monitor, progress)
                break
            except _Unstable as e:
                for s in p.live:
                    s.restore(snaps[s.name])
                    frames.pop(s.name, None)
                    tracks.pop(s.name, None)
                if not refine_unstable or attempt == max_refinements:
                    raise StabilityError(
                        f"{e}; try a smaller --dt for {e.system.name} or --integrator implicit")
                old = p.dts[e.system.name]
                p.dts[e.system.name] = old / 10.0
                warnings.append(f"{e.warnings[0]}; reran the pass with {e.system.name} "
                                f"dt={old / 10.0:.3g} s (was {old:.3g} s)")
        for s in p.live:
            monitors[s.name] = monitor
    return tracks, frames, warnings, monitors


def as_array_frames(frames: dict) -> dict:
    """Turn per-frame dicts into stacked arrays: {system: {"t": (f,), key: (f, ...)}}."""
    out = {}
    for name, fr in frames.items():
        data = fr["data"]
        arrays = {"t": np.asarray(fr["t"])}
        if data and data[0]:
            for key in data[0]:
                arrays[key] = np.stack([d[key] for d in data])
        out[name] = arrays
    return out
