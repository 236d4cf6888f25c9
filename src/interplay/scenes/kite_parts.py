"""One kite as the paper builds it (SPEC 4, the kites row): separate simulations, each with the
assumptions that suit it, coupled two-way.

* the **sail**: a spring-mass cloth (implicit, BDF2) with per-triangle drag and lift in the
  wind (``Aerodynamics``), cut a little bigger than its frame so that it billows and ripples;
* the **frame**: the spars as one rigid body (``RigidBody``: mass, centre and principal
  inertia of the rods, ``geometry.kite.frame_inertia``). Wooden or carbon spars bend by
  millimetres under a kite's few newtons, and a rigid body carries the sail's pull and the
  bridle's as forces and torques on six degrees of freedom, where a stiff network would need a
  truss of springs (a chain of springs has no bending stiffness) and steps short enough for
  its stiffest spring;
* the **bridle and flying line**: one network of tension-only cords (implicit), the legs from
  the frame meeting at the towing point and the line running on from it to the flyer's hand,
  with its own weight (sag) and drag (``CordDrag``);
* the **tail**: a string with bows (tension-only, implicit), dragged by the wind at its bows
  and along its string (``CordDrag``).

Attachments (``SegmentAttachment``) tie the sail's points along the spars to the frame, the
bridle's legs to the frame, the tail to the spine's foot and the line's end to the flyer's
hand; each is two-way, the force on the frame equal and opposite to the network's. The
towing point is a knot of the cord network (the legs and the line are one system), not an
attachment: a tie between two networks would be held explicitly over a coupling step on both
sides, and two light cord ends tied stiffly that way swap positions every step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..geometry.kite import KiteGeometry, frame_inertia, spar_mesh
from ..interactions.aero import AeroParams, Aerodynamics, CordDrag, CordDragParams
from ..interactions.attachment import AttachmentParams, SegmentAttachment
from ..interactions.ground import GroundContact, GroundParams
from ..params import param
from ..systems.rigid import RigidBody
from ..systems.springmass import SpringNetwork, Springs
from ..systems.wind import FlowPrimitive, WindField

FLY_ELEVATION = 40.0  # deg: the lowest line elevation at which a kite is said to fly
LANDED = 0.3  # m: a kite whose frame comes this low after its launch has come down
LAUNCH = 2.0  # s: the launch, when a kite may still be low


def came_down(frames) -> float | None:
    """When (s) a kite's frame, from its recorded frames (``t``, ``position``), first came
    below LANDED m after the launch; None if it stayed up."""
    t, z = np.asarray(frames["t"]), np.asarray(frames["position"])[:, 2]
    low = np.flatnonzero((t > LAUNCH) & (z < LANDED))
    return float(t[low[0]]) if len(low) else None


@dataclass(frozen=True)
class KiteWind:
    """The wind over open ground: speed (m/s) at the reference height (m) growing with height
    by the logarithmic profile of roughness length roughness (m; 0.03: short grass, open
    country), from heading (deg from +x, counter-clockwise); gusting by +-gust of it with
    main period gust_period (s); carrying turbulence of rms turbulence (share of speed, per
    component) in eddies of scale (m); seed picks the gusts' phase and the eddies (one wind
    per seed)."""
    speed: float = param(6.0, "m/s", ge=0.0, le=40.0, doc="at the reference height")
    height: float = param(10.0, "m", gt=0.0, le=200.0)
    roughness: float = param(0.03, "m", gt=0.0, le=2.0, doc="roughness length")
    heading: float = param(0.0, "deg", ge=-360.0, le=360.0)
    gust: float = param(0.2, "-", ge=0.0, le=1.0)
    gust_period: float = param(7.0, "s", gt=0.0, le=600.0)
    turbulence: float = param(0.1, "-", ge=0.0, le=1.0, doc="rms per component, share of speed")
    scale: float = param(8.0, "m", gt=0.0, le=1000.0)
    seed: int = param(0, "-", ge=0, le=2 ** 31 - 1)


def kite_wind(w: KiteWind) -> WindField:
    """The boundary-layer wind, gusting, with the turbulence it carries (frozen eddies moving
    with the wind at the reference height's speed)."""
    h = math.radians(w.heading)
    along = (math.cos(h), math.sin(h), 0.0)
    phase = (1.618034 * int(w.seed)) % (2.0 * math.pi)
    prims = [FlowPrimitive("boundary_layer", axis=along, strength=w.speed, core=w.roughness,
                           height=w.height, gust=w.gust, gust_period=w.gust_period,
                           phase=phase)]
    if w.turbulence > 0.0:
        prims.append(FlowPrimitive("turbulence", strength=w.turbulence * w.speed, core=w.scale,
                                   phase=0.5 + int(w.seed),
                                   velocity=tuple(w.speed * np.asarray(along))))
    return WindField("wind", prims)


@dataclass(frozen=True)
class SailParams:
    """density (kg/m^2): coated ripstop nylon ~40-50 g/m^2; stretch, shear, bend (N):
    stress/strain ratios (k = ratio / rest length); slack (-): the sail cut this much longer
    than the frame (it billows); resolution: cuts per edge of each of the design's triangles;
    mass_damping (1/s), stiffness_damping (s); dt (s) of its implicit (backward Euler)
    steps; cg_tolerance (-): the relative residual its linear solve stops at (1e-4 leaves an
    error ten thousand times below the step's own and runs 20% faster, but moves the chaotic
    flights: docs/kites.md's benchmark); ties: the springs holding it along the spars."""
    density: float = param(0.045, "kg/m^2", gt=0.0, le=10.0)
    stretch: float = param(300.0, "N", gt=0.0, le=1e7)
    shear: float = param(80.0, "N", ge=0.0, le=1e7)
    bend: float = param(0.5, "N", ge=0.0, le=1e6)
    slack: float = param(0.01, "-", ge=0.0, lt=0.2)
    resolution: int = param(8, "cuts", ge=1, le=40, cost=("points", 2))
    mass_damping: float = param(0.05, "1/s", ge=0.0, le=100.0)
    stiffness_damping: float = param(2e-4, "s", ge=0.0, le=1.0)
    dt: float = param(1.0 / 240.0, "s", ge=1e-6, le=0.05)
    cg_tolerance: float = param(1e-6, "-", gt=0.0, le=0.1, doc="the solve's relative residual")
    ties: AttachmentParams = AttachmentParams(stiffness=400.0, damping=0.5)


@dataclass(frozen=True)
class LineParams:
    """The flying line: length (m), segments, mass per length (kg/m: braided polyester or
    Dyneema, 0.3-1 g/m), stiffness E A (N; real lines are ~10-50 kN, softer here to keep the
    implicit solve short: 2 kN stretches 0.25% at 5 N), radius (m), stiffness_damping (s),
    dt (s); the bridle legs are the same cord; ties: the legs' ties to the frame and the
    line's to the flyer's hand."""
    length: float = param(25.0, "m", gt=0.0, le=1000.0)
    segments: int = param(25, "segments", ge=2, le=2000, cost="points")
    density: float = param(6e-4, "kg/m", gt=0.0, le=1.0)
    stiffness: float = param(2000.0, "N", gt=0.0, le=1e7, doc="E A")
    radius: float = param(6e-4, "m", gt=0.0, le=0.05)
    stiffness_damping: float = param(1e-3, "s", ge=0.0, le=1.0)
    dt: float = param(1.0 / 240.0, "s", ge=1e-6, le=0.05)
    ties: AttachmentParams = AttachmentParams(stiffness=250.0, damping=0.5)


@dataclass(frozen=True)
class TailParams:
    """A string with bows: length (m), segments, bows (one every ``bow_every`` points from the
    end, 0: a bare string), bow_mass (kg), bow_area (m^2: its frontal area), string density
    (kg/m), radius (m), stiffness E A (N), dt (s); length 0: no tail."""
    length: float = param(4.0, "m", ge=0.0, le=100.0, doc="0: no tail")
    segments: int = param(16, "segments", ge=1, le=2000, cost="points")
    bow_every: int = param(2, "points", ge=0, le=1000, doc="0: a bare string")
    bow_mass: float = param(0.002, "kg", ge=0.0, le=1.0)
    bow_area: float = param(0.012, "m^2", ge=0.0, le=1.0)
    density: float = param(1e-3, "kg/m", gt=0.0, le=1.0)
    radius: float = param(1e-3, "m", gt=0.0, le=0.05)
    stiffness: float = param(500.0, "N", gt=0.0, le=1e7, doc="E A")
    dt: float = param(1.0 / 240.0, "s", ge=1e-6, le=0.05)
    tie: AttachmentParams = AttachmentParams(stiffness=300.0, damping=0.3)


@dataclass(frozen=True)
class KiteParams:
    """The components of one kite besides its design: sail, line, tail, air (the sail's
    drag/lift coefficients and the cords'), ground contact of its networks."""
    sail: SailParams = SailParams()
    line: LineParams = LineParams()
    tail: TailParams = TailParams()
    aero: AeroParams = AeroParams()
    cord_air: CordDragParams = CordDragParams()
    ground: GroundParams = GroundParams()


@dataclass
class Kite:
    """The built components of one kite (systems already added to the scene) and what a
    measurement needs: the frame, the sail, the lines network with the index of each line's
    towing knot and hand end, the tail and its bows, the geometry."""
    name: str
    frame: RigidBody
    sail: SpringNetwork
    lines: SpringNetwork
    tail: SpringNetwork | None
    towing: list
    hands: list
    bows: np.ndarray
    geometry: KiteGeometry
    interactions: list


def _rotation_to_quat(R) -> np.ndarray:
    from scipy.spatial.transform import Rotation
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])


