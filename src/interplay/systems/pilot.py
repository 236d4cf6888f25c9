"""A kite flyer: a figure standing on the ground holding handles (two for a stunt kite, one
winder in both hands for a single-line kite); its arms follow the handles. Kinematic
(``Role.PRESCRIBED``): it moves as its controller tells it and ignores the lines' pull (a
person stands firm against a kite's few newtons), so the lines tied to its handles are coupled
one-way, in lock step with the kite (the controller watches the kite as the flight goes).

The handles move like a person's hands: each follows its target as a critically damped
second-order system of time constant ``response`` (positions and velocities continuous),
within ``reach`` of its rest position. The arms are posed by two-link inverse kinematics from
the shoulders to the grips (elbows out and down); the rest of the body stands in the
anthropometric rest pose (``geometry.anthropometry``), turned to face ``heading``, leaning back
by ``lean``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..geometry.anthropometry import SEGMENTS, BodyParams, body_plan, segment_mesh
from ..params import param
from .base import Role, System
from .shape import CLOTHES, Shape
from .views import BodiesView, RigidParts

HANDLE_RADIUS = 0.015  # m: a handle's grip
HANDLE_LENGTH = 0.12  # m


@dataclass(frozen=True)
class PilotParams:
    """position (m): between the feet on the ground; heading (deg from +x, counter-clockwise):
    the way it faces (downwind, towards the kite); handles: 2 (stunt: one per hand) or 1 (a
    winder held in both hands); grip (m): the handles' rest position in the body frame (x
    forward, y half the spread between two handles, z height above the ground); reach (m):
    how far a handle may move from rest; response (s): the arms' time constant; lean (deg):
    the body leaning back against the pull; mass (kg) and height (m) of the person; walk (m):
    how far the flyer may step back from ``position`` (a controller asks for it with
    ``stance``: a flyer takes up a line's slack by stepping back), at up to walk_speed
    (m/s)."""
    position: tuple = param((0.0, 0.0, 0.0), "m")
    heading: float = param(0.0, "deg", ge=-360.0, le=360.0)
    handles: int = param(2, "-", ge=1, le=2)
    grip: tuple = param((0.35, 0.22, 1.05), "m", ge=-3.0, le=3.0)
    reach: float = param(0.35, "m", gt=0.0, le=1.0)
    response: float = param(0.08, "s", gt=0.0, le=10.0)
    lean: float = param(6.0, "deg", ge=-45.0, le=45.0)
    mass: float = param(75.0, "kg", ge=10.0, le=500.0)
    height: float = param(1.75, "m", ge=0.5, le=3.0)
    walk: float = param(4.0, "m", ge=0.0, le=50.0)
    walk_speed: float = param(1.5, "m/s", gt=0.0, le=10.0)


def _rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def _aim(rest_dir, new_dir):
    """The smallest rotation taking unit rest_dir onto new_dir."""
    a, b = rest_dir / np.linalg.norm(rest_dir), new_dir / np.linalg.norm(new_dir)
    v, c = np.cross(a, b), float(a @ b)
    if c < -1 + 1e-9:
        return _rotation(np.cross(a, [1.0, 0, 0]) if abs(a[0]) < 0.9 else [0, 1.0, 0], math.pi)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def _quat(R) -> np.ndarray:
    from scipy.spatial.transform import Rotation
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])


def two_link(shoulder, target, upper, lower, pole):
    """The elbow (m) of an arm from ``shoulder`` reaching ``target`` with segments of length
    upper and lower (m), bending towards ``pole`` (a direction); a target out of reach is
    reached for in a straight arm."""
    d = target - shoulder
    dist = float(np.linalg.norm(d))
    u = d / dist
    dist = min(dist, upper + lower - 1e-6)
    # law of cosines: the elbow's distance along u and off it
    a = (upper * upper - lower * lower + dist * dist) / (2 * dist)
    off = math.sqrt(max(upper * upper - a * a, 0.0))
    side = pole - (pole @ u) * u
    side = side / np.linalg.norm(side)
    return shoulder + a * u + off * side


class Pilot(System, RigidParts):
    """The flyer. controller: an object with ``targets(pilot, t) -> (k,3)`` world handle
    targets (m) (``control.kite_pilot``), ``capture()`` and ``restore()``, or None (the
    handles stay at rest). Parts: the 17 segments, then the handles ("l_handle", "r_handle"
    or "winder"). Handle frames translate only (their rotation is the body's)."""

    role = Role.PRESCRIBED
    integrator = "kinematic: handles follow their targets (critically damped), arms by IK"

    def __init__(self, name: str, params: PilotParams = PilotParams(), controller=None,
                 dt: float = 1.0 / 240.0):
        super().__init__(name, dt)
        if params.handles not in (1, 2):
            raise ParameterError(f"{name}: handles must be 1 (a winder) or 2, got "
                                 f"{params.handles!r}")
        self.params = params
        self.reach = require_positive(name, "reach", params.reach, "m")
        self.response = require_positive(name, "response", params.response, "s")
        self.plan = body_plan(BodyParams(params.mass, params.height))
        self._mass = float(sum(s.mass for s in self.plan))
        h = math.radians(params.heading)
        self.base = np.asarray(params.position, float)
        self.R0 = _rotation((0, 0, 1), h) @ _rotation((0, 1, 0), -math.radians(params.lean))
        self.handle_names = (("l_handle", "r_handle") if params.handles == 2 else ("winder",))
        gx, gy, gz = params.grip
        rows = [(gx, gy, gz), (gx, -gy, gz)] if params.handles == 2 else [(gx, 0.0, gz)]
        self.rest = self.base + np.array(rows) @ _rotation((0, 0, 1), h).T
        self.facing = np.array([math.cos(h), math.sin(h), 0.0])
        self.home = (self.base.copy(), self.rest.copy())  # where it stands before stepping
        self.back = 0.0  # m stepped back from home, along -facing
        self.hx = self.rest.copy()  # handle positions (m) and velocities (m/s)
        self.hv = np.zeros_like(self.hx)
        self.target = self.rest.copy()
        self.controller = controller
        self._posed = None  # the handles and stance the pose was made for
        self._pose()
        meshes = [segment_mesh(s.shape) for s in self.plan]
        handle = segment_mesh(("capsule", HANDLE_RADIUS, np.array([0, 0, -HANDLE_LENGTH / 2]),
                               np.array([0, 0, HANDLE_LENGTH / 2])), 8)
        if params.handles == 1:  # a winder: a flat reel across both hands
            handle = segment_mesh(("capsule", 0.04, np.array([0, -0.12, 0]),
                                   np.array([0, 0.12, 0])), 10)
        self._handle_mesh = handle
        names = list(SEGMENTS) + list(self.handle_names)
        self._view = BodiesView(self, names, meshes + [handle] * params.handles,
                                [None] * len(names), np.full(len(names), np.inf),
                                movable=False)
        self.color = None

    # --- the pose ----------------------------------------------------------------------------
    def _pose(self):
        """Segment origins (17,3) and rotations (17,3,3) from the handles: the body in its rest
        pose turned and leaned, the arms reaching the grips; and the parts' poses as the
        contact view reads them. A pose is a function of the handles and the stance alone, so
        a flyer standing still (a single-line kite's: its handle at rest) is posed once, not
        at every step."""
        key = self.hx.tobytes() + self.base.tobytes()
        if key == self._posed:
            return
        self._posed = key
        R0 = self.R0
        pos, rot = np.zeros((17, 3)), np.zeros((17, 3, 3))
        for k, s in enumerate(self.plan):
            if s.parent is None:
                pos[k] = self.base + R0 @ s.offset
                rot[k] = R0
            else:
                p = SEGMENTS.index(s.parent)
                pos[k] = pos[p] + rot[p] @ s.offset
                rot[k] = rot[p]
        up = R0[:, 2]
        for side, sign in (("l", 1.0), ("r", -1.0)):
            ua, fa, hd = (SEGMENTS.index(f"{side}_{n}") for n in ("upper_arm", "forearm", "hand"))
            upper = float(np.linalg.norm(self.plan[fa].offset))
            fore = float(np.linalg.norm(self.plan[hd].offset))
            palm = 0.5 * float(np.linalg.norm(self.plan[hd].bone))
            if len(self.hx) == 2:
                grip = self.hx[0 if side == "l" else 1]
            else:  # both hands on the winder, either side of its middle
                grip = self.hx[0] + sign * 0.10 * R0[:, 1]
            pole = sign * R0[:, 1] - up  # elbows out and down
            elbow = two_link(pos[ua], grip, upper, fore + palm, pole)
            rot[ua] = _aim(np.array([0, 0, -1.0]), elbow - pos[ua]) @ R0
            pos[fa] = elbow
            rot[fa] = _aim(np.array([0, 0, -1.0]), grip - elbow) @ R0
            pos[hd] = elbow + rot[fa] @ self.plan[hd].offset
            rot[hd] = rot[fa]
        self.seg_pos, self.seg_rot = pos, rot
        k = len(self.hx)
        self._poses = (np.concatenate([pos, self.hx]),
                       np.concatenate([rot, np.broadcast_to(R0, (k, 3, 3))]))
        self._quats = None  # the frame's orientations, made when a frame is first asked for
        m = np.array([s.mass for s in self.plan])
        self._com = (m[:, None] * pos).sum(axis=0) / m.sum()

    # --- dynamics ------------------------------------------------------------------------------
    @property
    def mass(self) -> float:
        return self._mass

    def step(self, h):
        """Ask the controller for the handles' targets (kept within reach), move the handles
        towards them by the exact step of x'' = w^2 (target - x) - 2 w x' (w = 1 / response)
        for a target held over the step, and pose the arms."""
        if self.controller is not None and hasattr(self.controller, "stance"):
            want = min(max(float(self.controller.stance(self, self.time)), 0.0),
                       self.params.walk)
            move = self.params.walk_speed * h
            self._stand(self.back + min(max(want - self.back, -move), move))
        if self.controller is not None:
            tgt = np.asarray(self.controller.targets(self, self.time), float)
            off = tgt - self.rest
            n = np.linalg.norm(off, axis=1, keepdims=True)
            self.target = self.rest + off * np.minimum(1.0, self.reach / np.maximum(n, 1e-12))
        w = 1.0 / self.response
        e, ev = self.hx - self.target, self.hv
        decay = math.exp(-w * h)
        # critically damped: e(t) = (A + B t) exp(-w t), A = e0, B = ev0 + w e0
        B = ev + w * e
        self.hx[:] = self.target + (e + B * h) * decay
        self.hv[:] = (B - w * (e + B * h)) * decay
        self.time += h
        self._pose()

    def advance(self, h, dt=None):
        n = max(1, int(math.ceil(h / (self.dt if dt is None else dt) - 1e-9)))
        t0 = self.time
        for _ in range(n):
            self.step(h / n)
        self.time = t0 + h

    def _stand(self, back: float):
        """Stand ``back`` m behind home (the feet, the body and the handles' rest with them)."""
        self.back = float(back)
        self.base = self.home[0] - self.back * self.facing
        self.rest = self.home[1] - self.back * self.facing

    def handle_positions(self) -> np.ndarray:
        """(k,3) m: where the handles are."""
        return self.hx.copy()

    # --- the contact view: 17 segments and the handles, prescribed ------------------------------
    def contact_view(self):
        return self._view

    def part_poses(self):
        return self._poses  # made by _pose; callers read it, as they read a body's live state

    def part_centres(self):
        return self.part_poses()[0]

    def part_velocities(self, parts=None):
        """The handles' velocities; the body's segments are reported still (only the arms
        move, slowly, and nothing collides with them)."""
        lin = np.concatenate([np.zeros((17, 3)), self.hv])
        rows = slice(None) if parts is None else np.asarray(parts)
        return lin[rows], np.zeros_like(lin[rows])

    def centre_of_mass(self):
        return self._com

    def shapes(self):
        parts = [tuple(np.asarray(a) for a in segment_mesh(s.shape)) for s in self.plan]
        parts += [self._handle_mesh] * len(self.hx)
        index = {s.name: k for k, s in enumerate(self.plan)}
        parents = [index[s.parent] if s.parent else -1 for s in self.plan]
        parents += ([index["l_hand"], index["r_hand"]] if len(self.hx) == 2
                    else [index["r_hand"]])
        colors = [CLOTHES[s.name.split("_", 1)[-1] if s.name[:2] in ("l_", "r_") else s.name]
                  for s in self.plan] + [(0.10, 0.10, 0.12)] * len(self.hx)
        colors = np.array(colors)
        return [Shape(self.name, "parts", color=tuple(colors.mean(0)), parts=parts,
                      part_names=tuple(SEGMENTS) + self.handle_names,
                      part_parents=tuple(parents), part_colors=colors, palette="rigid",
                      material="skin")]

    def lowest_z(self) -> float:
        return float(self.seg_pos[:, 2].min())

    # --- state ---------------------------------------------------------------------------------
    def generalized_state(self):
        return (np.concatenate([self.hx.ravel(), self.target.ravel(), [self.back]]),
                np.concatenate([self.hv.ravel(), np.zeros(self.target.size + 1)]))

    def set_generalized_state(self, x, xdot):
        k = self.hx.size
        self.hx[:] = np.reshape(x[:k], self.hx.shape)
        self.target[:] = np.reshape(x[k:2 * k], self.target.shape)
        if len(x) > 2 * k:
            self._stand(float(x[2 * k]))
        self.hv[:] = np.reshape(xdot[:k], self.hv.shape)
        self._pose()

    def capture(self):
        snap = {"hx": self.hx.copy(), "hv": self.hv.copy(), "target": self.target.copy(),
                "time": np.array(self.time), "back": np.array(self.back)}
        if self.controller is not None:
            snap.update({f"controller_{k}": v for k, v in self.controller.capture().items()})
        return snap

    def restore(self, snap):
        self.hx[:], self.hv[:], self.target[:] = snap["hx"], snap["hv"], snap["target"]
        self.time = float(snap["time"])
        self._stand(float(snap.get("back", 0.0)))
        if self.controller is not None:
            self.controller.restore({k[len("controller_"):]: v for k, v in snap.items()
                                     if k.startswith("controller_")})
        self._pose()

    def frame(self):
        pos, rot = self.part_poses()
        if self._quats is None:
            self._quats = np.array([_quat(R) for R in rot])
        return {"segment_positions": pos.copy(), "segment_orientations": self._quats.copy()}
