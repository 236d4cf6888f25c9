"""Kite designs as geometry: the sail's mesh and which of its points lie on the frame, the
frame's spars, the bridle's legs and towing points, and where the tail hangs from.

Kite coordinates (m): x along the spine towards the nose, z out of the sail on its windward
face (towards the bridle and the flyer), y = z x x. A design is a plain frozen dataclass;
``geometry(design)`` turns it into a ``KiteGeometry`` (arrays only: the systems are built
from it in ``scenes/kite_parts.py``).

Designs (traditional proportions, e.g. Pelham, *The Penguin Book of Kites*, 1976):
* ``DiamondParams``: the flat two-stick kite: a spine and a cross spar a quarter of the way
  down it, the sail tied along both; a two-leg bridle from the spine; flown with a tail.
* ``RokkakuParams``: the Japanese six-sided kite: a spine and two cross spars near its ends,
  bowed back; a hexagonal sail tied along all three.
* ``StuntParams``: a two-line stunt delta with two bridles, one per flying line.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError, require_positive
from ..params import param


@dataclass(frozen=True)
class SparParams:
    """The frame's spars: radius (m) and density (kg/m^3) of a solid rod (a wooden dowel:
    ~600-700; a carbon rod: ~1600); the frame is a rigid body of their masses."""
    radius: float = param(0.003, "m", gt=0.0, le=0.1)
    density: float = param(650.0, "kg/m^3", gt=0.0, le=20000.0)


@dataclass(frozen=True)
class DiamondParams:
    """The flat diamond (two-stick) kite. length (m) of the spine; span (m) of the cross spar,
    which crosses the spine at cross (fraction of the spine from the nose); the bridle's upper
    and lower legs start on the spine at bridle (fractions from the nose) and meet at the
    towing point, tow (fraction from the nose, projected on the spine) and tow_height (m) in
    front of the sail; dihedral (deg): the cross spar bowed back so that each wingtip is
    this far out of the spine's plane; the tail hangs from the spine's foot."""
    length: float = param(1.0, "m", gt=0.0, le=20.0)
    span: float = param(0.85, "m", gt=0.0, le=20.0)
    cross: float = param(0.25, "-", ge=0.0, le=1.0)
    dihedral: float = param(0.0, "deg", ge=0.0, lt=45.0)
    bridle: tuple = param((0.04, 0.78), "-", ge=0.0, le=1.0, length=2)
    tow: float = param(0.36, "-", ge=0.0, le=1.0)
    tow_height: float = param(0.32, "m", gt=0.0, le=20.0)
    spars: SparParams = SparParams()


@dataclass(frozen=True)
class RokkakuParams:
    """The rokkaku. length (m) of the spine; span (m) of the two cross spars, which cross the
    spine at spars (fractions from the top); dihedral (deg): the cross spars bowed back so
    their tips are this far out of the spine's plane; bridle and tow, tow_height as the
    diamond's."""
    length: float = param(1.2, "m", gt=0.0, le=20.0)
    span: float = param(0.95, "m", gt=0.0, le=20.0)
    spars: tuple = param((0.2, 0.8), "-", ge=0.0, le=1.0, length=2)
    dihedral: float = param(12.0, "deg", ge=0.0, lt=45.0)
    bridle: tuple = param((0.1, 0.85), "-", ge=0.0, le=1.0, length=2)
    tow: float = param(0.42, "-", ge=0.0, le=1.0)
    tow_height: float = param(0.45, "m", gt=0.0, le=20.0)
    rods: SparParams = SparParams(radius=0.003, density=650.0)