def frame_body(name: str, g: KiteGeometry, position, rotation, dt: float) -> RigidBody:
    """The spars as one rigid body placed so that kite coordinates map to the world by
    ``rotation`` (3,3) about ``position`` (m, the kite origin)."""
    fi = frame_inertia(g.spars, g.spar_radius, g.spar_density, g.ballast)
    body = RigidBody(name, fi.mass, fi.moments, dt,
                     position=np.asarray(position, float) + rotation @ fi.centre,
                     surface=spar_mesh(g.spars, g.spar_radius, fi))
    body.q[:] = _rotation_to_quat(rotation @ fi.axes)
    body.material = "wood"
    body.color = (0.55, 0.38, 0.20)
    body.inertia = fi
    return body


def _local(fi, points):
    """Kite-coordinate points (k,3) in the frame's principal body frame."""
    return (np.asarray(points, float) - fi.centre) @ fi.axes


def sail_network(name, g: KiteGeometry, p: SailParams, position, rotation, color):
    x = np.asarray(position, float) + g.sail @ rotation.T
    area = 0.5 * np.linalg.norm(np.cross(x[g.triangles[:, 1]] - x[g.triangles[:, 0]],
                                         x[g.triangles[:, 2]] - x[g.triangles[:, 0]]),
                                axis=1).sum()
    net = SpringNetwork.from_mesh(name, x, g.triangles, require_positive(
        name, "density", p.density, "kg/m^2") * area, p.stretch, p.shear, p.bend, dt=p.dt,
        integrator="implicit", scheme="theta", mass_damping=p.mass_damping,
        stiffness_damping=p.stiffness_damping, cg_tolerance=p.cg_tolerance)
    if not 0.0 <= p.slack < 0.2:
        raise ParameterError(f"{name}: slack must be in [0, 0.2), got {p.slack!r}")
    net.l0 *= 1.0 + p.slack  # the sail is cut a little bigger than its frame: it billows
    net.color = color
    return net


