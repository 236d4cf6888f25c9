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
from ..geometry.clearance import ClearanceParams, clear_limbs, forward
from ..io.motion_file import BVHError, Motion, check_file, read_bvh
from ..kernels.rigid import quat_mul
from .base import Role, System
from .shape import figure_shape
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
SKIN_COLOR = (0.80, 0.56, 0.42)  # linear RGB
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


TPOSE_JUMP = 5.0  # deg (RMS over the joints): a first frame this far from the second ...
TPOSE_RATIO = 5.0  # ... and this many times the next frame-to-frame changes is no motion
STANCE_SPEED = 0.8  # m/s: a foot whose ankle or toe joint is slower than this ...
STANCE_SINK = 0.3  # m/s: ... whose sole moves up or down slower than this ...
STANCE_RISE = 0.05  # m: ... and is within this of its lowest around then, stands


def tpose_first(motion: Motion) -> bool:
    """Whether frame 0 is a calibration pose (the T-pose the CMU conversions put first) rather
    than motion: its joint rotations jump to frame 1 by more than TPOSE_JUMP degrees (root
    mean square over the rotation channels) and by TPOSE_RATIO times the largest such change
    over the next ten frames. (The clips here: 28, 31 and 16 deg against at most 2.4, 0.05
    and 0.1 for the three with a T-pose; 0.8 against 0.9 for the two without.)"""
    f = motion.frames
    if len(f) < 4:
        return False
    rot = [j.first + c for j in motion.joints for c, ch in enumerate(j.channels)
           if ch.endswith("rotation")]
    change = np.abs(np.diff(f[: min(len(f), 12), rot], axis=0))
    change = np.sqrt(np.mean(np.minimum(change, 360.0 - change) ** 2, axis=1))  # deg
    return bool(change[0] > TPOSE_JUMP and change[0] > TPOSE_RATIO * change[1:].max())


