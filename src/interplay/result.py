"""Result of a run: tracks, force logs, timings, diagnostics; summary.json and tracks.npz."""
from __future__ import annotations

import json

import numpy as np

from .analysis.advisor import advise
from .analysis.table import interaction_stats
from .io.atomic import atomic_path


class Result:
    """What ``Scene.simulate()`` returns.

    tracks: full-rate (x, xdot) of recorded systems; frames: per system, per output frame;
    logs: per interaction ForceLog; passes: the scheduler's passes with their wall times.
    """

    def __init__(self, scene, passes, logs, tracks, frames, warnings, monitors, initial_ke,
                 total_s):
        self.scene = scene
        self.passes = passes
        self.logs = logs
        self.tracks = tracks
        self.frames = frames
        self.warnings = warnings
        self.monitors = monitors
        self.initial_ke = initial_ke
        self.total_s = total_s

    # --- timings ---------------------------------------------------------------------------
    def _primary_pass_index(self) -> int:
        prim = self.scene.primary
        for i, p in enumerate(self.passes):
            if prim is not None and prim in p.live:
                return i
        return len(self.passes) - 1

    @property
    def primary_cycle_s(self) -> float:
        """Primary debug-cycle time: wall time (s) until the primary's motion is complete."""
        i = self._primary_pass_index()
        return float(sum(p.wall_s for p in self.passes[: i + 1]))

    def timings(self) -> dict:
        prim = self.primary_cycle_s
        return {"primary_pass_s": prim,
                "secondary_pass_s": float(sum(p.wall_s for p in self.passes)) - prim,
                "total_s": float(self.total_s),
                "passes": [{"systems": [s.name for s in p.live], "played": [s.name for s in p.played],
                            "wall_s": p.wall_s, "steps": p.steps, "coupling_dt_s": p.h}
                           for p in self.passes]}

    # --- states ----------------------------------------------------------------------------
    def state_at(self, system: str, t: float):
        """(x, xdot) of a recorded system at time t (cubic Hermite between steps)."""
        return self.tracks[system].sample(t)

    def checkpoints(self) -> list[dict]:
        out = []
        for name, times in self.scene.checkpoints.items():
            if name not in self.tracks:
                continue
            for t in times:
                if t <= self.scene.duration:
                    x, v = self.state_at(name, t)
                    out.append({"system": name, "t": t, "position": x[:3].tolist(),
                                "velocity": v[:3].tolist()})
        return out

    # --- analysis --------------------------------------------------------------------------
    def interaction_stats(self) -> list[dict]:
        return [interaction_stats(self.logs[it.name]) for it in self.scene.interactions]

    def advice(self, one_way_stable=None, two_way_cost_s=None) -> dict:
        """The advisor's verdict for the scene's main interaction (Scene.main_interaction)."""
        it = self.scene.main_interaction
        if it is None:
            return {"mode": None, "reasons": ["no interaction acts on a dynamic system"]}
        if one_way_stable is None and it.mode != "two-way":
            one_way_stable = not any(it.secondary.name in w for w in self.warnings)
        if two_way_cost_s is None and it.mode == "two-way":
            two_way_cost_s = self.total_s
        return advise(interaction_stats(self.logs[it.name]), it, one_way_stable, two_way_cost_s)

    def diagnostics(self) -> dict:
        out = {}
        for s in self.scene.systems:
            if not s.dynamic or s.name not in self.monitors:
                continue
            mon = self.monitors[s.name]
            ke = mon.ke[s.name]
            d = {"kinetic_energy_J": {"initial": float(self.initial_ke[s.name]),
                                      "max": float(max(ke)), "final": float(ke[-1])},
                 "lowest_z_m": float(min(mon.lowest[s.name])) if mon.lowest[s.name] else None,
                 "instability": [w for w in self.warnings if w.startswith(s.name + ":")]}
            if s.name in mon.strain:
                d["max_strain"] = float(max(mon.strain[s.name], default=0.0))
            d.update(s.extra_diagnostics())
            out[s.name] = d
        return out

    def summary(self, **advice_kw) -> dict:
        sc = self.scene
        return {"scene": sc.name, "coupling": sc.coupling, "duration_s": sc.duration,
                "fps": sc.fps,
                "systems": [s.describe() for s in sc.systems],
                "timings": self.timings(),
                "interactions": self.interaction_stats(),
                "advice": self.advice(**advice_kw),
                "diagnostics": self.diagnostics(),
                "primary_checkpoints": self.checkpoints(),
                "warnings": list(self.warnings)}

    # --- files -----------------------------------------------------------------------------
    def save(self, out_dir, summary: dict | None = None) -> list:
        """Write summary.json and tracks.npz into out_dir (atomically). Returns the paths."""
        from pathlib import Path
        out = Path(out_dir)
        summary = summary if summary is not None else self.summary()
        paths = [out / "summary.json", out / "tracks.npz"]
        with atomic_path(paths[0]) as tmp:
            tmp.write_text(json.dumps(summary, indent=2, default=_json_default))
        arrays = {}
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


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o).__name__)