def line_network(name, bridles, hands, p: LineParams, frame_points):
    """Per flying line: the bridle legs from ``frame_points`` (world, (k,3) m each) to the
    towing knot ``bridles`` (world (3,) each), then the line, straight, to ``hands`` (world (3,)
    each). Returns the network and, per line, (leg start indices, towing knot index, hand end
    index)."""
    L = require_positive(name, "line length", p.length, "m")
    n = int(p.segments)
    if n < 2:
        raise ParameterError(f"{name}: line segments must be >= 2, got {p.segments!r}")
    pts, mass, si, sj, rest, k, index = [], [], [], [], [], [], []
    ea = require_positive(name, "line stiffness", p.stiffness, "N")
    lam = require_positive(name, "line density", p.density, "kg/m")
    for legs, tow, hand in zip(frame_points, bridles, hands):
        base = len(pts)
        legs = np.asarray(legs, float)
        starts = list(range(base, base + len(legs)))
        knot = base + len(legs)
        pts += list(legs) + [np.asarray(tow, float)]
        leg_len = np.linalg.norm(legs - tow, axis=1)
        mass += list(0.5 * lam * leg_len) + [0.5 * lam * leg_len.sum()]
        for s, ll in zip(starts, leg_len):
            si.append(s)
            sj.append(knot)
            rest.append(ll)
            k.append(ea / ll)
        d = np.asarray(hand, float) - tow
        if np.linalg.norm(d) > L * (1 + 1e-9):
            raise ParameterError(f"{name}: the hand is {np.linalg.norm(d):.2f} m from the "
                                 f"towing point, farther than the line's {L} m")
        seg = L / n
        for i in range(1, n + 1):
            pts.append(tow + d * i / n)
            mass.append(lam * seg * (0.5 if i == n else 1.0))
            si.append(len(pts) - 2 if i > 1 else knot)
            sj.append(len(pts) - 1)
            rest.append(seg)
            k.append(ea / seg)
        mass[knot] += 0.5 * lam * seg
        index.append((starts, knot, len(pts) - 1))
    springs = Springs(np.array(si), np.array(sj), np.array(rest), np.array(k),
                      np.ones(len(si), dtype=bool))
    net = SpringNetwork(name, np.array(pts), np.array(mass), springs, dt=p.dt,
                        integrator="implicit", stiffness_damping=p.stiffness_damping,
                        mass_damping=0.02, cord_radius=require_positive(
                            name, "line radius", p.radius, "m"), color=(0.92, 0.92, 0.90),
                        cg_tolerance=1e-6, strain_limit=0.5)
    return net, index


