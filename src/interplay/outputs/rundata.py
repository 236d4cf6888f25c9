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
from ..result import strict_json
from ..systems.shape import Shape

SCENE_FILE = "scene.json"
QUATERNION_KEYS = ("orientation", "segment_orientations")  # (w, x, y, z), last axis
# what outputs read back from tracks.npz
FRAME_KEYS = ("t", "points", "position", "orientation", "segment_positions",
              "segment_orientations", "heights", "particles")
FORMAT_VERSION = 1
FORMS = ("body", "parts", "surface", "cords", "particles", "static")

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


def write_scene_file(run: RunData, out_dir, run_id: str | None = None) -> Path:
    """Write scene.json (shapes and run settings) beside tracks.npz; returns its path."""
    path = Path(out_dir) / SCENE_FILE
    doc = {"format": FORMAT_VERSION, "run_id": run_id, "scene": run.scene,
           "coupling": run.coupling,
           "fps": run.fps, "duration_s": run.duration, "primary": run.primary,
           "units": "m, s; +z up", "shapes": [s.to_json() for s in run.shapes]}
    with atomic_path(path) as tmp:
        tmp.write_text(strict_json(doc))
    return path


def load_run(run_dir) -> RunData:
    """Read a saved run (scene.json, tracks.npz, summary.json if present) back as RunData.

    A saved folder is data, never code: tracks.npz is read with ``allow_pickle=False`` and
    every shape, array, dtype and run id is checked before use (``_check``), so a damaged or
    hostile folder is one InterplayError naming the file and what is wrong."""
    from .runfolder import verify
    d = Path(run_dir)
    scene_path, tracks_path = d / SCENE_FILE, d / "tracks.npz"
    for p in (scene_path, tracks_path):
        if not p.is_file():
            raise InterplayError(f"{d}: no {p.name} here; pass the directory `interplay run` "
                                 "or `interplay compare` wrote (e.g. out/basketball/two-way)")
    manifest = verify(d)
    doc = _json_file(scene_path)
    run_id = manifest.get("run_id")
    if not isinstance(doc, dict) or doc.get("format") != FORMAT_VERSION:
        raise InterplayError(f"{scene_path}: not a scene file of format {FORMAT_VERSION}; run "
                             "the scene again")
    for key, kind in (("scene", str), ("coupling", str), ("fps", float),
                      ("duration_s", float), ("shapes", list)):
        v = doc.get(key)
        ok = isinstance(v, kind) or (kind is float and isinstance(v, int)
                                     and not isinstance(v, bool))
        if not ok or (kind is float and not (np.isfinite(v) and v > 0)):
            raise InterplayError(f"{scene_path}: {key} is missing or not a valid "
                                 f"{kind.__name__} ({v!r}); run the scene again")
    shapes = []
    for i, sd in enumerate(doc["shapes"]):
        try:
            sh = Shape.from_json(sd)
            if not (isinstance(sh.name, str) and sh.form in FORMS and isinstance(sh.palette, str)
                    and len(sh.color) == 3 and np.isfinite(np.asarray(sh.color, float)).all()
                    and np.isfinite(sh.width)):
                raise ValueError("name, form, palette, color or width")
            shapes.append(sh)
        except Exception as e:  # noqa: BLE001 - any malformed entry is the same answer
            raise InterplayError(f"{scene_path}: shape {i} is malformed ({type(e).__name__}: "
                                 f"{e}); run the scene again") from None
    if len({sh.name for sh in shapes}) != len(shapes):
        raise InterplayError(f"{scene_path}: two shapes share a name; run the scene again")
    frames: dict = {}
    try:
        with np.load(tracks_path, allow_pickle=False) as npz:
            ids = npz["run_id"] if "run_id" in npz.files else None
            for key in npz.files:
                name, _, field_ = key.rpartition("/")
                if field_ in FRAME_KEYS:
                    frames.setdefault(name, {})[field_] = npz[key]
    except Exception as e:  # noqa: BLE001 - zip, zlib, format and pickle refusals alike
        raise InterplayError(f"{tracks_path}: cannot read the saved run ({type(e).__name__}: "
                             f"{e}); run it again") from None
    summary = _json_file(d / "summary.json") if (d / "summary.json").is_file() else None
    # the manifest's id, else scene.json's: every file of the folder must carry it
    run_id = run_id or doc.get("run_id")
    for what, rid in (("scene.json", doc.get("run_id")),
                      ("tracks.npz", None if ids is None else str(ids)),
                      ("summary.json", summary.get("run_id", run_id)
                       if isinstance(summary, dict) else run_id)):
        if run_id is not None and rid != run_id:
            raise InterplayError(f"{d}: {what} belongs to run {rid}, not to run {run_id} (a "
                                 "folder mixing two runs); run the scene again")
    _check(frames, shapes, tracks_path)
    frames = _derive(frames, shapes)
    return RunData(doc["scene"], doc["coupling"], float(doc["fps"]), float(doc["duration_s"]),
                   shapes, frames, doc.get("primary"), summary)