@dataclass(frozen=True)
class StuntParams:
    """A two-line stunt delta. span (m) between the wingtips; length (m) of the spine; sweep
    (m): how far back from the nose the wingtips are; dihedral (deg): each wingtip this far
    out of the spine's plane, back (downwind, > 0) or forward towards the flyer (< 0: the sail
    a shallow V open to the wind, which is what steers the stunt kite the way it is pulled in
    the per-triangle aerodynamics: docs/kites.md); spreader (fraction of
    each leading edge from the nose): the upper spreader; lower (fraction of the spine and of
    each leading edge): the lower spreaders' ends. Each side's bridle has three legs meeting
    at that side's towing point (tow: fraction of the spine from the nose, projected;
    tow_side (m) off the spine; tow_height (m) in front of the sail): the upper leg from the
    spine at upper (fraction from the nose), the lower leg from the middle of that side's
    lower spreader and the outer leg from where it meets the leading edge. A pull on one line
    rolls the kite, tilting its force to that side; whether the nose follows to that side is
    the design's (its dihedral and where its mass and centre of pressure lie)."""
    span: float = param(2.2, "m", gt=0.0, le=20.0)
    length: float = param(0.85, "m", gt=0.0, le=20.0)
    sweep: float = param(0.55, "m", gt=0.0, le=20.0)
    dihedral: float = param(8.0, "deg", ge=-45.0, lt=45.0)
    spreader: float = param(0.45, "-", ge=0.0, le=1.0)
    lower: float = param(0.7, "-", ge=0.0, le=1.0)
    bridle: tuple = param((0.12, 0.78, 0.62), "-", ge=0.0, le=1.0, length=3)
    tow: float = param(0.44, "-", ge=0.0, le=1.0)
    tow_side: float = param(0.22, "m", gt=0.0, le=10.0)
    tow_height: float = param(0.6, "m", gt=0.0, le=20.0)
    ballast: float = param(0.0, "kg", ge=0.0, le=100.0)
    spars: SparParams = SparParams(radius=0.003, density=900.0)


@dataclass
class KiteGeometry:
    """A design in kite coordinates (m). sail (n,3) and triangles (m,3): the sail's mesh;
    ties: indices of sail points on the frame; spars: (s, 2, 3) ends of each spar, with
    radius (m) and density (kg/m^3); bridles: per flying line, the (k,3) frame points its
    legs start from and its towing point (3,); tail_root (3,): where the tail hangs from;
    keel: unit vector of the windward normal (z)."""
    sail: np.ndarray
    triangles: np.ndarray
    ties: np.ndarray
    spars: np.ndarray
    spar_radius: float
    spar_density: float
    bridles: list = field(default_factory=list)
    tail_root: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ballast: tuple = ()  # (point (3,), mass kg): weights fixed to the frame


def subdivided(corners, n: int):
    """A mesh of triangles (t,3,3) corner points, each cut into n^2 similar triangles (n cuts
    per edge), with points shared along common edges welded: (vertices (v,3), triangles)."""
    verts, tris, index = [], [], {}

    def vid(p):
        key = tuple(np.round(p, 9))
        if key not in index:
            index[key] = len(verts)
            verts.append(p)
        return index[key]

    for a, b, c in np.asarray(corners, dtype=float):
        grid = {(i, j): vid(a + (b - a) * i / n + (c - a) * j / n)
                for i in range(n + 1) for j in range(n + 1 - i)}
        for i in range(n):
            for j in range(n - i):
                tris.append((grid[i, j], grid[i + 1, j], grid[i, j + 1]))
                if i + j < n - 1:
                    tris.append((grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]))
    return np.array(verts), np.array(tris, dtype=np.int64)


def on_segments(points, segments, tol=1e-7):
    """Indices of points (n,3) lying on any of the segments (s,2,3), within tol (m)."""
    p = np.asarray(points, float)
    hit = np.zeros(len(p), dtype=bool)
    for a, b in np.asarray(segments, float):
        d = b - a
        s = np.clip((p - a) @ d / (d @ d), 0.0, 1.0)
        hit |= np.linalg.norm(p - (a + s[:, None] * d), axis=1) < tol
    return np.flatnonzero(hit)


def _fraction(owner, name, value):
    v = float(value)
    if not 0.0 <= v <= 1.0:
        raise ParameterError(f"{owner}: {name} must be a fraction in [0, 1], got {value!r}")
    return v


def _dihedral(owner, deg, low=0.0):
    if not low <= deg < 45.0:
        raise ParameterError(f"{owner}: dihedral must be in [{low:g}, 45) deg, got {deg!r}")
    return math.radians(deg)