def tail_network(name, root, direction, p: TailParams, color, ground=None, along=(1, 0, 0)):
    """The tail from ``root`` (world, m) along ``direction``: a chain of tension-only string
    segments with a bow every ``bow_every`` points counted from the free end. Where it would
    pass below ``ground`` (a height, m) it lies on it instead, running on ``along``."""
    n = int(p.segments)
    if n < 1:
        raise ParameterError(f"{name}: tail segments must be >= 1, got {p.segments!r}")
    L = require_positive(name, "tail length", p.length, "m")
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    s = np.linspace(0.0, L, n + 1)
    x = np.asarray(root, float) + np.outer(s, d)
    if ground is not None and d[2] < 0.0 and x[-1, 2] < ground + 0.01:
        drop = (x[0, 2] - ground - 0.01) / -d[2]  # length hanging before it reaches the ground
        flat = s > drop
        a = np.asarray(along, float) / np.linalg.norm(along)
        x[flat] = (np.asarray(root, float) + drop * d) + np.outer(s[flat] - drop, a)
    seg = L / n
    m = np.full(n + 1, require_positive(name, "tail density", p.density, "kg/m") * seg)
    m[[0, -1]] *= 0.5
    bows = (np.arange(n, 0, -int(p.bow_every)) if p.bow_every > 0
            else np.zeros(0, np.int64))
    m[bows] += p.bow_mass
    springs = Springs(np.arange(n), np.arange(1, n + 1), np.full(n, seg),
                      np.full(n, require_positive(name, "tail stiffness", p.stiffness, "N")
                              / seg), np.ones(n, dtype=bool))
    net = SpringNetwork(name, x, m, springs, dt=p.dt, integrator="implicit",
                        mass_damping=0.02, stiffness_damping=1e-3, cord_radius=p.radius,
                        color=color, cg_tolerance=1e-6, strain_limit=0.5)
    return net, bows


