"""Result of a run, as data: tracks, force logs, frames, timings, diagnostics, the systems'
descriptions and shapes; summary.json and tracks.npz.

A Result holds no live system or interaction: everything the analysis, the reports, the
compare tables and the outputs read was copied out of the scene when the run ended
(``Result.of``), so a Result can be kept, compared and written after the scene is gone.
"""
from __future__ import annotations

import json
import math

import numpy as np

from .analysis.advisor import advise
from .analysis.table import interaction_stats
from .io.atomic import atomic_path


class Result:
    """What ``Scene.simulate()`` returns.

    scene: the scene's name; coupling, duration (s), fps, primary (name or None), main (the
    main interaction's name or None); systems, interactions: their ``describe()``; shapes:
    every system's Shapes; checkpoints: {system: times (s)}; meta: the scene's metadata;
    passes: each pass's ``describe()``; logs: {interaction: ForceLog}; tracks: {system: Track}
    (full-rate (x, xdot) of recorded systems); frames: {system: {key: (f, ...)}} per output
    frame; warnings; diagnostics: {system: {...}} (energy, lowest point, strain, the system's
    own); total_s: wall time (s) of the whole run, compilation included (see compile_s).
    """

    def __init__(self, scene, coupling, duration, fps, primary, main, systems, interactions,
                 shapes, checkpoints, meta, passes, logs, tracks, frames, warnings, diagnostics,
                 total_s):
        self.scene, self.coupling, self.duration, self.fps = scene, coupling, duration, fps
        self.primary, self.main = primary, main
        self.systems, self.interactions, self.shapes = systems, interactions, shapes
        self.checkpoint_times, self.meta = checkpoints, meta
        self.passes, self.logs, self.tracks, self.frames = passes, logs, tracks, frames
        self.warnings, self.diagnostics, self.total_s = warnings, diagnostics, total_s

    @classmethod
    def of(cls, scene, passes, logs, tracks, frames, warnings, monitors, initial_ke, total_s):
        """Copy what a finished run of ``scene`` produced out of its live objects."""
        main = scene.main_interaction
        shapes = [sh for s in scene.systems for sh in s.shapes()]
        return cls(scene.name, scene.coupling, float(scene.duration), float(scene.fps),
                   scene.primary.name if scene.primary is not None else None,
                   main.name if main is not None else None,
                   [s.describe() for s in scene.systems],
                   [it.describe() for it in scene.interactions], shapes,
                   {k: list(v) for k, v in scene.checkpoints.items()}, dict(scene.meta),
                   [p.describe() for p in passes], logs, tracks, frames, list(warnings),
                   _diagnostics(scene.systems, monitors, initial_ke, warnings), total_s)

    # --- lookups -----------------------------------------------------------------------------
    def interaction(self, name: str) -> dict:
        """The description of the interaction called ``name``."""
        return next(it for it in self.interactions if it["name"] == name)

    def system(self, name: str) -> dict:
        """The description of the system called ``name``."""
        return next(s for s in self.systems if s["name"] == name)

    @property
    def main_interaction(self) -> dict | None:
        return None if self.main is None else self.interaction(self.main)

    # --- timings ---------------------------------------------------------------------------
    def _primary_pass_index(self) -> int:
        for i, p in enumerate(self.passes):
            if self.primary is not None and self.primary in p["systems"]:
                return i
        return len(self.passes) - 1

    @property
    def primary_cycle_s(self) -> float:
        """Primary debug-cycle time: wall time (s) until the primary's motion is complete."""
        i = self._primary_pass_index()
        return float(sum(p["wall_s"] for p in self.passes[: i + 1]))

    @property
    def compile_s(self) -> float:
        """Wall time (s) the run spent compiling Numba kernels (a first run, on an empty
        cache) or loading them from the cache; not in any pass's wall time."""
        return float(sum(p["compile_s"] for p in self.passes))

    def timings(self) -> dict:
        """(s) primary_pass_s: the primary debug-cycle time; secondary_pass_s: the passes
        after it; compile_s: kernels compiled or loaded (in neither); total_s: all of it."""
        prim = self.primary_cycle_s
        return {"primary_pass_s": prim,
                "secondary_pass_s": float(sum(p["wall_s"] for p in self.passes)) - prim,
                "compile_s": self.compile_s, "total_s": float(self.total_s),
                "passes": self.passes}

    # --- states ----------------------------------------------------------------------------
    def state_at(self, system: str, t: float):
        """(x, xdot) of a recorded system at time t (cubic Hermite between steps)."""
        return self.tracks[system].sample(t)

    def checkpoints(self) -> list[dict]:
        out = []
        for name, times in self.checkpoint_times.items():
            if name not in self.tracks:
                continue
            for t in times:
                if t <= self.duration:
                    x, v = self.state_at(name, t)
                    out.append({"system": name, "t": t, "position": x[:3].tolist(),
                                "velocity": v[:3].tolist()})
        return out

    # --- analysis --------------------------------------------------------------------------
    def interaction_stats(self) -> list[dict]:
        return [interaction_stats(self.logs[it["name"]]) for it in self.interactions]

    @property
    def work(self) -> float:
        """State values advanced over the run (substeps x values, every pass): its cost as a
        count, the same on any machine."""
        return float(sum(p.get("work", 0.0) for p in self.passes))

    def advice(self, one_way_stable=None, two_way_work=None, two_way_wall_s=None,
               debug_cycle=None) -> dict:
        """The advisor's verdict for the scene's main interaction; the verdict depends on
        counts only, unless debug_cycle gives the measured times of a hand-tuned primary
        (analysis/advisor.py); the wall time of the two-way run is reported beside it."""
        out = self._advice(one_way_stable, two_way_work, debug_cycle=debug_cycle)
        if two_way_wall_s is None and self.coupling == "two-way":
            two_way_wall_s = self.total_s - self.compile_s
        if two_way_wall_s is not None:
            out["two_way_wall_s"] = float(two_way_wall_s)
        return out

    def advice_for(self, it: dict) -> dict:
        """The advisor's verdict for any interaction (its ``describe()``) from this run."""
        return self._advice(None, None, it)

    def _advice(self, one_way_stable, two_way_cost_s, it=None, debug_cycle=None) -> dict:
        """The advisor's verdict for the interaction described by ``it`` (default: the
        scene's main interaction); debug_cycle: analysis/advisor.py ``advise``."""
        it = self.main_interaction if it is None else it
        if it is None:
            return {"mode": None, "reasons": ["no interaction acts on a moving system"]}
        if one_way_stable is None and it["mode"] != "two-way":
            one_way_stable = not any(it["secondary"] in w for w in self.warnings)
        if two_way_cost_s is None and it["mode"] == "two-way":
            two_way_cost_s = self.work
        return advise(interaction_stats(self.logs[it["name"]]), it, one_way_stable,
                      two_way_cost_s, debug_cycle=debug_cycle)

    def summary(self, **advice_kw) -> dict:
        return {"scene": self.scene, "coupling": self.coupling, "duration_s": self.duration,
                "fps": self.fps, "systems": self.systems, "timings": self.timings(),
                "interactions": self.interaction_stats(), "advice": self.advice(**advice_kw),
                "interaction_advice": {it["name"]: self.advice_for(it)
                                       for it in self.interactions},
                "diagnostics": self.diagnostics, "primary_checkpoints": self.checkpoints(),
                "warnings": list(self.warnings)}

    # --- files -----------------------------------------------------------------------------
    def save(self, out_dir, summary: dict | None = None, run_id: str | None = None) -> list:
        """Write summary.json (strict JSON: a non-finite number is written as null) and
        tracks.npz into out_dir (atomically); both carry ``run_id`` when given. Returns the
        paths."""
        from pathlib import Path
        out = Path(out_dir)
        summary = summary if summary is not None else self.summary()
        if run_id is not None:
            summary = dict(summary, run_id=run_id)
        paths = [out / "summary.json", out / "tracks.npz"]
        with atomic_path(paths[0]) as tmp:
            tmp.write_text(strict_json(summary, indent=2))
        arrays = {} if run_id is None else {"run_id": np.array(run_id)}
        for name, fr in self.frames.items():
            for key, arr in fr.items():
                arrays[f"{name}/{key}"] = arr
        for name, tr in self.tracks.items():
            arrays[f"{name}/track_t"] = tr.t
            arrays[f"{name}/track_x"] = tr.x
            arrays[f"{name}/track_xdot"] = tr.xdot
        with atomic_path(paths[1]) as tmp:
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, **arrays)
        return paths