def _bridle(owner, spine_top, spine_foot, starts, tow, height):
    """Bridle legs from points on the spine (fractions from the top) to a towing point at
    fraction tow and height (m) in front of the sail (+z)."""
    top, foot = np.asarray(spine_top, float), np.asarray(spine_foot, float)
    legs = np.array([top + _fraction(owner, "bridle", f) * (foot - top) for f in starts])
    towing = top + _fraction(owner, "tow", tow) * (foot - top)
    towing = towing + np.array([0.0, 0.0, require_positive(owner, "tow_height", height, "m")])
    return legs, towing


def diamond(p: DiamondParams, n: int = 8) -> KiteGeometry:
    """The diamond: four sail triangles around the spars' crossing, tied along both spars."""
    L = require_positive("diamond", "length", p.length, "m")
    S = require_positive("diamond", "span", p.span, "m")
    c = _fraction("diamond", "cross", p.cross)
    g = _dihedral("diamond", p.dihedral)
    nose, foot = np.array([c * L, 0.0, 0.0]), np.array([-(1.0 - c) * L, 0.0, 0.0])
    left = np.array([0.0, S / 2 * math.cos(g), -S / 2 * math.sin(g)])
    right = left * [1.0, -1.0, 1.0]
    o = np.zeros(3)
    v, t = subdivided([(o, nose, left), (o, left, foot), (o, foot, right), (o, right, nose)], n)
    spars = np.array([(nose, foot), (left, o), (o, right)])
    legs, towing = _bridle("diamond", nose, foot, p.bridle, p.tow, p.tow_height)
    return KiteGeometry(v, t, on_segments(v, spars), spars, p.spars.radius, p.spars.density,
                        [(legs, towing)], foot.copy())


def rokkaku(p: RokkakuParams, n: int = 5) -> KiteGeometry:
    """The rokkaku: the hexagon cut into triangles along its spine and cross spars, tied along
    all three."""
    L = require_positive("rokkaku", "length", p.length, "m")
    S = require_positive("rokkaku", "span", p.span, "m")
    g = _dihedral("rokkaku", p.dihedral)
    if len(p.spars) != 2:
        raise ParameterError(f"rokkaku: spars needs 2 fractions, got {p.spars!r}")
    f1, f2 = sorted(_fraction("rokkaku", "spars", f) for f in p.spars)
    top, foot = np.zeros(3), np.array([-L, 0.0, 0.0])
    c1, c2 = f1 * foot, f2 * foot
    tip = np.array([0.0, S / 2 * math.cos(g), -S / 2 * math.sin(g)])
    ul, ll = c1 + tip, c2 + tip
    ur, lr = ul * [1.0, -1.0, 1.0], ll * [1.0, -1.0, 1.0]
    v, t = subdivided([(top, ul, c1), (top, c1, ur), (c1, ul, ll), (c1, ll, c2),
                       (c1, c2, lr), (c1, lr, ur), (c2, ll, foot), (c2, foot, lr)], n)
    spars = np.array([(top, foot), (ul, c1), (c1, ur), (ll, c2), (c2, lr)])
    legs, towing = _bridle("rokkaku", top, foot, p.bridle, p.tow, p.tow_height)
    return KiteGeometry(v, t, on_segments(v, spars), spars, p.rods.radius, p.rods.density,
                        [(legs, towing)], foot.copy())


