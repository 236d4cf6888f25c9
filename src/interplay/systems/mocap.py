"""Motion-capture figures: a BVH clip retargeted onto the figure's 17 segments and played as a
kinematic primary (SPEC 2.3): it follows the clip and ignores forces (Role.PRESCRIBED).

Retargeting: units and up axis are detected from the skeleton; the clip's joints are matched
to segments by name (CMU cgspeed and bvh11 schemes, and the same names behind a "prefix:");
the figure gets the clip subject's leg geometry (hip offsets, thigh and shank lengths) and
anthropometric proportions elsewhere; each segment takes its joint's world rotation times the
fixed rotation that carries the figure's rest bone onto the clip's rest bone (so T-pose and
arms-down rest poses both work); positions follow by forward kinematics from the clip's root.
Playback is a cubic spline through the frames: positions and velocities are continuous.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..geometry.anthropometry import (SEGMENTS, BodyParams, body_plan, segment_mesh,
                                      segment_primitive)
from ..io.motion_file import BVHError, Motion, check_file, read_bvh
from ..kernels.rigid import quat_mul
from .base import Role, System
from .shape import Shape
from .views import BodiesView, RigidParts

# segment -> (candidate joint names, candidate names of the joint ending its bone)
NAMES = {
    "pelvis": (("Hips", "hip", "Pelvis"), ()),
    "torso": (("Spine1", "Chest2", "Chest", "Spine"), ()),
    "head": (("Head",), ()),
    "l_upper_arm": (("LeftArm", "LeftShoulder"), ("LeftForeArm", "LeftElbow")),
    "l_forearm": (("LeftForeArm", "LeftElbow"), ("LeftHand", "LeftWrist")),
    "l_hand": (("LeftHand", "LeftWrist"), ("LeftFingerBase", "lhand")),
    "l_thigh": (("LeftUpLeg", "LeftHip"), ("LeftLeg", "LeftKnee")),
    "l_shank": (("LeftLeg", "LeftKnee"), ("LeftFoot", "LeftAnkle")),
    "l_foot": (("LeftFoot", "LeftAnkle"), ("LeftToeBase", "LeftToe")),
    "l_toes": (("LeftToeBase", "LeftToe"), ()),
}
for _k in list(NAMES):
    if _k.startswith("l_"):
        j, b = NAMES[_k]
        NAMES["r" + _k[1:]] = (tuple(n.replace("Left", "Right") for n in j),
                               tuple(n.replace("Left", "Right").replace("lhand", "rhand")
                                     for n in b))
UNITS = {"m": 1.0, "cm": 0.01, "mm": 1e-3, "inch": 0.0254, "cmu": 0.0254 / 0.45}
TYPICAL_LEG = 0.85  # m, hip to ankle of an adult: picks the unit that makes the legs human


def _find(motion: Motion, names) -> int:
    short = [j.name.split(":")[-1] for j in motion.joints]
    for n in names:
        if n in short:
            return short.index(n)
    return -1


def _rotation_between(a, b) -> np.ndarray:
    """The smallest rotation matrix taking direction a onto direction b."""
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    v, c = np.cross(a, b), float(np.dot(a, b))
    if c < -1 + 1e-9:  # opposite: half turn about any perpendicular
        p = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        p /= np.linalg.norm(p)
        return 2 * np.outer(p, p) - np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def _quats(R) -> np.ndarray:
    from scipy.spatial.transform import Rotation
    q = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat()  # x, y, z, w
    return np.roll(q, 1, axis=-1).reshape(R.shape[:-2] + (4,))


class MocapFigure(System, RigidParts):
    """A figure that plays a retargeted BVH clip. mass (kg) is what the analysis divides
    interaction forces by; units: one of UNITS or None to detect; skip_tpose: drop a first
    frame whose rotations are all zero (the T-pose the cgspeed conversion adds)."""

    role = Role.PRESCRIBED
    integrator = "retargeted BVH clip, cubic spline playback"

    def __init__(self, name: str, path, mass: float = 75.0, units: str | None = None,
                 skip_tpose: bool = True, position_offset=(0.0, 0.0, 0.0)):
        motion = read_bvh(path)
        super().__init__(name, motion.frame_time)
        if units is not None and units not in UNITS:
            raise ParameterError(f"{name}: unknown units {units!r}; choose one of "
                                 f"{', '.join(UNITS)}")
        idx = {s: _find(motion, NAMES[s][0]) for s in NAMES}
        missing = [s for s, i in idx.items() if i < 0]
        if missing:
            raise BVHError(f"{path}: no joint for segment(s) {', '.join(missing)}; expected one "
                           f"of {', '.join(NAMES[missing[0]][0])} (CMU naming)")
        rest = self._rest_positions(motion)
        C = self._axes(motion, rest, idx)
        legs = [np.linalg.norm(motion.joints[_find(motion, NAMES[s][1])].offset)
                for s in ("l_thigh", "l_shank")]
        scale = UNITS[units] if units else min(
            UNITS.values(), key=lambda u: abs(np.log(sum(legs) * u / TYPICAL_LEG)))
        self.units = units or next(k for k, v in UNITS.items() if v == scale)
        frames = motion.frames
        if skip_tpose and len(frames) > 1:
            rot_cols = [j.first + c for j in motion.joints for c, ch in enumerate(j.channels)
                        if ch.endswith("rotation")]
            if np.all(frames[0, rot_cols] == 0.0):
                motion.frames = frames[1:]
        hip = (rest[idx["l_thigh"]] - rest[idx["pelvis"]]) * scale @ C.T
        H = (legs[0] + legs[1]) * scale / 0.491  # thigh + shank = 0.491 of standing height
        self.body = BodyParams(mass=mass, height=float(np.clip(H, 0.5, 3.0)),
                               thigh=legs[0] * scale, shank=legs[1] * scale,
                               hip_offset=tuple(hip))
        self.plan = body_plan(self.body)
        self._mass = float(sum(s.mass for s in self.plan))
        pos, rot = motion.global_transforms()
        pos = pos * scale @ C.T + np.asarray(position_offset, dtype=float)
        rot = np.einsum("ij,fkjl,ml->fkim", C, rot, C)
        self.joint_positions = pos  # (F, J, 3) m, world, for checks against the clip
        self.joint_index = idx
        F = len(pos)
        seg_rot = np.zeros((F, 17, 3, 3))
        seg_pos = np.zeros((F, 17, 3))
        for k, seg in enumerate(self.plan):
            j = idx[seg.name]
            Q = np.eye(3)
            child = _find(motion, NAMES[seg.name][1]) if NAMES[seg.name][1] else -1
            bone = C @ (rest[child] - rest[j]) if child >= 0 else np.zeros(3)
            if np.linalg.norm(bone) > 1e-9:  # some clips have zero-length end bones
                Q = _rotation_between(seg.bone, bone)
            seg_rot[:, k] = rot[:, j] @ Q
            if seg.parent is None:
                seg_pos[:, k] = pos[:, j]
            else:
                p = SEGMENTS.index(seg.parent)
                seg_pos[:, k] = seg_pos[:, p] + seg_rot[:, p] @ seg.offset
        q = _quats(seg_rot)
        # sign continuity so the spline does not cross the quaternion double cover
        for f in range(1, F):
            flip = np.sum(q[f] * q[f - 1], axis=1) < 0
            q[f, flip] *= -1
        from scipy.interpolate import CubicSpline
        t = np.arange(F) * motion.frame_time
        self.duration = float(t[-1])
        self._spline = CubicSpline(t, np.concatenate([seg_pos.reshape(F, -1),
                                                      q.reshape(F, -1)], axis=1), axis=0)
        self._d_spline = self._spline.derivative()
        self.motion = motion
        self._x = self._spline(0.0)
        self._v = self._d_spline(0.0)
        self.color = None
        prims = [segment_primitive(sg.shape) for sg in self.plan]
        self._middle = np.array([pr.middle for pr in prims])  # m, segment frame
        self._view = BodiesView(self, SEGMENTS, self.segment_meshes(), prims,
                                np.full(17, np.inf), movable=False)

    @staticmethod
    def _rest_positions(motion: Motion) -> np.ndarray:
        rest = np.zeros((len(motion.joints), 3))
        for j, jt in enumerate(motion.joints):
            rest[j] = jt.offset + (rest[jt.parent] if jt.parent >= 0 else 0.0)
        return rest

    @staticmethod
    def _axes(motion, rest, idx) -> np.ndarray:
        """Rows: the file's forward, left and up directions (a proper rotation to +x forward,
        +y left, +z up). Up: the file axis from the feet to the head in the rest pose; left:
        toward the left hip."""
        up_vec = rest[idx["head"]] - rest[idx["l_foot"]]
        a = int(np.argmax(np.abs(up_vec)))
        up = np.eye(3)[a] * np.sign(up_vec[a])
        left_vec = rest[idx["l_thigh"]] - rest[idx["r_thigh"]]
        left_vec = left_vec - up * np.dot(left_vec, up)
        b = int(np.argmax(np.abs(left_vec)))
        left = np.eye(3)[b] * np.sign(left_vec[b])
        return np.array([np.cross(left, up), left, up])

    # --- the System protocol -----------------------------------------------------------------
    @property
    def mass(self) -> float:
        return self._mass

    def add_wrench(self, force, torque=None, point=None, body=0):
        """Forces are ignored: the clip drives the figure."""

    def set_time(self, t: float):
        """Pose the figure as the clip is at time t (s), clamped to the clip."""
        self.time = float(t)
        self._sample(self.time)

    def _sample(self, t):
        t = min(max(t, 0.0), self.duration)
        self._x = self._spline(t)
        self._v = self._d_spline(t) if t < self.duration else np.zeros_like(self._x)

    def step(self, h):
        self._sample(self.time + h)

    def advance(self, h, dt=None):
        self.time += h
        self._sample(self.time)

    def segment_positions(self) -> np.ndarray:
        return self._x[:51].reshape(17, 3)

    def segment_orientations(self) -> np.ndarray:
        q = self._x[51:].reshape(17, 4)
        return q / np.linalg.norm(q, axis=1, keepdims=True)

    def kinetic_energy(self):
        """Translational kinetic energy (J) of the segments, moving with their origins."""
        v = self._v[:51].reshape(17, 3)
        m = np.array([s.mass for s in self.plan])
        return 0.5 * float(np.sum(m[:, None] * v * v))

    def momentum(self):
        m = np.array([s.mass for s in self.plan])
        return (m[:, None] * self._v[:51].reshape(17, 3)).sum(axis=0)

    def lowest_z(self) -> float:
        return float(self.segment_positions()[:, 2].min())

    def generalized_state(self):
        return self._x, self._v

    def set_generalized_state(self, x, xdot):
        self._x = np.array(x, dtype=float)
        self._v = np.array(xdot, dtype=float)

    def frame(self):
        return {"segment_positions": self.segment_positions().copy(),
                "segment_orientations": self.segment_orientations().copy()}

    def segment_meshes(self) -> list:
        return [segment_mesh(s.shape) for s in self.plan]

    # --- the contact view: 17 prescribed parts ------------------------------------------------
    def contact_view(self):
        return self._view

    def part_poses(self):
        from scipy.spatial.transform import Rotation
        q = self.segment_orientations()
        R = Rotation.from_quat(np.roll(q, -1, axis=1)).as_matrix()
        return self.segment_positions(), R

    def part_centres(self):
        """Each segment's middle (its shape's centre): the clip carries no masses."""
        pos, R = self.part_poses()
        return pos + np.einsum("kij,kj->ki", R, self._middle)

    def part_velocities(self, parts=None):
        """The clip's velocities: w = 2 qdot q* (world frame) and the middle's velocity."""
        if parts is not None:
            lin, ang = self.part_velocities()
            return lin[parts], ang[parts]
        q = self.segment_orientations()
        qd = self._v[51:].reshape(17, 4)
        conj = q * np.array([1.0, -1.0, -1.0, -1.0])
        ang = np.array([2.0 * quat_mul(qd[k], conj[k])[1:] for k in range(17)])
        pos, _ = self.part_poses()
        lin = self._v[:51].reshape(17, 3) + np.cross(ang, self.part_centres() - pos)
        return lin, ang

    def centre_of_mass(self):
        m = np.array([sg.mass for sg in self.plan])
        return (m[:, None] * self.part_centres()).sum(axis=0) / m.sum()

    def shapes(self):
        return [Shape(self.name, "parts", color=self.color,
                      parts=[(np.asarray(v, float), np.asarray(t, np.int64))
                             for v, t in self.segment_meshes()])]


def clip_path(name: str) -> Path:
    """A clip in the mocap data folder ($INTERPLAY_MOCAP_DIR, else ../shared/data/mocap next
    to the repository), or ``name`` itself when it is a path."""
    import os
    folder = os.environ.get("INTERPLAY_MOCAP_DIR")
    folder = Path(folder) if folder else Path(__file__).resolve().parents[3] / ".." / "shared"
    return (folder / "data" / "mocap" if not os.environ.get("INTERPLAY_MOCAP_DIR")
            else folder) / name


def check_clip(name: str) -> None:
    """A parameter check: "" (no clip) or a readable BVH clip (a name in the mocap folder or a
    path to a regular file, bounded in size: io.motion_file.check_file). ParameterError
    naming the clips there otherwise, so a mistyped name is not a silent fallback."""
    if not name:
        return
    path = clip_path(name)
    if not path.exists():
        folder = clip_path("")
        have = sorted(p.name for p in folder.glob("*.bvh")) if folder.is_dir() else []
        raise ParameterError(f"no clip {name!r}" + (
            f"; clips in {folder.resolve()}: {', '.join(have)}" if have else
            f" and no mocap folder at {folder.resolve()}") + "; or '' for the keyframed foot")
    try:
        check_file(path)
    except BVHError as e:
        raise ParameterError(str(e)) from None
