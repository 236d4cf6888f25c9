"""Limb clearance: retargeting a clip so the body's limbs do not pass through each other.

A clip recorded on one person and played on our body (its anthropometric trunk and limbs,
geometry/body_surface.py's solids) can swing a hand through a hip that is wider than the
subject's, or brush one thigh through the other. A skin then crosses itself, and a garment
between the two parts cannot be anywhere. ``clear_limbs`` adds the least abduction that
keeps a gap: at each frame the arm (shoulder to hand) turns out about the trunk's forward
axis until its hand and forearm stand ``arms`` m off the trunk and the thighs, and both legs
turn out about the pelvis's forward axis, half each, until each leg below its upper thigh
stands ``legs`` m off the other. The angles are then widened and smoothed over ``window`` s
(a running maximum, then a running mean of the same width: never less than a frame needs,
and with no jump a garment would feel). The upper arm against the trunk, and the tops of
the thighs, are joined by the skin at the shoulder and the crotch: they are not tested.

Distances are between the segments' solids (signed distances, m), sampled on the moving
part's surface; angles in rad.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import maximum_filter1d, uniform_filter1d

from ..params import param
from .body_surface import solid_distance, solid_gradient, solids

#: the moving chains, the parts of each that are tested, and what they must clear
ARM = {"l": ("l_upper_arm", "l_forearm", "l_hand"), "r": ("r_upper_arm", "r_forearm", "r_hand")}
ARM_TESTED = ("forearm", "hand")
ARM_OBSTACLES = ("pelvis", "torso", "l_thigh", "r_thigh")
LEG = {"l": ("l_thigh", "l_shank", "l_foot", "l_toes"),
       "r": ("r_thigh", "r_shank", "r_foot", "r_toes")}
THIGH_TOP = 0.3  # share of the thigh's length from the hip where the crotch joins the thighs
STEP = np.radians(1.0)  # rad: the resolution of the abduction searched
COARSE = 4  # the search tries every COARSE-th angle before the ones between
SAMPLE = 0.01  # m: spacing of the points sampled on a part's surface


@dataclass(frozen=True)
class ClearanceParams:
    """arms, legs (m): the gap kept between a hand or forearm and the trunk and thighs, and
    between one leg and the other; window (s): the width over which the added abduction is
    widened and smoothed; most (deg): the largest abduction added to a limb."""
    arms: float = param(0.02, "m", ge=0.0, le=0.2)
    legs: float = param(0.01, "m", ge=0.0, le=0.2)
    window: float = param(0.15, "s", ge=0.0, le=2.0)
    most: float = param(40.0, "deg", gt=0.0, le=60.0)


def surface_points(items, spacing: float = SAMPLE) -> np.ndarray:
    """Points (n,3) on the surface of one segment's solids (its frame): a grid on the faces of
    each solid's bounding box projected onto the union's zero set (Newton along the distance's
    gradient), keeping those that land on it."""
    out = []
    for it in items:
        lo, hi = _bounds(it)
        pts = []
        for a in range(3):
            b, c = [d for d in range(3) if d != a]
            u = np.arange(lo[b], hi[b] + spacing, spacing)
            v = np.arange(lo[c], hi[c] + spacing, spacing)
            U, V = np.meshgrid(u, v, indexing="ij")
            for side in (lo[a], hi[a]):
                p = np.empty((U.size, 3))
                p[:, a], p[:, b], p[:, c] = side, U.ravel(), V.ravel()
                pts.append(p)
        p = np.concatenate(pts)
        for _ in range(4):
            g = solid_gradient(p, [it])
            p = p - (solid_distance(p, [it]) / np.maximum((g * g).sum(axis=1), 1e-12))[:, None] * g
        out.append(p[np.abs(solid_distance(p, [it])) < 1e-4])
    p = np.concatenate(out)
    return p[solid_distance(p, items) > -1e-4]


def _bounds(it):
    """(low, high) corners (m) of a solid's bounding box: a cone's ends and radius, a box's or
    an ellipsoid's centre and half sizes."""
    if it[0] == "cone":
        r = max(it[3], it[4])
        return np.minimum(it[1], it[2]) - r, np.maximum(it[1], it[2]) + r
    return it[1] - it[2], it[1] + it[2]


def forward(plan, root_pos, seg_rot) -> np.ndarray:
    """(F,17,3) segment origins (m) from the root's (F,3) and every segment's rotation
    (F,17,3,3) by the plan's joint offsets: each joint where its parent carries it."""
    idx = {s.name: k for k, s in enumerate(plan)}
    pos = np.zeros(seg_rot.shape[:2] + (3,))
    for k, s in enumerate(plan):
        if s.parent is None:
            pos[:, k] = root_pos
        else:
            p = idx[s.parent]
            pos[:, k] = pos[:, p] + seg_rot[:, p] @ s.offset
    return pos