def _diagnostics(systems, monitors, initial_ke, warnings) -> dict:
    """Per moving system: kinetic energy (initial, max, final), lowest point, instabilities,
    largest strain, and the system's own extra diagnostics."""
    out = {}
    for s in systems:
        if s.name not in monitors:
            continue
        mon = monitors[s.name]
        ke = mon.ke[s.name]
        d = {"kinetic_energy_J": {"initial": float(initial_ke[s.name]),
                                  "max": float(max(ke)), "final": float(ke[-1])},
             "lowest_z_m": float(min(mon.lowest[s.name])) if mon.lowest[s.name] else None,
             "instability": [w for w in warnings if w.startswith(s.name + ":")]}
        if mon.strain[s.name]:
            d["max_strain"] = float(max(mon.strain[s.name]))
        d.update(s.extra_diagnostics())
        out[s.name] = d
    return out


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o).__name__)


def finite(o):
    """``o`` with every non-finite float replaced by None (JSON has no NaN or inf)."""
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {k: finite(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [finite(v) for v in o]
    if isinstance(o, (np.generic, np.ndarray)):
        return finite(_json_default(o))
    return o


def strict_json(doc, **kw) -> str:
    """``doc`` as strict JSON (RFC 8259): NaN and inf, which no JSON parser must accept,
    become null; anything else unknown is an error."""
    return json.dumps(finite(doc), allow_nan=False, default=_json_default, **kw)
