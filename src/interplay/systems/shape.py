"""Shapes: what a system looks like, for drawing and export, known when it is built.

Each system returns its Shapes from ``shapes()``; the outputs (USD, OBJ, the preview, the web
viewer) draw them with the per-frame data the run recorded, and nothing else. A Shape has one
*form*:
  body       a rigid body: a body-frame mesh moved by per-frame position + orientation
  parts      an articulated figure: one body-frame mesh per segment, moved by per-frame
             segment_positions (k,3) + segment_orientations (k,4)
  surface    a deforming mesh: per-frame points and fixed triangles (a height field's points
             are made from its grid and per-frame heights)
  cords      a network without faces: per-frame points and fixed (s,2) segments
  particles  per-frame points only (NaN rows are absent particles: spray)
  static     a world-space mesh that never moves (the floor, set pieces)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Shape:
    """One system's geometry. Lengths in m; colour linear RGB 0..1.

    verts/tris: body-frame mesh (body) or world mesh (static); triangles: faces over the
    per-frame points (surface); segments: (s,2) point pairs (cords); width: cord or particle
    diameter (m); anchors: (a,3) fixed world points a network hangs from (drawn as hooks);
    parts: [(verts, tris)] per segment of a figure; grid_xy: (n,2) column centres of a height
    field; source: (system, frame key) a derived shape's points come from (water spray);
    palette: the family whose default colours a shape without its own ``color`` takes
    ("rigid", "cloth", "static" or "other": outputs cycle through each family's colours).
    """
    name: str
    form: str
    color: tuple | None = None
    verts: np.ndarray | None = None
    tris: np.ndarray | None = None
    triangles: np.ndarray | None = None
    segments: np.ndarray | None = None
    width: float = 0.0
    anchors: np.ndarray | None = None
    parts: list | None = None
    grid_xy: np.ndarray | None = None
    source: tuple | None = None
    palette: str = "other"

    @property
    def animated(self) -> bool:
        return self.form != "static"

    def to_json(self) -> dict:
        out = {"name": self.name, "form": self.form, "color": list(self.color),
               "width": self.width, "palette": self.palette}
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
                     palette=d.get("palette", "other"), **arrays)