def _json_file(path: Path):
    try:
        return json.loads(path.read_text())
    except (ValueError, OSError, UnicodeDecodeError) as e:
        raise InterplayError(f"{path}: damaged JSON ({e}); run the scene again") from None


# the trailing shape of each frame array, from the shape it draws (None: any length)
def _expected(key, shape):
    n = None if shape is None else (
        len(shape.verts) if shape.verts is not None and shape.form in ("surface", "cords")
        else None)
    parts = None if shape is None or shape.parts is None else len(shape.parts)
    return {"t": (), "position": (3,), "orientation": (4,), "points": (n, 3),
            "segment_positions": (parts, 3), "segment_orientations": (parts, 4),
            "heights": (None if shape is None or shape.grid_xy is None else len(shape.grid_xy),),
            "particles": (None, 3)}[key]


def _check(frames: dict, shapes, path):
    """Every frame array a float array of the shape its system's Shape implies, the same
    number of frames per system, times finite and increasing, values finite (absent spray
    particles are whole NaN rows)."""
    by_name = {sh.name: sh for sh in shapes}
    for sh in shapes:
        if sh.animated and sh.source is None:
            need = {"body": ("position", "orientation"),
                    "parts": ("segment_positions", "segment_orientations"),
                    "surface": ("heights",) if sh.grid_xy is not None else ("points",),
                    "cords": ("points",)}.get(sh.form, ())
            missing = [k for k in ("t", *need) if k not in frames.get(sh.name, {})]
            if missing:
                raise InterplayError(f"{path}: no {', '.join(missing)} frames for {sh.name}; "
                                     "run the scene again")
    for name, fr in frames.items():
        t = fr.get("t")
        if t is None or t.ndim != 1 or len(t) == 0:
            raise InterplayError(f"{path}: {name}/t is missing or not a list of times")
        for key, a in fr.items():
            want = _expected(key, by_name.get(name))
            if key == "heights" and a.ndim > 2:  # a water system saves its (nx, ny) grid
                a = a.reshape(len(a), -1)
            if a.dtype.kind != "f" or a.ndim != 1 + len(want) or len(a) != len(t) or any(
                    w is not None and g != w for g, w in zip(a.shape[1:], want)):
                raise InterplayError(f"{path}: {name}/{key} has shape {a.shape} and dtype "
                                     f"{a.dtype}; expected ({len(t)}, "
                                     f"{', '.join('n' if w is None else str(w) for w in want)})"
                                     " floats; run the scene again")
            sh = by_name.get(name)
            idx = None if sh is None else (sh.triangles if sh.triangles is not None
                                           else sh.segments)
            if key == "points" and idx is not None and len(idx) and a.shape[1] <= idx.max():
                raise InterplayError(f"{path}: {name}/points has {a.shape[1]} points but its "
                                     f"shape uses point {int(idx.max())}; run the scene again")
            ok = np.isfinite(a)
            if key == "particles":
                ok = ok.all(-1) | np.isnan(a).all(-1)
            if not ok.all():
                raise InterplayError(f"{path}: {name}/{key} holds NaN or inf; run the scene "
                                     "again")
        if np.any(np.diff(t) <= 0):
            raise InterplayError(f"{path}: {name}/t does not increase; run the scene again")
