"""What every output needs to redraw a run: each system's shapes and its motion per frame.

``RunData`` is built from a Result (``from_result``: the shapes the systems described when
the run ended) or from a saved run directory (``load_run``: scene.json + tracks.npz +
summary.json), so the USD and OBJ exporters, the preview renderer and the web viewer read one
structure and need no scene-specific code. Shapes (systems/shape.py) come with their form;
a shape without its own colour takes the next of its palette family's colours here.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import InterplayError
from ..io.atomic import atomic_path
from ..systems.shape import Shape

SCENE_FILE = "scene.json"
QUATERNION_KEYS = ("orientation", "segment_orientations")  # (w, x, y, z), last axis
# what outputs read back from tracks.npz
FRAME_KEYS = ("t", "points", "position", "orientation", "segment_positions",
              "segment_orientations", "heights", "particles")
FORMAT_VERSION = 1

# linear RGB in 0..1, per palette family (systems/shape.py)
_PALETTE = {"rigid": [(0.85, 0.38, 0.10), (0.20, 0.45, 0.80), (0.30, 0.65, 0.30)],
            "cloth": [(0.93, 0.93, 0.90), (0.85, 0.75, 0.30), (0.60, 0.40, 0.70)],
            "static": [(0.55, 0.55, 0.57)],
            "other": [(0.35, 0.70, 0.85)]}


@dataclass
class RunData:
    """A run as outputs see it: scene name, coupling, fps (frames/s), duration (s), shapes,
    and ``frames[name]`` = {"t": (f,) s, "points": (f,n,3) m | "position": (f,3) m,
    "orientation": (f,4) w,x,y,z}."""
    scene: str
    coupling: str
    fps: float
    duration: float
    shapes: list
    frames: dict
    primary: str | None = None
    summary: dict | None = field(default=None, repr=False)

    def shape(self, name: str) -> Shape:
        for s in self.shapes:
            if s.name == name:
                return s
        raise KeyError(name)

    @property
    def times(self) -> np.ndarray:
        """Output frame times (s), shared by every animated system."""
        for s in self.shapes:
            t = self.frames.get(s.name, {}).get("t")
            if s.animated and t is not None and len(t):
                return np.asarray(t, dtype=float)
        return np.arange(int(round(self.duration * self.fps)) + 1) / self.fps

    def points(self, name: str, i: int) -> np.ndarray:
        """World points (n,3) of a deforming system at output frame i."""
        return self.frames[name]["points"][i]

    def pose(self, name: str, i: int) -> tuple[np.ndarray, np.ndarray]:
        """(position (3,) m, unit quaternion (4,) w,x,y,z) of a body at output frame i."""
        fr = self.frames[name]
        return fr["position"][i], fr["orientation"][i]

    def sample(self, name: str, t: float) -> dict:
        """A system's state at time t (s), linear between frames (quaternions normalised):
        what a video at another frame rate shows."""
        fr = self.frames[name]
        times = np.asarray(fr["t"], dtype=float)
        if len(times) == 1:
            return {k: v[0] for k, v in fr.items() if k != "t"}
        j = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2))
        a = float(np.clip((t - times[j]) / (times[j + 1] - times[j]), 0.0, 1.0))
        out = {}
        for key, arr in fr.items():
            if key == "t":
                continue
            q0, q1 = arr[j], arr[j + 1]
            if np.isnan(q0).any() or np.isnan(q1).any():
                out[key] = q0 if a < 0.5 else q1  # particles come and go: no blending
            elif key in QUATERNION_KEYS:
                # the shorter way round, row by row, then back to unit length
                q1 = np.where((q0 * q1).sum(-1, keepdims=True) < 0, -q1, q1)
                v = (1 - a) * q0 + a * q1
                out[key] = v / np.linalg.norm(v, axis=-1, keepdims=True)
            else:
                out[key] = (1 - a) * q0 + a * q1
        return out

    def bounds(self, at: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box (lo, hi) in m around every animated system over the whole run, or
        at the output frame nearest time ``at`` (s) (static systems such as a 20 m floor
        would swamp the framing)."""
        pts = []
        for s in self.shapes:
            fr = self.frames.get(s.name, {})
            if at is not None and len(fr.get("t", ())):
                i = int(np.argmin(np.abs(np.asarray(fr["t"], dtype=float) - at)))
                fr = {k: v[i:i + 1] for k, v in fr.items()}
            if s.form == "body" and "position" in fr and len(fr["position"]):
                r = float(np.max(np.linalg.norm(s.verts, axis=1))) if s.verts is not None else 0
                p = fr["position"]
                pts += [p.min(0) - r, p.max(0) + r]
            elif s.form == "parts" and len(fr.get("segment_positions", ())):
                r = max(float(np.max(np.linalg.norm(v, axis=1))) for v, _ in s.parts)
                p = fr["segment_positions"]
                pts += [p.min((0, 1)) - r, p.max((0, 1)) + r]
            elif "points" in fr and np.isfinite(fr["points"]).any():
                p = fr["points"]
                pts += [np.nanmin(p, (0, 1)), np.nanmax(p, (0, 1))]
            if s.anchors is not None and len(s.anchors):
                pts += [s.anchors.min(0), s.anchors.max(0)]
        if not pts:
            return np.array([-1.0, -1.0, 0.0]), np.array([1.0, 1.0, 2.0])
        pts = np.array(pts)
        return pts.min(0), pts.max(0)


