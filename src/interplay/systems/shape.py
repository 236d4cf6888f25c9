"""Shapes: what a system looks like, for drawing and export, known when it is built.

Each system returns its Shapes from ``shapes()``; the outputs (USD, OBJ, the preview, the web
viewer) draw them with the per-frame data the run recorded, and nothing else. A Shape has one
*form*:
  body       a rigid body: a body-frame mesh moved by per-frame position + orientation
  parts      an articulated figure or rig: one body-frame mesh per named part, moved by
             per-frame segment_positions (k,3) + segment_orientations (k,4)
  surface    a deforming mesh: per-frame points and fixed triangles (a height field's points
             are made from its grid and per-frame heights)
  cords      a network without faces: per-frame points and fixed (s,2) segments
  particles  per-frame points only (NaN rows are absent particles: spray)
  static     a world-space mesh that never moves (the floor, set pieces)
and a *material* (MATERIALS): how its surface reflects light, in the preview and as a
UsdPreviewSurface.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class Material:
    """A surface's look: roughness and metallic (0..1, UsdPreviewSurface's meaning), opacity
    (0..1; below 1 the surface is drawn translucent, after the opaque ones), and glow (0..1):
    light of its own, for small bright things such as spray droplets."""
    roughness: float = 0.7
    metallic: float = 0.0
    opacity: float = 1.0
    glow: float = 0.0


MATERIALS = {
    "matte": Material(),
    "cloth": Material(roughness=0.9),
    "rubber": Material(roughness=0.55),         # a basketball, the balls of the pond
    "skin": Material(roughness=0.6),            # figures
    "metal": Material(roughness=0.35, metallic=1.0),
    "paint": Material(roughness=0.4),           # a backboard, a bicycle frame
    "wood": Material(roughness=0.8),
    "concrete": Material(roughness=0.95),       # a bridge deck, a road
    "ground": Material(roughness=1.0),          # grass, earth, a pond's bed
    "water": Material(roughness=0.05, opacity=0.6),
    "spray": Material(roughness=0.2, opacity=1.0, glow=0.6),
}


@dataclass
class Shape:
    """One system's geometry. Lengths in m; colour linear RGB 0..1.

    verts/tris: body-frame mesh (body) or world mesh (static); triangles: faces over the
    per-frame points (surface); segments: (s,2) point pairs (cords); width: cord or particle
    diameter (m); anchors: (a,3) fixed world points a network hangs from (drawn as hooks);
    parts: [(verts, tris)] per part of a figure or rig, part_names its parts' names and
    part_parents the index of each part's parent (-1: a root), so exports nest them;
    grid_xy: (n,2) column centres of a height field and base: (n,) its bed height under each
    (m): a column is dry where its height is within DRY of the bed; source: (system, frame key)
    a derived shape's points come from (water spray); palette: the family whose default
    colours a shape without its own ``color`` takes ("rigid", "cloth", "static" or "other":
    outputs cycle through each family's colours); point_colors: (n,3) a colour per point of a
    surface (autumn leaves, each its own) and part_colors: (k,3) one per part (a figure's
    clothes), drawn instead of ``color``; material: a key of
    MATERIALS; double_sided: both faces are seen (cloth, leaves).
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
    part_names: tuple | None = None
    part_parents: tuple | None = None
    base: np.ndarray | None = None
    point_colors: np.ndarray | None = None
    part_colors: np.ndarray | None = None
    material: str = "matte"
    double_sided: bool = False

    def __post_init__(self):
        if self.material not in MATERIALS:
            raise ParameterError(f"shape {self.name}: unknown material {self.material!r}; "
                                 f"choose one of {', '.join(MATERIALS)}")
        if self.parts is not None:
            k = len(self.parts)
            if self.part_names is None:
                self.part_names = tuple(f"part_{i:02d}" for i in range(k))
            if self.part_parents is None:
                self.part_parents = (-1,) * k
            if len(self.part_names) != k or len(self.part_parents) != k:
                raise ParameterError(f"shape {self.name}: {k} parts need {k} part names and "
                                     f"parents, got {len(self.part_names)} and "
                                     f"{len(self.part_parents)}")

    @property
    def animated(self) -> bool:
        return self.form != "static"

    @property
    def look(self) -> Material:
        return MATERIALS[self.material]

    def to_json(self) -> dict:
        out = {"name": self.name, "form": self.form, "color": list(self.color),
               "width": self.width, "palette": self.palette, "material": self.material,
               "double_sided": self.double_sided}
        for key in ("verts", "tris", "triangles", "segments", "anchors", "grid_xy", "base",
                    "point_colors", "part_colors"):
            val = getattr(self, key)
            if val is not None:
                out[key] = np.asarray(val).tolist()
        if self.parts is not None:
            out["parts"] = [[np.asarray(v).tolist(), np.asarray(t).tolist()]
                            for v, t in self.parts]
            out["part_names"] = list(self.part_names)
            out["part_parents"] = list(self.part_parents)
        if self.source is not None:
            out["source"] = list(self.source)
        return out

    @staticmethod
    def from_json(d: dict) -> "Shape":
        arrays = {}
        for key, dtype, cols in (("verts", float, 3), ("tris", np.int64, 3),
                                 ("triangles", np.int64, 3), ("segments", np.int64, 2),
                                 ("anchors", float, 3), ("grid_xy", float, 2),
                                 ("point_colors", float, 3), ("part_colors", float, 3)):
            if key in d:
                arrays[key] = np.asarray(d[key], dtype=dtype).reshape(-1, cols)
        if "base" in d:
            arrays["base"] = np.asarray(d["base"], float).reshape(-1)
        if "parts" in d:
            arrays["parts"] = [(np.asarray(v, float).reshape(-1, 3),
                                np.asarray(t, np.int64).reshape(-1, 3)) for v, t in d["parts"]]
            arrays["part_names"] = tuple(d.get("part_names", ())) or None
            arrays["part_parents"] = tuple(d.get("part_parents", ())) or None
        if "source" in d:
            arrays["source"] = tuple(d["source"])
        return Shape(d["name"], d["form"], tuple(d["color"]), width=float(d.get("width", 0.0)),
                     palette=d.get("palette", "other"), material=d.get("material", "matte"),
                     double_sided=bool(d.get("double_sided", False)), **arrays)


#: m: a height-field column whose surface is this close to its bed holds no water (dry)
DRY = 1e-3


# linear RGB of a figure's segments when it has no colour of its own: skin, shirt, trousers,
# shoes (a person reads as one at a glance; one flat colour reads as a mannequin)
CLOTHES = {"head": (0.80, 0.56, 0.42), "hand": (0.80, 0.56, 0.42),
           "forearm": (0.80, 0.56, 0.42), "torso": (0.70, 0.16, 0.12),
           "upper_arm": (0.70, 0.16, 0.12), "pelvis": (0.12, 0.18, 0.34),
           "thigh": (0.12, 0.18, 0.34), "shank": (0.12, 0.18, 0.34),
           "foot": (0.06, 0.06, 0.07), "toes": (0.06, 0.06, 0.07)}


def figure_shape(name: str, plan, color=None) -> Shape:
    """The parts Shape of an articulated figure from its body plan (anthropometry.body_plan):
    one mesh per segment, named after it and nested under its parent; dressed (CLOTHES)
    unless it has a colour of its own."""
    from ..geometry.anthropometry import segment_mesh
    index = {s.name: k for k, s in enumerate(plan)}
    clothes = None
    if color is None:
        clothes = np.array([CLOTHES[s.name.split("_", 1)[-1] if s.name[:2] in ("l_", "r_")
                                    else s.name] for s in plan])
    return Shape(name, "parts", color=color if color is not None else tuple(clothes.mean(0)),
                 parts=[tuple(np.asarray(a) for a in segment_mesh(s.shape)) for s in plan],
                 part_names=tuple(s.name for s in plan),
                 part_parents=tuple(index[s.parent] if s.parent else -1 for s in plan),
                 part_colors=clothes, palette="rigid", material="skin")


def split_color(color):
    """(one colour or None, (n,3) colours per point or None) of a system's ``color``, which is
    one linear RGB colour or one per point of its mesh."""
    if color is not None and np.ndim(color) == 2:
        per_point = np.asarray(color, dtype=float)
        return tuple(per_point.mean(axis=0)), per_point
    return color, None