class MocapFigure(System, RigidParts):
    """A figure that plays a retargeted BVH clip. mass (kg) is what the analysis divides
    interaction forces by; units: one of UNITS or None to detect; skip_tpose: drop a first
    frame that is a calibration pose, not motion (``tpose_first``: the CMU clips have one);
    position_offset (m): where the clip is placed; ground: None, a height (m) or a function
    height(x, y) -> z (m) of the terrain: the clip is then lifted or lowered, stance by stance,
    so that each standing foot's sole rests on it (``plant``), easing between stances;
    clearance: None, or the gaps the limbs keep on our body (geometry/clearance.py: the
    abduction added per frame, rad, is kept as ``clearance``)."""

    role = Role.PRESCRIBED
    integrator = "retargeted BVH clip, cubic spline playback"

    def __init__(self, name: str, path, mass: float = 75.0, units: str | None = None,
                 skip_tpose: bool = True, position_offset=(0.0, 0.0, 0.0), ground=None,
                 clearance: ClearanceParams | None = None):
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
        self.skipped_tpose = bool(skip_tpose and tpose_first(motion))
        if self.skipped_tpose:
            motion.frames = motion.frames[1:]
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
        for k, seg in enumerate(self.plan):
            j = idx[seg.name]
            Q = np.eye(3)
            child = _find(motion, NAMES[seg.name][1]) if NAMES[seg.name][1] else -1
            bone = C @ (rest[child] - rest[j]) if child >= 0 else np.zeros(3)
            if np.linalg.norm(bone) > 1e-9:  # some clips have zero-length end bones
                Q = _rotation_between(seg.bone, bone)
            seg_rot[:, k] = rot[:, j] @ Q
        root = pos[:, idx[self.plan[0].name]]
        self.clearance = {}
        if clearance is not None:
            seg_rot, self.clearance = clear_limbs(self.plan, root, seg_rot, motion.frame_time,
                                                  clearance)
        seg_pos = forward(self.plan, root, seg_rot)
        self.plant_offsets = np.zeros(F)
        if ground is not None:
            self.plant_offsets = self.plant(seg_pos, seg_rot, motion.frame_time, ground)
            seg_pos[:, :, 2] += self.plant_offsets[:, None]
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
        self.skin = None
        prims = [segment_primitive(sg.shape) for sg in self.plan]
        self._middle = np.array([pr.middle for pr in prims])  # m, segment frame
        self._view = BodiesView(self, SEGMENTS, self.segment_meshes(), prims,
                                np.full(17, np.inf), movable=False)

    def soles(self, seg_pos, seg_rot) -> np.ndarray:
        """(F, 2) height (m) of the lowest point of the left and the right foot (foot and toes
        segments) in each frame."""
        out = np.empty((len(seg_pos), 2))
        for side, pair in enumerate((("l_foot", "l_toes"), ("r_foot", "r_toes"))):
            low = []
            for name in pair:
                k = SEGMENTS.index(name)
                v = segment_mesh(self.plan[k].shape)[0]
                low.append((seg_pos[:, k, 2, None]
                            + np.einsum("fj,nj->fn", seg_rot[:, k, 2], v)).min(axis=1))
            out[:, side] = np.minimum(*low)
        return out

    @staticmethod
    def stances(seg_pos, sole, dt: float) -> np.ndarray:
        """(F, 2) whether the left and the right foot stand in each frame: its ankle or its
        toe joint (a foot rolls from the one to the other) slower than STANCE_SPEED, its sole
        neither rising nor sinking faster than STANCE_SINK and within STANCE_RISE of its
        lowest over the 0.3 s around."""
        from scipy.ndimage import minimum_filter1d
        out = np.zeros(sole.shape, dtype=bool)
        for side, pair in enumerate((("l_foot", "l_toes"), ("r_foot", "r_toes"))):
            speed = np.min([np.linalg.norm(np.gradient(seg_pos[:, SEGMENTS.index(n)], dt,
                                                       axis=0), axis=1) for n in pair], axis=0)
            near = minimum_filter1d(sole[:, side], size=max(3, int(0.3 / dt)), mode="nearest")
            sink = np.abs(np.gradient(sole[:, side], dt))
            out[:, side] = ((speed < STANCE_SPEED) & (sink < STANCE_SINK)
                            & (sole[:, side] < near + STANCE_RISE))
        return out

    def plant(self, seg_pos, seg_rot, dt: float, ground) -> np.ndarray:
        """(F,) vertical offset (m) per frame that puts the sole of the standing foot on the
        ground in every stance frame (``stances``: a clip's sole drifts by centimetres within
        a stance, from retargeting onto capsule feet and marker slip), the mean of the two
        where both feet stand, and monotone cubic between stances."""
        from scipy.interpolate import PchipInterpolator
        height = ground if callable(ground) else (lambda x, y, g=float(ground): g)
        sole = self.soles(seg_pos, seg_rot)
        stand = self.stances(seg_pos, sole, dt)
        F = len(sole)
        total, count = np.zeros(F), np.zeros(F)
        for side, name in enumerate(("l_foot", "r_foot")):
            k = SEGMENTS.index(name)
            for f in np.flatnonzero(stand[:, side]):
                total[f] += float(height(*seg_pos[f, k, :2])) - float(sole[f, side])
                count[f] += 1
        on = count > 0
        if not on.any():
            return np.zeros(F)
        t, v = np.flatnonzero(on).astype(float), total[on] / count[on]
        if len(t) == 1:
            return np.full(F, v[0])
        return PchipInterpolator(t, v, extrapolate=False)(np.clip(np.arange(F), t[0], t[-1]))

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
        out = {"segment_positions": self.segment_positions().copy(),
               "segment_orientations": self.segment_orientations().copy()}
        if self.skin is not None:
            out["points"] = self.skin.pose(*self.part_poses())
        return out

    def wear_skin(self, surface) -> None:
        """Draw and export the figure as its skinned body surface (geometry.body_surface):
        one deforming mesh, per-frame points, instead of one mesh per segment."""
        self.skin = surface

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

    def pose_at(self, t: float):
        """(positions (17,3), rotations (17,3,3), linear velocities at the centres, angular
        velocities, centres) of the segments at time t (s), leaving the figure where it is:
        what a contact resolved at the end of a step needs of the clip there."""
        keep = self._x, self._v
        try:
            self._sample(t)
            pos, R = self.part_poses()
            lin, ang = self.part_velocities()
            return pos.copy(), R, lin, ang, self.part_centres()
        finally:
            self._x, self._v = keep

    def centre_of_mass(self):
        m = np.array([sg.mass for sg in self.plan])
        return (m[:, None] * self.part_centres()).sum(axis=0) / m.sum()

    def shapes(self):
        if self.skin is not None:
            from .shape import Shape
            return [Shape(self.name, "surface", color=self.color or SKIN_COLOR,
                          triangles=self.skin.triangles, palette="rigid", material="skin")]
        return [figure_shape(self.name, self.plan, self.color)]


def clip_path(name: str) -> Path:
    """A clip in the mocap data folder: $INTERPLAY_MOCAP_DIR if set, else shared/data/mocap
    beside the repository or beside any folder above it (a worktree's repository sits
    deeper); or ``name`` itself when it is a path."""
    import os
    if os.environ.get("INTERPLAY_MOCAP_DIR"):
        return Path(os.environ["INTERPLAY_MOCAP_DIR"]) / name
    repo = Path(__file__).resolve().parents[3]
    for base in (repo, *repo.parents):
        folder = base / "shared" / "data" / "mocap"
        if folder.is_dir():
            return folder / name
    return repo.parent / "shared" / "data" / "mocap" / name


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
