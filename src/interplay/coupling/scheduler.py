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

Before any step it estimates what the run costs (``estimate``: coupling steps, substeps times
state size, the memory of tracks and frames) and refuses a run over ``BUDGET`` (CostError,
``--force`` goes on). A system whose state turns non-finite, or strains past its limit, stops
its pass; the pass is rerun at a tenth of that system's step while that helps, and otherwise
the run stops with a StabilityError saying which system, when, why and what to try. A
``Checkpointer`` saves the whole run state at step boundaries; ``Runner.restore`` continues
from one, bit for bit.
"""
from __future__ import annotations

import math
import time as wallclock
from dataclasses import dataclass, field

import numpy as np

from ..errors import CostError, SceneError, StabilityError
from ..systems.base import Role, substeps
from . import checkpoint as C
from . import compilation
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
    wall_s: float = 0.0  # its wall time (s) without compilation: the debug-cycle time
    compile_s: float = 0.0  # wall time (s) it spent compiling or loading Numba kernels
    steps: int = 0
    work: float = 0.0  # state values advanced: substeps x values, summed over live systems
    h: float = 0.0
    dts: dict = field(default_factory=dict)      # system name -> largest substep (s)

    @property
    def label(self) -> str:
        return "+".join(s.name for s in self.live)

    def describe(self) -> dict:
        """The pass as data (summary.json's timings)."""
        return {"systems": [s.name for s in self.live], "played": [s.name for s in self.played],
                "wall_s": self.wall_s, "compile_s": self.compile_s, "steps": self.steps,
                "work": self.work,
                "coupling_dt_s": self.h,
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



#: the most a run may cost without --force: state values advanced (substeps x values), substeps
#: (each has a fixed cost: an implicit solve, a MuJoCo step, ~10-20 us) and the memory kept
#: for tracks and frames. The default scenes advance 8e5 to 7e7 values in 1.2e3 to 1.5e5
#: substeps and keep 1 to 100 MB (docs/robustness.md); the budget is ~100x that
BUDGET = {"work": 1e10, "substeps": 2e7, "bytes": 4 * 2 ** 30}


def estimate(passes, duration, fps, coupling_dt) -> dict:
    """What running ``passes`` costs, before any step: per pass its coupling step (s), coupling
    steps, substeps of each system and work (substeps x state values); in total the work, the
    coupling steps and the bytes of tracks, logs and output frames."""
    out = {"passes": [], "work": 0.0, "steps": 0.0, "bytes": 0.0}
    frames = min(duration * fps, 1e30) + 1
    for p in passes:
        h = coupling_dt or min(p.dts.values())
        n = duration / h
        row = {"systems": p.label, "h": h, "steps": n, "substeps": {}, "work": 0.0,
               "dts": dict(p.dts)}
        for s in p.live:
            dof = s.generalized_state()[0].size
            sub = n * max(1.0, math.ceil(h / p.dts[s.name] - 1e-9))
            row["substeps"][s.name] = sub
            row["work"] += sub * max(dof, 1)
            out["bytes"] += 8.0 * s.frame_size() * min(frames, n + 1)
        for s in p.record:
            out["bytes"] += 16.0 * s.generalized_state()[0].size * (n + 1)
        out["bytes"] += 80.0 * len(p.actions) * n
        out["passes"].append(row)
        out["work"] += row["work"]
        out["steps"] += n
    return out


def check_budget(est: dict, scene: str, force: bool = False):
    """CostError with the estimate and how to proceed when ``est`` is over BUDGET."""
    if force:
        return
    if est["work"] > BUDGET["work"]:
        worst = max(est["passes"], key=lambda r: r["work"])
        sub = max(worst["substeps"].items(), key=lambda kv: kv[1])
        raise CostError(f"{scene}: the run would advance {est['work']:.3g} state values "
                        f"(budget {BUDGET['work']:.0e}): {sub[0]} takes {sub[1]:.3g} substeps "
                        f"of {worst['dts'][sub[0]]:.3g} s ({worst['steps']:.3g} coupling "
                        f"steps of {worst['h']:.3g} s); "
                        "shorten --duration, raise --dt or the step in --set, or pass --force "
                        "to go on anyway")
    subs = sum(sum(r["substeps"].values()) for r in est["passes"])
    if subs > BUDGET["substeps"]:
        worst = max(((name, n, r) for r in est["passes"] for name, n in r["substeps"].items()),
                    key=lambda x: x[1])
        raise CostError(f"{scene}: the run would take {subs:.3g} substeps (budget "
                        f"{BUDGET['substeps']:.0e}): {worst[0]} takes {worst[1]:.3g} substeps "
                        f"of {worst[2]['dts'][worst[0]]:.3g} s; shorten --duration, raise "
                        "--dt or the step in --set, or pass --force to go on anyway")
    if est["bytes"] > BUDGET["bytes"]:
        raise CostError(f"{scene}: the run would keep about {est['bytes'] / 2 ** 30:.3g} GiB of "
                        f"tracks and frames (budget {BUDGET['bytes'] / 2 ** 30:.0f} GiB); lower "
                        "--fps or --duration, or pass --force to go on anyway")


class _Unstable(Exception):
    def __init__(self, system, warnings, t):
        super().__init__("; ".join(warnings))
        self.system, self.warnings, self.t = system, warnings, t


#: what a step raises when its state or forces went non-finite (NumPy and Numba's linear
#: algebra refuse NaN, an overflow in a conversion): treated as the pass being unstable
NUMERIC = (np.linalg.LinAlgError, FloatingPointError, ZeroDivisionError, OverflowError)


def _blame(p, err) -> _Unstable:
    """The likely cause among the pass's unhealthy systems: the one with the smallest step
    (the stiffest: non-finite forces spread from it to the others within the coupling step),
    else the error itself."""
    bad = [(p.dts[s.name], i, s, s.health()) for i, s in enumerate(p.live)]
    bad = [b for b in bad if b[3]]
    if bad:
        _, _, s, w = min(bad, key=lambda b: b[:2])
        others = [b[2].name for b in bad if b[2] is not s]
        also = f" (and so {', '.join(others)})" if others else ""
        return _Unstable(s, [w[0] + also], s.time)
    s = p.live[0]
    return _Unstable(s, [f"{s.name}: a step failed at t={s.time:.4f} s "
                         f"({type(err).__name__}: {err})"], s.time)


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

    def arrays(self, prefix) -> dict:
        out = {}
        for key in ("ke", "lowest", "strain"):
            for name, v in getattr(self, key).items():
                out[f"{prefix}/{name}/{key}"] = np.asarray(v, dtype=float)
        return out

    @classmethod
    def from_arrays(cls, arrays, prefix, names):
        m = cls([])
        for key in ("ke", "lowest", "strain"):
            getattr(m, key).update({n: [float(x) for x in arrays[f"{prefix}/{n}/{key}"]]
                                    for n in names})
        return m


def _fix(system) -> str:
    """What to try when ``system`` blew up, from what it is (not what scene it is in)."""
    integ = str(system.integrator or "")
    if integ == "explicit":
        return (f"try --integrator implicit (or a smaller --dt) for {system.name}, or check the "
                "parameters that make it stiff or fast")
    if integ in ("implicit", "localglobal"):
        return (f"{system.name} already integrates implicitly: check the parameters that make "
                "it stiff, heavy-loaded or fast, or set a smaller step for it with --set")
    return (f"check the parameters that drive {system.name} (speeds, stiffnesses, steps set "
            "with --set)")


@dataclass
class _PassState:
    """Where a pass is: the next coupling step k, the next output frame, the recorders."""
    k: int = 0
    next_frame: int = 0
    recs: list = field(default_factory=list)


class Runner:
    """Runs the passes of a scene in order (see the module docstring) and holds everything a
    checkpoint needs: which pass, the step, the tracks, frames, logs and monitors so far."""

    def __init__(self, systems, interactions, passes, duration, fps, coupling_dt, logs,
                 progress=None, refine_unstable=True, max_refinements=2, checkpointer=None):
        self.systems, self.interactions, self.passes = systems, interactions, passes
        self.duration, self.fps, self.coupling_dt, self.logs = duration, fps, coupling_dt, logs
        self.progress, self.refine, self.max_refinements = progress, refine_unstable, \
            max_refinements
        self.ckpt = checkpointer
        self.tracks: dict[str, Track] = {}
        self.frames: dict[str, dict] = {}
        self.warnings: list[str] = []
        self.monitors: dict = {}
        self.index = 0          # the pass running
        self.attempt = 0        # its reruns so far
        self.failed_at: list = []  # simulated times of its failures
        self.state = _PassState()
        self.snaps: dict = {}   # live systems and interactions at the pass's start
        self.monitor = None
        self.resumed = False
        self.extra: dict = {}   # what the caller keeps in checkpoints (initial energies)

    # --- running ---------------------------------------------------------------------------
    def run(self):
        """Run (or continue) every pass; returns (tracks, frames, warnings, monitors)."""
        while self.index < len(self.passes):
            p = self.passes[self.index]
            if not self.resumed:
                self._start(p)
            self.resumed = False
            while True:
                try:
                    self._run_pass(p)
                    break
                except _Unstable as e:
                    self._rerun_or_raise(p, e)
                except NUMERIC as e:  # a step fed non-finite forces or a singular matrix
                    self._rerun_or_raise(p, _blame(p, e))
            for s in p.live:
                self.monitors[s.name] = self.monitor
            self.index += 1
            self.attempt, self.failed_at = 0, []
        return self.tracks, self.frames, self.warnings, self.monitors

    def _start(self, p):
        for s in p.live:  # bad from the start (a network that could not settle): no rerun
            w = s.health()
            if w:
                raise StabilityError(f"{w[0]}, before the first step: the scene was built in a "
                                     "state it cannot run from; nothing was written as a "
                                     f"result; {_fix(s)}")
        self.snaps = {"sys": {s.name: s.capture() for s in p.live},
                      "int": {it.name: it.capture() for it, _ in p.actions}}
        self._fresh(p)

    def _fresh(self, p):
        h = self.coupling_dt or min(p.dts.values())
        n = int(round(self.duration / h))
        if n < 1:
            raise SceneError(f"the coupling step {h:g} s is longer than the duration "
                             f"{self.duration:g} s; shorten the step or lengthen --duration")
        if abs(n * h - self.duration) > 1e-9 * self.duration and self.attempt == 0:
            self.warnings.append(f"duration {self.duration:g} s is not a whole number of "
                                 f"coupling steps of {h:g} s: pass {p.label} runs {n} steps, "
                                 f"{n * h:.9g} s")
        p.h, p.steps, p.wall_s, p.compile_s = h, n, 0.0, 0.0
        p.work = float(n * sum(substeps(h, p.dts[s.name]) * s.generalized_state()[0].size
                               for s in p.live))
        self.monitor = Monitor(p.live)
        self.state = _PassState(recs=[TrackRecorder(s.name, n + 1,
                                                    s.generalized_state()[0].size)
                                      for s in p.record])
        for s, r in zip(p.record, self.state.recs):
            r.record(0.0, *s.generalized_state())
        for it, role in p.actions:
            if role == "standin":
                log = self.logs[it.name]
                log.standin = ForceLog(it.standin.name, it.primary.name, it.primary.name,
                                       "stand-in", it.primary.mass)
                log.standin.allocate(n)
            else:
                self.logs[it.name].allocate(n)
        for s in p.live:
            self.frames[s.name] = {"t": [], "data": []}

    def _rerun_or_raise(self, p, e):
        for s in p.live:
            s.restore(self.snaps["sys"][s.name])
            self.tracks.pop(s.name, None)
        for it, _ in p.actions:
            it.restore(self.snaps["int"][it.name])
        self.failed_at.append(e.t)
        where = f"{e}; {e.system.name} failed at t={e.t:.4g} s"
        # a smaller step that fails no later than the larger one did is not the cure (failures
        # are seen every ~1 ms, so two within the first few checks tell nothing apart)
        helpless = (len(self.failed_at) > 1 and self.failed_at[-2] > 10 * max(p.h, 1e-3)
                    and self.failed_at[-1] <= 1.05 * self.failed_at[-2])
        if not self.refine or self.attempt >= self.max_refinements or helpless:
            tried = (f" (and again at t={self.failed_at[-1]:.4g} s with dt="
                     f"{p.dts[e.system.name]:.3g} s: smaller steps did not help, so the cause "
                     "is physical, not the step)" if helpless else "")
            raise StabilityError(f"{where}{tried}; nothing was written as a result; "
                                 f"{_fix(e.system)}")
        old = p.dts[e.system.name]
        p.dts[e.system.name] = old / 10.0
        self.warnings.append(f"{e.warnings[0]}; reran the pass with {e.system.name} "
                             f"dt={old / 10.0:.3g} s (was {old:.3g} s)")
        self.attempt += 1
        self._fresh(p)

    def _run_pass(self, p: Pass):
        """Run pass p from self.state.k to its end; fill logs, tracks and frames."""
        h, n, st = p.h, p.steps, self.state
        recs, monitor = st.recs, self.monitor
        played_tracks = [(s, self.tracks[s.name]) for s in p.played]
        frame_dt = 1.0 / self.fps
        fr = {s.name: self.frames[s.name] for s in p.live}
        check_every = max(1, int(round(1e-3 / h)))
        live, dts, logs = p.live, p.dts, self.logs
        actions = [(it, role, logs[it.name] if role != "standin" else logs[it.name].standin)
                   for it, role in p.actions]
        for it, role in p.actions:
            it.prepare(h, p.dts)
        self.resumed_step = st.k > 0
        if st.k:  # resumed: prepare() may reset what capture() holds
            for it, _ in p.actions:
                it.restore(self.snaps["now"][it.name])
        deferred = []
        t0 = wallclock.perf_counter() - p.wall_s
        c_base, c0 = p.compile_s, compilation.seconds()

        def elapsed() -> float:
            # the pass's wall time so far without the kernels' compilation (a first run's),
            # which goes to p.compile_s
            spent = compilation.seconds() - c0
            p.compile_s = c_base + spent
            return wallclock.perf_counter() - t0 - spent
        if self.ckpt is not None:
            self.ckpt.start(st.k * h)
        first = st.k
        for k in range(st.k, n + 1):
            t = k * h
            resumed_here = k == first and self.resumed_step
            # played systems are where their tracks say before anything reads them: a live
            # system's frame may depend on one (a garment certified against a played body)
            for s, tr in played_tracks:
                s.set_generalized_state(*tr.sample(t))
                s.time = t
            if not resumed_here and (t >= st.next_frame * frame_dt - 1e-9 * h or k == n):
                while st.next_frame * frame_dt <= t + 0.5 * h:
                    st.next_frame += 1
                for s in live:
                    fr[s.name]["t"].append(t)
                    fr[s.name]["data"].append(s.frame())
            if k == n:
                break
            # checkpoints sit after the step's frame: a frame may show forces held from the
            # last step (a figure's wrenches), which capture() does not keep
            if self.ckpt is not None and k > first and self.ckpt.due(t):
                st.k = k
                p.wall_s = elapsed()
                self.save()
            for s in live:
                s.clear_forces()
            for it, role, log in actions:
                res = it.standin.act(it.primary) if role == "standin" else \
                    it.exchange(role == "both", True)
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
            if (k + 1) % check_every == 0 or k + 1 == n:
                monitor.sample(live)
                for s in live:
                    w = s.health()
                    if w:
                        raise _Unstable(s, w, t + h)
            if self.progress is not None and k % 500 == 0:
                self.progress(p, t, wallclock.perf_counter() - t0)
        p.wall_s = elapsed()
        if self.progress is not None:
            self.progress(p, self.duration, p.wall_s, done=True)
        for s, r in zip(p.record, recs):
            self.tracks[s.name] = r.track()
        for it, role in p.actions:
            (logs[it.name].standin if role == "standin" else logs[it.name]).trim()

    # --- checkpoints -----------------------------------------------------------------------
    def save(self):
        """Write the run's state through the checkpointer (at a step boundary)."""
        p = self.passes[self.index]
        a = {}
        for s in self.systems:
            C.put(a, f"sys/{s.name}", s.capture())
        for it in self.interactions:
            C.put(a, f"int/{it.name}", it.capture())
        for kind, snaps in self.snaps.items():
            if kind != "now":
                for name, snap in snaps.items():
                    C.put(a, f"start/{kind}/{name}", snap)
        for name, log in self.logs.items():
            C.put_log(a, f"log/{name}", log)
        for name, tr in self.tracks.items():
            C.put(a, f"track/{name}", {"t": tr.t, "x": tr.x, "xdot": tr.xdot})
        for r in self.state.recs:
            C.put(a, f"rec/{r.name}", {"t": r.t, "x": r.x, "xdot": r.xdot, "n": np.array(r.n)})
        for name, fr in self.frames.items():
            C.put_frames(a, f"frames/{name}", fr)
        for i, q in enumerate(self.passes[: self.index]):
            a.update(self.monitors[q.live[0].name].arrays(f"mon/{i}"))
        a.update(self.monitor.arrays(f"mon/{self.index}"))
        header = {"pass": self.index, "k": self.state.k, "next_frame": self.state.next_frame,
                  "attempt": self.attempt, "failed_at": self.failed_at,
                  "warnings": self.warnings, "extra": self.extra,
                  "passes": [{"label": q.label, "dts": q.dts, "wall_s": q.wall_s,
                              "compile_s": q.compile_s, "steps": q.steps, "h": q.h,
                              "work": q.work}
                             for q in self.passes],
                  "systems": [s.name for s in self.systems]}
        self.ckpt.save(header, a, self.state.k * p.h)

    def restore(self, header: dict, a: dict):
        """Continue from a checkpoint of this same scene (``checkpoint.read``)."""
        names = [s.name for s in self.systems]
        labels = [q.label for q in self.passes]
        if header["systems"] != names or [q["label"] for q in header["passes"]] != labels:
            from ..errors import OutputError
            raise OutputError("the checkpoint is of another scene layout (systems "
                              f"{', '.join(header['systems'])}); run again without --resume")
        for q, saved in zip(self.passes, header["passes"]):
            q.dts.update(saved["dts"])
            q.wall_s, q.steps, q.h = saved["wall_s"], saved["steps"], saved["h"]
            q.compile_s = saved["compile_s"]
            q.work = saved["work"]
        for s in self.systems:
            s.restore(C.take(a, f"sys/{s.name}"))
        now = {it.name: C.take(a, f"int/{it.name}") for it in self.interactions}
        for it in self.interactions:
            it.restore(now[it.name])
        self.index, self.attempt = header["pass"], header["attempt"]
        self.failed_at, self.warnings = header["failed_at"], header["warnings"]
        self.extra = header.get("extra", {})
        p = self.passes[self.index]
        self.snaps = {"sys": {s.name: C.take(a, f"start/sys/{s.name}") for s in p.live},
                      "int": {it.name: C.take(a, f"start/int/{it.name}") for it, _ in p.actions},
                      "now": now}
        for name, log in self.logs.items():
            C.take_log(a, f"log/{name}", log)
        from .track import Track
        for key in a:
            if key.startswith("track/") and key.endswith("/t"):
                name = key[6:-2]
                self.tracks[name] = Track(name, a[key].copy(), a[f"track/{name}/x"].copy(),
                                          a[f"track/{name}/xdot"].copy())
        recs = []
        for s in p.record:
            r = TrackRecorder(s.name, 0, 0)
            r.t, r.x, r.xdot = (a[f"rec/{s.name}/{k}"].copy() for k in ("t", "x", "xdot"))
            r.n = int(a[f"rec/{s.name}/n"])
            recs.append(r)
        self.state = _PassState(header["k"], header["next_frame"], recs)
        for key in a:
            if key.startswith("frames/") and key.endswith("/t"):
                name = key[7:-2]
                self.frames[name] = C.take_frames(a, f"frames/{name}")
        for i, q in enumerate(self.passes[: self.index + 1]):
            mon = Monitor.from_arrays(a, f"mon/{i}", [s.name for s in q.live])
            if i < self.index:
                for s in q.live:
                    self.monitors[s.name] = mon
            else:
                self.monitor = mon
        self.resumed = True


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
