"""The human body plan: 17 segments, 30 joint axes, masses and shapes scaled to a person.

Mass fractions are de Leva (1996), adjustments to Zatsiorsky-Seluyanov's segment inertia
parameters (J. Biomech. 29:1223), male: head+neck 6.94 %, trunk 43.46 % (upper + middle
32.29 % -> torso, lower 11.17 % -> pelvis), upper arm 2.71 %, forearm 1.62 %, hand 0.61 %,
thigh 14.16 %, shank 4.33 %, foot 1.37 % (split here 1.10 % foot, 0.27 % toes by their share of
the foot's length). Segment lengths are fractions of standing height (Drillis & Contini 1966,
as tabulated by Winter, *Biomechanics and Motor Control of Human Movement*): ankle height
0.039 H, shank 0.246 H, thigh 0.245 H, shoulder height 0.818 H, upper arm 0.186 H, forearm
0.146 H, hand 0.108 H, foot 0.152 H. Inertias follow from each segment's shape (a capsule, box
or sphere carrying the segment's mass), so they scale as m L^2 like the tabulated radii of
gyration.

Rest pose: standing upright, facing +x, left +y, arms hanging; every segment's frame is
parallel to the world frame at rest, its origin at the joint that connects it to its parent.
Joint angles are positive in the anatomical sense named by the joint (flexion, abduction, ...).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError, require_positive
from ..params import param

SEGMENTS = ("pelvis", "torso", "head", "l_upper_arm", "l_forearm", "l_hand", "r_upper_arm",
            "r_forearm", "r_hand", "l_thigh", "l_shank", "l_foot", "l_toes", "r_thigh",
            "r_shank", "r_foot", "r_toes")

# % of total mass (de Leva 1996, male)
MASS_PERCENT = {"pelvis": 11.17, "torso": 32.29, "head": 6.94, "upper_arm": 2.71,
                "forearm": 1.62, "hand": 0.61, "thigh": 14.16, "shank": 4.33, "foot": 1.10,
                "toes": 0.27}

# fractions of standing height
LENGTHS = {"ankle_height": 0.039, "shank": 0.246, "thigh": 0.245, "hip_half_width": 0.053,
           "hip_to_pelvis": 0.055, "pelvis_to_waist": 0.045, "waist_to_shoulder": 0.188,
           "waist_to_neck": 0.21, "shoulder_half_width": 0.13, "upper_arm": 0.186,
           "forearm": 0.146, "hand": 0.108, "heel": 0.035, "foot": 0.112, "toes": 0.04,
           "foot_half_width": 0.0275, "toe_joint_height": 0.015, "head_radius": 0.065,
           "head_centre": 0.09, "pelvis_half_width": 0.095, "pelvis_half_depth": 0.055,
           "torso_half_width": 0.09, "torso_half_depth": 0.055}

TISSUE_DENSITY = 1050.0  # kg/m^3, sets the capsule radii of the limbs

# (joint suffix, axis in the parent frame for the LEFT side, range in degrees); the right side
# mirrors abduction and rotation axes. Ranges are typical active ranges of motion (AAOS).
_J3 = {
    "neck": (("flex", (0, 1, 0), (-50, 60)), ("bend", (1, 0, 0), (-40, 40)),
             ("twist", (0, 0, 1), (-70, 70))),
    "waist": (("flex", (0, 1, 0), (-30, 90)), ("bend", (1, 0, 0), (-35, 35)),
              ("twist", (0, 0, 1), (-45, 45))),
    "shoulder": (("flex", (0, -1, 0), (-60, 180)), ("abd", (1, 0, 0), (-30, 180)),
                 ("rot", (0, 0, 1), (-90, 90))),
    "hip": (("flex", (0, -1, 0), (-20, 125)), ("abd", (1, 0, 0), (-30, 45)),
            ("rot", (0, 0, 1), (-40, 45))),
    "elbow": (("flex", (0, -1, 0), (0, 150)),),
    "wrist": (("flex", (0, 1, 0), (-80, 70)), ("dev", (1, 0, 0), (-30, 25))),
    "knee": (("flex", (0, 1, 0), (0, 150)),),
    "ankle": (("flex", (0, -1, 0), (-50, 30)),),
    "toe": (("flex", (0, -1, 0), (-40, 70)),),
}


@dataclass(frozen=True)
class BodyParams:
    """A person: total mass (kg) and standing height (m). Optional overrides (m) of the leg
    geometry, used to match a motion-capture subject: thigh, shank, hip_offset (x, y, z of the
    left hip joint from the pelvis origin; the right one mirrors y)."""
    # a child to a heavy adult: MuJoCo's inertias stay well conditioned over this range
    mass: float = param(75.0, "kg", ge=10.0, le=500.0)
    height: float = param(1.75, "m", ge=0.5, le=3.0)
    thigh: float | None = param(None, "m", gt=0.0, le=2.0)
    shank: float | None = param(None, "m", gt=0.0, le=2.0)
    hip_offset: tuple | None = param(None, "m", ge=-1.0, le=1.0, length=3)


@dataclass
class Segment:
    """One rigid segment. offset: its origin (the joint to its parent) in the parent's frame at
    rest (m); joints: (name, axis, (lo, hi) rad); shape: ("capsule", radius, p0, p1) |
    ("box", half sizes, centre) | ("sphere", radius, centre), local m; bone: local vector (m)
    from the origin to the main child joint (the segment's long axis, for retargeting)."""
    name: str
    parent: str | None
    offset: np.ndarray
    mass: float
    joints: list = field(default_factory=list)
    shape: tuple = ()
    bone: np.ndarray = field(default_factory=lambda: np.zeros(3))


def _joints(side: str, group: str) -> list:
    out = []
    for suffix, axis, (lo, hi) in _J3[group]:
        a = np.array(axis, dtype=float)
        if side == "r" and suffix in ("abd", "rot", "bend", "dev"):
            a = -a  # mirror: right abduction moves the limb toward -y
        name = f"{side}_{group}_{suffix}" if side else f"{group}_{suffix}"
        if len(_J3[group]) == 1:
            name = f"{side}_{group}"
        out.append((name, a, (np.radians(lo), np.radians(hi))))
    return out


def _capsule(mass, p0, p1):
    """A capsule of the segment's mass and tissue density between p0 and p1 (its end caps
    included in the volume)."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    length = float(np.linalg.norm(p1 - p0))
    r = np.sqrt(mass / (TISSUE_DENSITY * np.pi * length))
    # keep the cap inside the segment: shorten the far end by the radius
    p1s = p1 - (p1 - p0) / length * min(r, 0.45 * length)
    return ("capsule", r, p0, p1s)


def body_plan(params: BodyParams = BodyParams()) -> list[Segment]:
    """The 17 segments in SEGMENTS order (parents before children)."""
    mass = require_positive("figure", "mass", params.mass, "kg")
    H = require_positive("figure", "height", params.height, "m")
    if not 0.5 <= H <= 3.0:
        raise ParameterError(f"figure: height {H} m is not a human height; use 0.5 to 3 m")
    L = {k: v * H for k, v in LENGTHS.items()}
    for key in ("thigh", "shank"):
        val = getattr(params, key)
        if val is not None:
            L[key] = require_positive("figure", key, val, "m")
    hip = np.array(params.hip_offset if params.hip_offset is not None
                   else (0.0, L["hip_half_width"], -L["hip_to_pelvis"]), dtype=float)
    if hip.shape != (3,) or not np.all(np.isfinite(hip)):
        raise ParameterError(f"figure: hip_offset must be 3 finite numbers (m), got "
                             f"{params.hip_offset!r}")
    M = {k: v / 100.0 * mass for k, v in MASS_PERCENT.items()}
    seg: list[Segment] = []
    z_pelvis = L["ankle_height"] + L["shank"] + L["thigh"] - hip[2]
    seg.append(Segment("pelvis", None, np.array([0.0, 0.0, z_pelvis]), M["pelvis"], [],
                       ("box", np.array([L["pelvis_half_depth"], L["pelvis_half_width"],
                                         0.5 * (L["pelvis_to_waist"] - hip[2])]),
                        np.array([0.0, 0.0, 0.5 * (L["pelvis_to_waist"] + hip[2])])),
                       np.array([0.0, 0.0, L["pelvis_to_waist"]])))
    ht = L["waist_to_neck"]
    seg.append(Segment("torso", "pelvis", np.array([0.0, 0.0, L["pelvis_to_waist"]]),
                       M["torso"], _joints("", "waist"),
                       ("box", np.array([L["torso_half_depth"], L["torso_half_width"], ht / 2]),
                        np.array([0.0, 0.0, ht / 2])), np.array([0.0, 0.0, ht])))
    seg.append(Segment("head", "torso", np.array([0.0, 0.0, ht]), M["head"], _joints("", "neck"),
                       ("sphere", L["head_radius"], np.array([0.0, 0.0, L["head_centre"]])),
                       np.array([0.0, 0.0, L["head_centre"]])))
    for side, s in (("l", 1.0), ("r", -1.0)):
        down = lambda n: np.array([0.0, 0.0, -L[n]])  # noqa: E731 - a bone hanging down
        seg.append(Segment(f"{side}_upper_arm", "torso",
                           np.array([0.0, s * L["shoulder_half_width"], L["waist_to_shoulder"]]),
                           M["upper_arm"], _joints(side, "shoulder"),
                           _capsule(M["upper_arm"], np.zeros(3), down("upper_arm")),
                           down("upper_arm")))
        seg.append(Segment(f"{side}_forearm", f"{side}_upper_arm", down("upper_arm"),
                           M["forearm"], _joints(side, "elbow"),
                           _capsule(M["forearm"], np.zeros(3), down("forearm")), down("forearm")))
        seg.append(Segment(f"{side}_hand", f"{side}_forearm", down("forearm"), M["hand"],
                           _joints(side, "wrist"),
                           _capsule(M["hand"], np.zeros(3), down("hand")), down("hand")))
    for side, s in (("l", 1.0), ("r", -1.0)):
        down = lambda n: np.array([0.0, 0.0, -L[n]])  # noqa: E731
        seg.append(Segment(f"{side}_thigh", "pelvis", hip * np.array([1.0, s, 1.0]), M["thigh"],
                           _joints(side, "hip"), _capsule(M["thigh"], np.zeros(3), down("thigh")),
                           down("thigh")))
        seg.append(Segment(f"{side}_shank", f"{side}_thigh", down("thigh"), M["shank"],
                           _joints(side, "knee"),
                           _capsule(M["shank"], np.zeros(3), down("shank")), down("shank")))
        ha, fl, hw = L["ankle_height"], L["foot"], L["foot_half_width"]
        toe = np.array([fl, 0.0, L["toe_joint_height"] - ha])
        seg.append(Segment(f"{side}_foot", f"{side}_shank", down("shank"), M["foot"],
                           _joints(side, "ankle"),
                           ("box", np.array([0.5 * (fl + L["heel"]), hw, 0.5 * 0.9 * ha]),
                            np.array([0.5 * (fl - L["heel"]), 0.0, -ha + 0.45 * ha])), toe))
        tl = L["toes"]
        th = 0.5 * L["toe_joint_height"]
        seg.append(Segment(f"{side}_toes", f"{side}_foot", toe, M["toes"], _joints(side, "toe"),
                           ("box", np.array([tl / 2, hw, th]), np.array([tl / 2, 0.0, 0.0])),
                           np.array([tl, 0.0, 0.0])))
    return seg


def joint_names(plan: list[Segment]) -> list[str]:
    """The controlled joint axes in model order (30 for the standard plan)."""
    return [j[0] for s in plan for j in s.joints]


def segment_mesh(shape: tuple, resolution: int = 10):
    """A closed triangle surface (vertices (n,3) m in the segment frame, triangles (m,3)) of a
    segment's shape: what renders and what the shape's collision primitive tessellates."""
    kind = shape[0]
    if kind == "box":
        half, c = np.asarray(shape[1]), np.asarray(shape[2])
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
        tris = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                         [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        return c + corners * half, tris
    if kind == "sphere":
        from .sphere import icosphere
        v, t = icosphere(1)
        return np.asarray(shape[2]) + shape[1] * v, t
    r, p0, p1 = shape[1], np.asarray(shape[2]), np.asarray(shape[3])
    axis = (p1 - p0) / np.linalg.norm(p1 - p0)
    u = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)
    n = resolution
    ang = 2 * np.pi * np.arange(n) / n
    ring = np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * w
    # rings from the p0 pole to the p1 pole (latitudes of each cap); poles closed with fans
    lats = np.linspace(0.0, np.pi / 2, 4)[:-1]  # 0 (equator) .. 60 degrees
    rings = [p0 + r * (np.cos(a) * ring - np.sin(a) * axis) for a in lats[::-1]]
    rings += [p1 + r * (np.cos(a) * ring + np.sin(a) * axis) for a in lats]
    verts = np.concatenate(rings + [[p0 - r * axis], [p1 + r * axis]])
    tris = []
    nr = len(rings)
    for k in range(nr - 1):
        for i in range(n):
            a, b = k * n + i, k * n + (i + 1) % n
            tris += [[a, b, b + n], [a, b + n, a + n]]
    south, north = nr * n, nr * n + 1
    for i in range(n):
        tris.append([south, (i + 1) % n, i])
        tris.append([north, (nr - 1) * n + i, (nr - 1) * n + (i + 1) % n])
    return verts, np.array(tris, dtype=np.int64)


def segment_primitive(shape: tuple):
    """The analytic Primitive (geometry/primitive.py) of a segment's shape."""
    from .primitive import Primitive
    kind = shape[0]
    if kind == "box":
        return Primitive("box", axes=tuple(map(float, shape[1])), centre=tuple(map(float, shape[2])))
    if kind == "sphere":
        return Primitive("sphere", radius=float(shape[1]), centre=tuple(map(float, shape[2])))
    return Primitive("capsule", radius=float(shape[1]), a=tuple(map(float, shape[2])),
                     b=tuple(map(float, shape[3])))
