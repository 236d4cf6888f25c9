"""A small BVH (Biovision hierarchy) reader with errors that name the line.

(The PyPI readers checked, ``bvh`` 0.3 and ``bvhio`` 1.5, do not report the line of a bad
value; this one does, and it reads each joint's own CHANNELS order.) Conventions: OFFSETs and
translations in file units, rotations in degrees, composed in the listed channel order
(``Zrotation Yrotation Xrotation`` -> R = Rz Ry Rx, column vectors); a child's position is
parent_pos + parent_R OFFSET.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InterplayError

CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


class BVHError(InterplayError, ValueError):
    """A BVH file is malformed; the message names the file and line."""


@dataclass
class Joint:
    name: str
    parent: int  # -1 for the root
    offset: np.ndarray  # file units
    channels: list = field(default_factory=list)
    first: int = 0  # index of its first channel in a motion line
    end_site: np.ndarray | None = None  # offset of its End Site, if any


@dataclass
class Motion:
    """joints in file order; frames (F, channels) as in the file; frame_time (s)."""
    joints: list
    frames: np.ndarray
    frame_time: float
    path: str = ""

    def index(self, name: str) -> int:
        for i, j in enumerate(self.joints):
            if j.name == name:
                return i
        raise KeyError(name)

    def global_transforms(self):
        """World positions (F, J, 3) in file units and rotations (F, J, 3, 3) of every joint."""
        F, J = len(self.frames), len(self.joints)
        pos = np.zeros((F, J, 3))
        rot = np.zeros((F, J, 3, 3))
        for j, jt in enumerate(self.joints):
            local = np.broadcast_to(np.eye(3), (F, 3, 3)).copy()
            trans = np.zeros((F, 3))
            for c, ch in enumerate(jt.channels):
                v = self.frames[:, jt.first + c]
                if ch.endswith("position"):
                    trans[:, "XYZ".index(ch[0])] = v
                else:
                    local = local @ _axis_rotation(ch[0], np.radians(v))
            if jt.parent < 0:
                pos[:, j] = jt.offset + trans
                rot[:, j] = local
            else:
                pr = rot[:, jt.parent]
                pos[:, j] = pos[:, jt.parent] + pr @ jt.offset + np.einsum("fij,fj->fi", pr, trans)
                rot[:, j] = pr @ local
        return pos, rot


def _axis_rotation(axis: str, a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    i = "XYZ".index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    R[..., i, i] = 1.0
    R[..., j, j] = c
    R[..., k, k] = c
    R[..., j, k] = -s
    R[..., k, j] = s
    return R


#: the largest BVH file read (bytes): a 10-minute 120 Hz clip of a 30-joint skeleton is ~40 MB
MAX_BYTES = 64 * 2 ** 20
#: frame counts and frame times a clip may have: at least two frames to interpolate between;
#: from 10,000 down to 1 frame per second
MAX_FRAMES = 1_000_000
FRAME_TIME = (1e-4, 1.0)  # s
MAX_JOINTS = 512


def check_file(path) -> Path:
    """``path`` if it is a regular file no larger than MAX_BYTES; BVHError otherwise (a FIFO,
    a device such as /dev/zero, a folder or a missing file is refused before it is opened)."""
    from .inputs import regular_file
    return regular_file(path, MAX_BYTES, "BVH clip", BVHError)


def read_bvh(path) -> Motion:
    """Read a BVH file; BVHError naming the line for anything malformed. The file must be a
    regular file of at most MAX_BYTES, with 2 to MAX_FRAMES frames, a Frame Time within
    FRAME_TIME, exactly as many motion lines as ``Frames:`` says, and finite numbers."""
    path = check_file(path)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:  # it grew after the check
            raise BVHError(f"{path}: larger than {MAX_BYTES // 2 ** 20} MiB; trim the clip")
        lines = data.decode("utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise BVHError(f"{path}: cannot read BVH file ({e})") from None
    where = lambda n: f"{path}:{n + 1}"  # noqa: E731
    n = 0

    def nxt():
        nonlocal n
        while n < len(lines) and not lines[n].strip():
            n += 1
        if n >= len(lines):
            raise BVHError(f"{path}: file ends inside the HIERARCHY section (truncated?)")
        toks = lines[n].split()
        n += 1
        return toks

    def floats(toks, k, line):
        try:
            vals = [float(t) for t in toks]
        except ValueError:
            bad = next(t for t in toks if not _is_float(t))
            raise BVHError(f"{where(line)}: expected a number, got {bad!r}") from None
        if len(vals) != k:
            raise BVHError(f"{where(line)}: expected {k} numbers, got {len(vals)}")
        bad = [t for t, v in zip(toks, vals) if not np.isfinite(v)]
        if bad:
            raise BVHError(f"{where(line)}: {bad[0]!r} is not a finite number")
        return np.array(vals)

    if nxt() != ["HIERARCHY"]:
        raise BVHError(f"{where(n - 1)}: a BVH file starts with HIERARCHY")
    joints: list[Joint] = []
    stack: list[int] = []
    nchan = 0
    toks = nxt()
    while True:
        kw = toks[0] if toks else ""
        if kw in ("ROOT", "JOINT"):
            if len(toks) < 2:
                raise BVHError(f"{where(n - 1)}: {kw} needs a name")
            if (kw == "ROOT") != (not stack):
                raise BVHError(f"{where(n - 1)}: {kw} {toks[1]} is misplaced")
            jt = Joint(toks[1], stack[-1] if stack else -1, np.zeros(3))
            if nxt() != ["{"]:
                raise BVHError(f"{where(n - 1)}: expected '{{' after {kw} {jt.name}")
            t = nxt()
            if not t or t[0] != "OFFSET":
                raise BVHError(f"{where(n - 1)}: expected OFFSET for joint {jt.name}")
            jt.offset = floats(t[1:], 3, n - 1)
            t = nxt()
            if not t or t[0] != "CHANNELS":
                raise BVHError(f"{where(n - 1)}: expected CHANNELS for joint {jt.name}")
            try:
                k = int(t[1])
            except (IndexError, ValueError):
                raise BVHError(f"{where(n - 1)}: CHANNELS needs a count") from None
            if k != len(t) - 2 or any(c not in CHANNELS for c in t[2:]):
                raise BVHError(f"{where(n - 1)}: CHANNELS says {k} but lists {t[2:]}; each "
                               f"must be one of {', '.join(CHANNELS)}")
            jt.channels, jt.first = t[2:], nchan
            nchan += k
            joints.append(jt)
            if len(joints) > MAX_JOINTS:
                raise BVHError(f"{where(n - 1)}: more than {MAX_JOINTS} joints")
            stack.append(len(joints) - 1)
        elif kw == "End":
            if nxt() != ["{"]:
                raise BVHError(f"{where(n - 1)}: expected '{{' after End Site")
            t = nxt()
            if not t or t[0] != "OFFSET":
                raise BVHError(f"{where(n - 1)}: expected OFFSET in End Site")
            joints[stack[-1]].end_site = floats(t[1:], 3, n - 1)
            if nxt() != ["}"]:
                raise BVHError(f"{where(n - 1)}: expected '}}' closing End Site")
        elif kw == "}":
            if not stack:
                raise BVHError(f"{where(n - 1)}: unbalanced '}}'")
            stack.pop()
            if not stack:
                break
        else:
            raise BVHError(f"{where(n - 1)}: unexpected {' '.join(toks)!r} in HIERARCHY")
        toks = nxt()
    t = nxt()
    if t != ["MOTION"]:
        raise BVHError(f"{where(n - 1)}: expected MOTION after the hierarchy")
    t = nxt()
    if len(t) != 2 or t[0] != "Frames:" or not t[1].isdigit():
        raise BVHError(f"{where(n - 1)}: expected 'Frames: <count>'")
    nframes = int(t[1])
    if not 2 <= nframes <= MAX_FRAMES:
        raise BVHError(f"{where(n - 1)}: Frames: {nframes}; a clip needs 2 to {MAX_FRAMES:,} "
                       "frames")
    t = nxt()
    if len(t) != 3 or t[:2] != ["Frame", "Time:"] or not _is_float(t[2]):
        raise BVHError(f"{where(n - 1)}: expected 'Frame Time: <seconds>'")
    frame_time = float(t[2])
    if not FRAME_TIME[0] <= frame_time <= FRAME_TIME[1]:
        raise BVHError(f"{where(n - 1)}: Frame Time: {t[2]} s must be within {FRAME_TIME[0]:g} "
                       f"to {FRAME_TIME[1]:g} s (10,000 to 1 frames per second)")
    if nchan == 0:
        raise BVHError(f"{path}: the hierarchy has no CHANNELS: there is no motion to read")
    first = n
    body = [i for i in range(first, len(lines)) if lines[i].strip()]
    if len(body) < nframes:
        raise BVHError(f"{path}: Frames: says {nframes} but only {len(body)} motion lines follow "
                       f"(truncated after line {body[-1] + 1 if body else first})")
    if len(body) > nframes:
        raise BVHError(f"{where(body[nframes])}: Frames: says {nframes} but {len(body)} motion "
                       "lines follow; fix the count")
    frames = np.zeros((nframes, nchan))
    for f, i in enumerate(body[:nframes]):
        frames[f] = floats(lines[i].split(), nchan, i)
    return Motion(joints, frames, frame_time, str(path))


def _is_float(t: str) -> bool:
    try:
        float(t)
        return True
    except ValueError:
        return False
