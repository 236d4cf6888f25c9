"""A rider on a bicycle as a rig of rigid parts: the wheels roll, the crank turns with them
through the gear, and the legs follow the pedals (two-link inverse kinematics from hip to
ankle, knees forward). ``Bicyclist.pose(s)`` poses every part for the distance s (m) ridden;
a PathFollower carries the rig along its path.

Frame: x forward, y left, z up, the origin on the ground midway between the wheels' contact
points. Lengths in m.
"""
from __future__ import annotations

import numpy as np

from .setpieces import box, merge, rod


def _roty(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _along(direction) -> np.ndarray:
    """The rotation taking the part's rest axis (-z) onto ``direction``, keeping its y axis
    in the y direction (legs swing in the bicycle's sagittal plane)."""
    z = -np.asarray(direction, float)
    z /= np.linalg.norm(z)
    y = np.array([0.0, 1.0, 0.0]) - z[1] * z
    y /= np.linalg.norm(y)
    return np.stack([np.cross(y, z), y, z], axis=1)


def _wheel(r: float, spokes: int = 8):
    from trimesh import creation
    tyre = creation.annulus(r_min=0.88 * r, r_max=r, height=0.035, sections=32)
    tyre.apply_transform(np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1.0]]))
    parts = [(np.asarray(tyre.vertices, float), np.asarray(tyre.faces, np.int64))]
    for k in range(spokes):
        a = np.pi * k / spokes
        d = 0.9 * r * np.array([np.cos(a), 0.0, np.sin(a)])
        parts.append(rod(-d, d, 0.004, 6))
    parts.append(rod([0, -0.05, 0], [0, 0.05, 0], 0.02, 8))
    return merge(*parts)


