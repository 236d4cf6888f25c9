"""What every output needs to redraw a run: each system's shape and its motion per frame.

``RunData`` is built from a live ``Result`` (``from_result``) or from a saved run directory
(``load_run``: scene.json + tracks.npz + summary.json), so the USD and OBJ exporters, the
preview renderer and the web viewer read one structure and need no scene-specific code.

Each system becomes a ``Shape`` of one *form*:
  body       a rigid body: a body-frame mesh moved by per-frame position + orientation
  parts      an articulated figure: one body-frame mesh per segment, moved by per-frame
             segment_positions (k,3) + segment_orientations (k,4)
  surface    a deforming mesh: per-frame points and fixed triangles (a height field's points
             are made from its grid and per-frame heights)
  cords      a network without faces: per-frame points and fixed (s,2) segments
  particles  per-frame points only (NaN rows are absent particles: spray)
  static     a world-space mesh that never moves (the floor)
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InterplayError
from ..io.atomic import atomic_path

SCENE_FILE = "scene.json"
QUATERNION_KEYS = ("orientation", "segment_orientations")  # (w, x, y, z), last axis
# what outputs read back from tracks.npz
FRAME_KEYS = ("t", "points", "position", "orientation", "segment_positions",
              "segment_orientations", "heights", "particles")
FORMAT_VERSION = 1

# linear RGB in 0..1; a system may carry its own ``color`` attribute instead
_PALETTE = {"rigid": [(0.85, 0.38, 0.10), (0.20, 0.45, 0.80), (0.30, 0.65, 0.30)],
            "springmass": [(0.93, 0.93, 0.90), (0.85, 0.75, 0.30), (0.60, 0.40, 0.70)],
            "static": [(0.55, 0.55, 0.57)],
            "other": [(0.35, 0.70, 0.85)]}


@dataclass
class Shape:
    """One system's geometry. Lengths in m; colour linear RGB 0..1.

    verts/tris: body-frame mesh (body) or world mesh (static); triangles: faces over the
    per-frame points (surface); segments: (s,2) point pairs (cords); width: cord or particle
    diameter (m); anchors: (a,3) fixed world points a network hangs from (drawn as hooks);
    parts: [(verts, tris)] per segment of a figure; grid_xy: (n,2) column centres of a height
    field; source: (system, frame key) a derived shape's points come from (water spray).
    """
    name: str
    form: str
    color: tuple
    verts: np.ndarray | None = None
    tris: np.ndarray | None = None
    triangles: np.ndarray | None = None
    segments: np.ndarray | None = None
    width: float = 0.0
    anchors: np.ndarray | None = None
    parts: list | None = None
    grid_xy: np.ndarray | None = None
    source: tuple | None = None

    @property
    def animated(self) -> bool:
        return self.form != "static"

    def to_json(self) -> dict:
        out = {"name": self.name, "form": self.form, "color": list(self.color),
               "width": self.width}
        for key in ("verts", "tris", "triangles", "segments", "anchors", "grid_xy"):
            val = getattr(self, key)
            if val is not None:
                out[key] = np.asarray(val).tolist()
        if self.parts is not None:
            out["parts"] = [[np.asarray(v).tolist(), np.asarray(t).tolist()]
                            for v, t in self.parts]
        if self.source is not None:
            out["source"] = list(self.source)
        return out

    @staticmethod
    def from_json(d: dict) -> "Shape":
        arrays = {}
        for key, dtype in (("verts", float), ("tris", np.int64), ("triangles", np.int64),
                           ("segments", np.int64), ("anchors", float), ("grid_xy", float)):
            if key in d:
                cols = 2 if key in ("segments", "grid_xy") else 3
                arrays[key] = np.asarray(d[key], dtype=dtype).reshape(-1, cols)
        if "parts" in d:
            arrays["parts"] = [(np.asarray(v, float).reshape(-1, 3),
                                np.asarray(t, np.int64).reshape(-1, 3)) for v, t in d["parts"]]
        if "source" in d:
            arrays["source"] = tuple(d["source"])
        return Shape(d["name"], d["form"], tuple(d["color"]), width=float(d.get("width", 0.0)),
                     **arrays)


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

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box (lo, hi) in m around every animated system over the whole run
        (static systems such as a 20 m floor would swamp the framing)."""
        pts = []
        for s in self.shapes:
            fr = self.frames.get(s.name, {})
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