def build_kite(scene, name: str, g: KiteGeometry, p: KiteParams, wind, ground, position,
               rotation, hands, holder=None, color=(0.85, 0.10, 0.10),
               tail_color=(0.95, 0.80, 0.10), mode="two-way") -> Kite:
    """Add one kite's systems to ``scene`` and couple them: the kite origin at ``position``
    (m), kite coordinates turned to the world by ``rotation``; each line ends at ``hands``
    (world (3,) m per line) where ``holder`` holds it: None (staked: the end point fixed) or
    (system, [part name per line]) seen as rigid parts (a flyer's hands)."""
    rotation = np.asarray(rotation, float)
    position = np.asarray(position, float)
    world = lambda pts: position + np.asarray(pts, float) @ rotation.T  # noqa: E731
    _check_line(name, g, p.line.length, p.tail.length, hands, ground.contact_view().height)
    frame = scene.add(frame_body(f"{name}-frame", g, position, rotation, p.sail.dt))
    fi = frame.inertia
    sail = scene.add(sail_network(f"{name}-sail", g, p.sail, position, rotation, color))
    legs = [world(b[0]) for b in g.bridles]
    tows = [world(b[1]) for b in g.bridles]
    lines, index = line_network(f"{name}-line", tows, hands, p.line, legs)
    if holder is None:
        lines.fixed[[end for _, _, end in index]] = True
    scene.add(lines)
    its = [SegmentAttachment(f"{name}-sail-ties", frame, sail,
                             [(int(i), frame.name) for i in g.ties],
                             _local(fi, g.sail[g.ties]), p.sail.ties, mode, carry=True),
           SegmentAttachment(f"{name}-bridle", frame, lines,
                             [(s, frame.name) for starts, _, _ in index for s in starts],
                             _local(fi, np.concatenate([b[0] for b in g.bridles])),
                             p.line.ties, mode),
           Aerodynamics(f"{name}-air-sail", wind, sail, p.aero),
           CordDrag(f"{name}-air-line", wind, lines, p.cord_air),
           GroundContact(f"{name}-ground-sail", ground, sail, p.ground),
           GroundContact(f"{name}-ground-line", ground, lines, p.ground)]
    if holder is not None:  # one tie per line: each one's force log is that line's pull
        body, parts = holder
        its += [SegmentAttachment(f"{name}-{part}", body, lines, [(end, part)],
                                  params=p.line.ties, mode=mode)
                for (_, _, end), part in zip(index, parts)]
    tail, bows = None, np.zeros(0, np.int64)
    if p.tail.length > 0.0:
        root = world(g.tail_root)
        tail, bows = tail_network(f"{name}-tail", root, -rotation[:, 0], p.tail, tail_color,
                                  ground.contact_view().height)
        scene.add(tail)
        its += [SegmentAttachment(f"{name}-tail-tie", frame, tail, [(0, frame.name)],
                                  _local(fi, g.tail_root[None]), p.tail.tie, mode),
                CordDrag(f"{name}-air-tail", wind, tail,
                         CordDragParams(**{**p.cord_air.__dict__,
                                           "bow_area": p.tail.bow_area}), bows),
                GroundContact(f"{name}-ground-tail", ground, tail, p.ground)]
    for it in its:
        scene.connect(it)
    return Kite(name, frame, sail, lines, tail, [kn for _, kn, _ in index],
                [end for _, _, end in index], bows, g, its)


def _check_line(name, g: KiteGeometry, line: float, tail: float, hands, ground: float):
    """Refuse a line too short to fly on: flown at FLY_ELEVATION, the towing point must be
    high enough for the sail and the tail hanging below it to clear the ground by LANDED m
    (else the tail drags and the kite is down before it flies). The message names the
    shortest line that would do."""
    reach = max(float(np.linalg.norm(g.sail - g.bridles[0][1], axis=1).max()), 0.0) + tail
    hand = min(float(np.asarray(h, float)[2]) for h in hands) - ground
    rise = math.sin(math.radians(FLY_ELEVATION))
    if hand + line * rise >= reach + LANDED:
        return
    raise ParameterError(
        f"kite {name}: a {line} m line holds it at most {hand + line * rise:.1f} m up at "
        f"{FLY_ELEVATION:.0f} deg, less than the {reach:.1f} m of sail and tail below its "
        f"towing point: the tail would drag on the ground; use a line of at least "
        f"{(reach + LANDED - hand) / rise:.1f} m")


def launch_pose(hand, length: float, elevation_deg: float, tow_kite, pitch_deg: float = 0.0,
                heading=(1.0, 0.0, 0.0)):
    """Where a kite starts: its towing point ``length`` (m) from ``hand`` (m) at
    ``elevation_deg`` up from the ground, downwind along ``heading``; the kite standing nose
    up, its windward face towards the hand, leaning back by ``pitch_deg``. tow_kite: the
    towing point in kite coordinates. Returns (position, rotation)."""
    e = math.radians(elevation_deg)
    h = np.asarray(heading, float)
    h = h / np.linalg.norm(h)
    side = np.cross([0.0, 0.0, 1.0], h)
    tow = np.asarray(hand, float) + length * (math.cos(e) * h + math.sin(e) * np.array(
        [0.0, 0.0, 1.0]))
    a = math.radians(pitch_deg)
    up = math.cos(a) * np.array([0.0, 0.0, 1.0]) + math.sin(a) * h  # nose
    face = np.cross(side, up)  # the windward normal: towards the hand
    face = -face if face @ h > 0 else face
    R = np.stack([up, np.cross(face, up), face], axis=1)
    return tow - R @ np.asarray(tow_kite, float), R