def coloured(shapes) -> list:
    """The shapes with a colour each: their own, or the next of their palette family's."""
    counts: dict = {}
    out = []
    for sh in shapes:
        if sh.color is None:
            family = sh.palette if sh.palette in _PALETTE else "other"
            i = counts.get(family, 0)
            counts[family] = i + 1
            sh = replace(sh, color=_PALETTE[family][i % len(_PALETTE[family])])
        out.append(sh)
    return out


def from_result(result) -> RunData:
    """RunData of a Result (frames are shared, not copied)."""
    shapes = coloured(result.shapes)
    frames = _derive(dict(result.frames), shapes)  # the Result's own dict stays untouched
    return RunData(result.scene, result.coupling, result.fps, result.duration, shapes, frames,
                   result.primary)


def _derive(frames: dict, shapes) -> dict:
    """Add the per-frame points of derived shapes: a height field's grid + heights, spray
    from its system's particle array."""
    for s in shapes:
        if s.grid_xy is not None and "heights" in frames.get(s.name, {}):
            fr = dict(frames[s.name])
            h = np.asarray(fr["heights"]).reshape(len(fr["heights"]), -1)
            xy = np.broadcast_to(s.grid_xy, (len(h), *s.grid_xy.shape))
            fr["points"] = np.concatenate([xy, h[..., None]], axis=-1)
            frames[s.name] = fr
        elif s.source is not None and s.source[0] in frames:
            src = frames[s.source[0]]
            frames[s.name] = {"t": src["t"], "points": src[s.source[1]]}
    return frames


def write_scene_file(run: RunData, out_dir) -> Path:
    """Write scene.json (shapes and run settings) beside tracks.npz; returns its path."""
    path = Path(out_dir) / SCENE_FILE
    doc = {"format": FORMAT_VERSION, "scene": run.scene, "coupling": run.coupling,
           "fps": run.fps, "duration_s": run.duration, "primary": run.primary,
           "units": "m, s; +z up", "shapes": [s.to_json() for s in run.shapes]}
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(doc))
    return path


def load_run(run_dir) -> RunData:
    """Read a saved run (scene.json, tracks.npz, summary.json if present) back as RunData."""
    d = Path(run_dir)
    scene_path, tracks_path = d / SCENE_FILE, d / "tracks.npz"
    for p in (scene_path, tracks_path):
        if not p.is_file():
            raise InterplayError(f"{d}: no {p.name} here; pass the directory `interplay run` "
                                 "or `interplay compare` wrote (e.g. out/basketball/two-way)")
    try:
        doc = json.loads(scene_path.read_text())
        shapes = [Shape.from_json(s) for s in doc["shapes"]]
        frames: dict = {}
        with np.load(tracks_path) as npz:
            for key in npz.files:
                name, _, field_ = key.rpartition("/")
                if field_ in FRAME_KEYS:
                    frames.setdefault(name, {})[field_] = npz[key]
        frames = _derive(frames, shapes)
    except (ValueError, KeyError, OSError) as e:
        raise InterplayError(f"{d}: cannot read the saved run ({e}); run it again") from None
    summary = None
    if (d / "summary.json").is_file():
        summary = json.loads((d / "summary.json").read_text())
    return RunData(doc["scene"], doc["coupling"], float(doc["fps"]), float(doc["duration_s"]),
                   shapes, frames, doc.get("primary"), summary)