def stunt(p: StuntParams, n: int = 8) -> KiteGeometry:
    """The stunt delta: a delta's sail and leading edges, an upper spreader and two lower
    spreaders from the spine to the leading edges; two bridles, left (+y) and right, each
    ending at its own towing point where its flying line is tied."""
    S = require_positive("stunt", "span", p.span, "m")
    L = require_positive("stunt", "length", p.length, "m")
    sweep = require_positive("stunt", "sweep", p.sweep, "m")
    g = _dihedral("stunt", p.dihedral, low=-45.0)
    nose, foot = np.zeros(3), np.array([-L, 0.0, 0.0])
    left = np.array([-sweep, S / 2 * math.cos(g), -S / 2 * math.sin(g)])
    right = left * [1.0, -1.0, 1.0]
    v, t = subdivided([(nose, left, foot), (nose, foot, right)], n)
    s = _fraction("stunt", "spreader", p.spreader)
    lo = _fraction("stunt", "lower", p.lower)
    spine_lo = lo * foot
    spars = np.array([(nose, foot), (nose, left), (nose, right), (s * left, s * right),
                      (spine_lo, lo * left), (spine_lo, lo * right)])
    side = require_positive("stunt", "tow_side", p.tow_side, "m")
    tow = _fraction("stunt", "tow", p.tow) * foot + [0.0, 0.0, require_positive(
        "stunt", "tow_height", p.tow_height, "m")]
    if len(p.bridle) != 3:
        raise ParameterError(f"stunt: bridle needs 3 fractions (upper and lower on the spine, "
                             f"outer on the leading edge), got {p.bridle!r}")
    up, low, out = (_fraction("stunt", "bridle", f) for f in p.bridle)
    bridles = []
    for tip, sign in ((left, 1.0), (right, -1.0)):
        legs = np.array([up * foot, low * foot, out * tip])
        bridles.append((legs, tow + [0.0, sign * side, 0.0]))
    ballast = ((foot.copy(), float(p.ballast)),) if p.ballast > 0 else ()
    return KiteGeometry(v, t, on_segments(v, spars[:3]), spars, p.spars.radius,
                        p.spars.density, bridles, foot.copy(), ballast)


# --- the frame as a rigid body: mass, centre of mass, principal axes -------------------------
@dataclass
class FrameInertia:
    """mass (kg), centre (3,) in kite coordinates (m), principal moments (3,) (kg m^2) and
    axes: the rotation (3,3) whose columns are the principal axes in kite coordinates."""
    mass: float
    centre: np.ndarray
    moments: np.ndarray
    axes: np.ndarray


def frame_inertia(spars, radius: float, density: float, ballast=()) -> FrameInertia:
    """Solid round rods: each of mass rho pi r^2 l, inertia m r^2 / 2 about its axis and
    m (3 r^2 + l^2) / 12 across it about its middle, moved to the common centre of mass
    (parallel axes); ballast: (point, mass kg) point masses fixed to the frame."""
    r = require_positive("frame", "spar radius", radius, "m")
    rho = require_positive("frame", "spar density", density, "kg/m^3")
    a, b = np.asarray(spars, float)[:, 0], np.asarray(spars, float)[:, 1]
    ln = np.linalg.norm(b - a, axis=1)
    m = rho * math.pi * r * r * ln
    mid = 0.5 * (a + b)
    pm = np.array([w for _, w in ballast], float)
    pp = np.array([q for q, _ in ballast], float).reshape(-1, 3)
    c = ((m[:, None] * mid).sum(0) + (pm[:, None] * pp).sum(0)) / (m.sum() + pm.sum())
    inertia = np.zeros((3, 3))
    for mk, lk, u, d in zip(m, ln, (b - a) / ln[:, None], mid - c):
        uu = np.outer(u, u)
        inertia += mk * r * r / 2 * uu + mk * (3 * r * r + lk * lk) / 12 * (np.eye(3) - uu)
        inertia += mk * ((d @ d) * np.eye(3) - np.outer(d, d))
    for mk, q in zip(pm, pp - c):
        inertia += mk * ((q @ q) * np.eye(3) - np.outer(q, q))
    moments, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1.0
    return FrameInertia(float(m.sum() + pm.sum()), c, moments, axes)


def spar_mesh(spars, radius: float, frame: FrameInertia, resolution: int = 6):
    """The spars as closed tubes (vertices (v,3) in the frame's principal body frame,
    triangles): what the frame looks like."""
    from .anthropometry import segment_mesh
    verts, tris = [], []
    for a, b in np.asarray(spars, float):
        v, t = segment_mesh(("capsule", radius, (a - frame.centre) @ frame.axes,
                             (b - frame.centre) @ frame.axes), resolution)
        tris.append(t + sum(len(x) for x in verts))
        verts.append(v)
    return np.concatenate(verts), np.concatenate(tris)