def _color(system, kind_counts) -> tuple:
    own = getattr(system, "color", None)
    if own is not None:
        return tuple(float(c) for c in own)
    kind = system.kind if system.kind in _PALETTE else "other"
    i = kind_counts.get(kind, 0)
    kind_counts[kind] = i + 1
    pal = _PALETTE[kind]
    return pal[i % len(pal)]


def _cord_width(system, points, segments) -> float:
    """Cord diameter (m): the system's own ``cord_radius`` if it has one, else a fraction of
    the median segment length so thin cords stay visible at any scale."""
    r = getattr(system, "cord_radius", None)
    if r is not None:
        return 2.0 * float(r)
    if len(segments) == 0:
        return 0.005
    lengths = np.linalg.norm(points[segments[:, 0]] - points[segments[:, 1]], axis=1)
    return float(np.clip(0.08 * np.median(lengths), 0.002, 0.02))


def shapes_of(system, frames: dict, kind_counts: dict | None = None) -> list[Shape]:
    """The Shapes of one system (none if it has nothing to draw; a water system gives its
    surface and its spray)."""
    kind_counts = {} if kind_counts is None else kind_counts
    color = _color(system, kind_counts)
    name = system.name
    if "segment_positions" in frames and hasattr(system, "segment_meshes"):
        parts = [(np.asarray(v, float), np.asarray(t, np.int64))
                 for v, t in system.segment_meshes()]
        return [Shape(name, "parts", color, parts=parts)]
    if "heights" in frames and hasattr(system, "surface"):
        verts, tris = system.surface()
        out = [Shape(name, "surface", color, triangles=np.asarray(tris, np.int64),
                     grid_xy=np.asarray(verts, float)[:, :2])]
        if "particles" in frames:
            r = frames.get("particle_radius")
            width = 2 * float(np.nanmax(r)) if r is not None and np.isfinite(r).any() else 0.008
            out.append(Shape(f"{name}-spray", "particles", color, width=width,
                             source=(name, "particles")))
        return out
    shape = _single_shape(system, frames, color)
    return [shape] if shape is not None else []


def _single_shape(system, frames, color) -> Shape | None:
    name = system.name
    if "position" in frames and "orientation" in frames:
        if hasattr(system, "surface"):
            v, t = system.surface(3) if _takes_arg(system.surface) else system.surface()
        elif getattr(system, "semi_axes", None) is not None:  # an ellipsoid (keyframed foot)
            from ..geometry.sphere import icosphere
            v, t = icosphere(3)
            v = v * np.asarray(system.semi_axes, float)
        else:
            return None
        return Shape(name, "body", color, verts=np.asarray(v, float), tris=np.asarray(t))
    if "points" in frames:
        pts = np.asarray(frames["points"][0]) if len(frames["points"]) else np.zeros((0, 3))
        anchors = getattr(system, "a_pos", None)
        anchors = np.asarray(anchors, float) if anchors is not None and len(anchors) else None
        tri = getattr(system, "triangles", None)
        if tri is not None:
            return Shape(name, "surface", color, triangles=np.asarray(tri, np.int64),
                         anchors=anchors)
        if hasattr(system, "segments"):
            seg = np.asarray(system.segments(), np.int64).reshape(-1, 2)
            return Shape(name, "cords", color, segments=seg,
                         width=_cord_width(system, pts, seg), anchors=anchors)
        return Shape(name, "particles", color, width=float(getattr(system, "radius", 0.005)) * 2)
    if getattr(system, "kind", None) == "static" and hasattr(system, "surface"):
        v, t = system.surface()
        return Shape(name, "static", color, verts=np.asarray(v, float), tris=np.asarray(t))
    return None


def _takes_arg(fn) -> bool:
    import inspect
    try:
        return len(inspect.signature(fn).parameters) >= 1
    except (TypeError, ValueError):
        return False


def from_result(result) -> RunData:
    """RunData of a live Result (frames are shared, not copied)."""
    sc = result.scene
    counts: dict = {}
    shapes = []
    for s in sc.systems:
        shapes += shapes_of(s, result.frames.get(s.name, {}), counts)
    frames = _derive(dict(result.frames), shapes)  # the Result's own dict stays untouched
    return RunData(sc.name, sc.coupling, float(sc.fps), float(sc.duration), shapes,
                   frames, sc.primary.name if sc.primary is not None else None)


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