def _turn(axis, angles) -> np.ndarray:
    """(n,3,3) rotations by ``angles`` (n,) rad about unit ``axis`` (3,), or about each of
    ``axis`` (n,3) in turn (Rodrigues)."""
    a = np.asarray(angles, float)
    ax = np.broadcast_to(np.asarray(axis, float), a.shape + (3,))
    K = np.zeros(a.shape + (3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -ax[:, 2], ax[:, 1], -ax[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    a = a[:, None, None]
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


class _Limbs:
    """The plan's solids and the sampled points of the tested parts, for one frame's tests."""

    def __init__(self, plan, spacing: float = SAMPLE):
        self.idx = {s.name: k for k, s in enumerate(plan)}
        self.solids = solids(plan)
        self.points = {}
        tested = LEG["l"] + LEG["r"] + tuple(f"{side}_{n}" for side in "lr" for n in ARM_TESTED)
        for s in plan:
            if s.name not in tested:
                continue
            pts = surface_points(self.solids[self.idx[s.name]], spacing)
            if s.name.endswith("thigh"):  # below the crotch only
                pts = pts[pts @ s.bone >= THIGH_TOP * float(s.bone @ s.bone)]
            self.points[s.name] = pts

    def gap(self, moving, pos, rot, obstacles, turned, still=None) -> np.ndarray:
        """(n,) the least distance (m) from the parts ``moving`` to the solids of
        ``obstacles``, the segments posed at (pos, rot), for each of n candidate turns: the
        moving parts turned by ``turned`` = (pivot (3,), rotations (n,3,3)) and the obstacles
        by ``still`` likewise (None: they stay)."""
        pivot, turns = turned
        best = np.full(len(turns), np.inf)
        for name in moving:
            k = self.idx[name]
            w = self.points[name] @ rot[k].T + pos[k] - pivot  # (m,3) world, from the pivot
            world = np.einsum("nij,mj->nmi", turns, w) + pivot
            if still is not None:  # into the obstacles' frame before their turn
                q, back = still
                world = np.einsum("nji,nmj->nmi", back, world - q) + q
            world = world.reshape(-1, 3)
            for o in obstacles:
                j = self.idx[o]
                local = (world - pos[j]) @ rot[j]
                d = solid_distance(local, self.solids[j])
                best = np.minimum(best, d.reshape(len(turns), -1).min(axis=1))
        return best


def _needed(gap, want, angles) -> float:
    """The least of ``angles`` whose gap(angles) (n,) reaches ``want`` (the largest if none
    does): most frames need none, so the first angle is tried alone; then every COARSE-th,
    then the angles between the last short one and the first that reaches it."""
    if gap(angles[:1])[0] >= want:
        return float(angles[0])
    coarse = np.arange(COARSE, len(angles) + COARSE - 1, COARSE).clip(max=len(angles) - 1)
    ok = np.flatnonzero(gap(angles[coarse]) >= want)
    if not len(ok):
        return float(angles[-1])
    hi = coarse[ok[0]]
    fine = np.arange(hi - COARSE + 1, hi)
    ok = np.flatnonzero(gap(angles[fine]) >= want) if len(fine) else []
    return float(angles[fine[ok[0]]] if len(ok) else angles[hi])


def _widen(angles, frames: int) -> np.ndarray:
    """A running maximum then a running mean, both ``frames`` wide: at every frame the result
    is at least the input there (each mean's window lies inside maxima that saw it)."""
    if frames <= 1:
        return angles
    width = 2 * (frames // 2) + 1
    peak = maximum_filter1d(angles, width, mode="nearest")
    return uniform_filter1d(peak, width, mode="nearest")


def clear_limbs(plan, root_pos, seg_rot, frame_time: float,
                params: ClearanceParams = ClearanceParams()):
    """The clip's segment rotations (F,17,3,3) with the abduction that keeps its limbs apart
    (module docstring), and the angles added (rad) per frame: {"legs": (F,), "l_arm": (F,),
    "r_arm": (F,)} (the legs' is the total, shared half each). Positions follow by
    ``forward`` from ``root_pos`` (F,3)."""
    limbs = _Limbs(plan)
    idx = limbs.idx
    rot = np.array(seg_rot, float)
    angles = np.arange(0.0, np.radians(params.most) + 0.5 * STEP, STEP)
    frames = max(1, int(round(params.window / frame_time)))
    pelvis, torso = idx["pelvis"], idx["torso"]
    added = {}
    # the legs first: the arms clear the thighs where the legs end up
    pos = forward(plan, root_pos, rot)
    need = np.zeros(len(rot))
    for f in range(len(rot)):
        fwd = rot[f, pelvis][:, 0]
        hips = {s: pos[f, idx[f"{s}_thigh"]] for s in "lr"}

        def gap(a):
            out = {"l": _turn(fwd, a / 2), "r": _turn(fwd, -a / 2)}
            return np.minimum(
                limbs.gap(LEG["l"], pos[f], rot[f], LEG["r"], (hips["l"], out["l"]),
                          (hips["r"], out["r"])),
                limbs.gap(LEG["r"], pos[f], rot[f], LEG["l"], (hips["r"], out["r"]),
                          (hips["l"], out["l"])))
        need[f] = _needed(gap, params.legs, angles)
    added["legs"] = _widen(need, frames)
    for side, sign in (("l", 1.0), ("r", -1.0)):
        ks = [idx[n] for n in LEG[side]]
        T = _turn(rot[:, pelvis][:, :, 0], sign * added["legs"] / 2)
        rot[:, ks] = np.einsum("fij,fkjl->fkil", T, rot[:, ks])
    pos = forward(plan, root_pos, rot)
    for side, sign in (("l", 1.0), ("r", -1.0)):
        chain = [idx[n] for n in ARM[side]]
        tested = tuple(f"{side}_{n}" for n in ARM_TESTED)
        need = np.zeros(len(rot))
        for f in range(len(rot)):
            fwd = rot[f, torso][:, 0]
            need[f] = _needed(lambda a: limbs.gap(tested, pos[f], rot[f], ARM_OBSTACLES,
                                                  (pos[f, chain[0]], _turn(fwd, sign * a))),
                              params.arms, angles)
        added[f"{side}_arm"] = _widen(need, frames)
        T = _turn(rot[:, torso][:, :, 0], sign * added[f"{side}_arm"])
        rot[:, chain] = np.einsum("fij,fkjl->fkil", T, rot[:, chain])
        pos = forward(plan, root_pos, rot)
    return rot, added