class Bicyclist:
    """The rig. wheel_radius, wheelbase (m); crank (m): crank arm length; gear: wheel turns per
    crank turn; thigh, shank (m): the rider's leg. Parts, in order: PART_NAMES; parents: the
    index each part hangs from (-1: the frame, the root); colors: linear RGB per part."""

    PART_NAMES = ("frame", "rider", "head", "rear_wheel", "front_wheel", "crank", "l_thigh",
                  "l_shank", "l_foot", "r_thigh", "r_shank", "r_foot")
    PARENTS = (-1, 0, 1, 0, 0, 0, 1, 6, 7, 1, 9, 10)
    COLORS = ((0.78, 0.10, 0.08), (0.10, 0.45, 0.62), (0.80, 0.56, 0.42), (0.10, 0.10, 0.11),
              (0.10, 0.10, 0.11), (0.70, 0.70, 0.72), (0.12, 0.12, 0.16), (0.12, 0.12, 0.16),
              (0.05, 0.05, 0.06), (0.12, 0.12, 0.16), (0.12, 0.12, 0.16), (0.05, 0.05, 0.06))

    def __init__(self, wheel_radius: float = 0.34, wheelbase: float = 1.05,
                 crank: float = 0.17, gear: float = 2.6, thigh: float = 0.46,
                 shank: float = 0.45):
        r, wb = wheel_radius, wheelbase
        self.r, self.crank, self.gear = r, crank, gear
        self.thigh, self.shank = thigh, shank
        self.rear, self.front = np.array([-wb / 2, 0, r]), np.array([wb / 2, 0, r])
        self.bb = np.array([-0.04, 0.0, 0.29])        # bottom bracket: the crank's axle
        seat, bars = np.array([-0.26, 0.0, 0.93]), np.array([0.40, 0.0, 1.0])
        self.hips = (seat + [0.02, 0.10, 0.07], seat + [0.02, -0.10, 0.07])
        shoulder = np.array([0.14, 0.0, 1.43])
        frame = merge(rod(self.rear, self.bb, 0.015), rod(self.bb, seat, 0.018),
                      rod(seat, bars - [0.08, 0, 0.08], 0.018), rod(self.bb, bars - [0.08, 0, 0.1],
                                                                    0.02),
                      rod(bars - [0.08, 0, 0.08], self.front, 0.016),
                      rod(self.rear, seat - [0.02, 0, 0.06], 0.012),
                      rod(bars + [0, -0.22, 0], bars + [0, 0.22, 0], 0.013),
                      box(seat + [-0.12, -0.07, -0.01], seat + [0.08, 0.07, 0.04]))
        rider = merge(rod(seat + [0.0, 0.0, 0.08], shoulder, 0.14),
                      rod(shoulder + [0, 0.17, 0], bars + [0, 0.2, 0.02], 0.04),
                      rod(shoulder + [0, -0.17, 0], bars + [0, -0.2, 0.02], 0.04),
                      rod(shoulder + [0, -0.19, 0], shoulder + [0, 0.19, 0], 0.06))
        from trimesh import creation
        head = creation.icosphere(subdivisions=2, radius=0.11)
        head.apply_translation(shoulder + [0.07, 0.0, 0.2])
        crank_mesh = merge(rod([0, -0.13, 0], [0, 0.13, 0], 0.012),
                           rod([0, 0.12, 0], [0, 0.12, -crank], 0.012),
                           rod([0, -0.12, 0], [0, -0.12, crank], 0.012),
                           _wheel(0.1, 4))
        leg = lambda length, radius: rod([0, 0, 0], [0, 0, -length], radius)  # noqa: E731
        foot = box([-0.06, -0.045, -0.035], [0.17, 0.045, 0.035])
        wheel = _wheel(r)
        self.parts = [frame, rider, (np.asarray(head.vertices, float),
                                     np.asarray(head.faces, np.int64)),
                      wheel, wheel, crank_mesh, leg(thigh, 0.07), leg(shank, 0.055), foot,
                      leg(thigh, 0.07), leg(shank, 0.055), foot]

    def pedals(self, s: float):
        """The left and right pedal points (m) after s (m) ridden."""
        a = s / (self.r * self.gear)  # crank angle (rad) about +y, like the wheels
        arm = self.crank * np.array([np.sin(a), 0.0, np.cos(a)])
        return (self.bb + [0.0, 0.12, 0.0] - arm, self.bb + [0.0, -0.12, 0.0] + arm)

    def pose(self, s: float):
        """(origins (k,3) m, rotations (k,3,3)) of every part in the bicycle frame after s (m)
        ridden: the wheels turned by s / r, the crank by s / (r gear), the legs on the pedals."""
        k = len(self.parts)
        pos, rot = np.zeros((k, 3)), np.repeat(np.eye(3)[None], k, axis=0)
        wheel = _roty(s / self.r)
        pos[3], rot[3] = self.rear, wheel
        pos[4], rot[4] = self.front, wheel
        pos[5], rot[5] = self.bb, _roty(s / (self.r * self.gear))
        for side, (hip, pedal) in enumerate(zip(self.hips, self.pedals(s))):
            ankle = pedal + [-0.05, 0.0, 0.07]  # the ball of the foot on the pedal
            d = ankle - hip
            dist = float(np.clip(np.linalg.norm(d), 1e-6, 0.999 * (self.thigh + self.shank)))
            u = d / np.linalg.norm(d)
            w = np.cross(u, [0.0, 1.0, 0.0])  # the knees bend forward, in the xz plane
            w -= (w @ u) * u
            w /= np.linalg.norm(w)
            c = (self.thigh ** 2 + dist ** 2 - self.shank ** 2) / (2 * self.thigh * dist)
            alpha = np.arccos(np.clip(c, -1.0, 1.0))
            knee = hip + self.thigh * (np.cos(alpha) * u + np.sin(alpha) * w)
            i = 6 + 3 * side
            pos[i], rot[i] = hip, _along(knee - hip)
            pos[i + 1], rot[i + 1] = knee, _along(ankle - knee)
            pos[i + 2] = ankle
        return pos, rot

    def mesh(self):
        """The whole rig as one mesh (vertices, triangles) at rest (s = 0)."""
        pos, rot = self.pose(0.0)
        return merge(*[(v @ R.T + p, t) for (v, t), p, R in zip(self.parts, pos, rot)])
