"""Leaves stirred by a passing bicyclist: a few dozen spring-mass leaves lie on the ground;
a rider (a kinematic prop following a path) passes by; its wake, flow primitives riding along
its path, lifts them; they flutter back down under gravity and drag and come to rest on the
ground (penalty contact with friction). One-way: the air does not feel the leaves."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry import shapes
from ..geometry.bicycle import Bicyclist
from ..interactions.aero import AeroParams, Aerodynamics
from ..interactions.ground import GroundContact, GroundParams
from ..outputs.render.camera import TrackingCamera
from ..scene import Scene
from ..systems.path import Path, PathFollower
from ..systems.springmass import SpringNetwork
from ..systems.static import StaticPlane
from ..systems.wind import FlowPrimitive, WindField
from .contract import SceneSpec
from ..params import intervals, param


@dataclass(frozen=True)
class LeafParams:
    """count leaves scattered with random yaw over the ground rectangle area = (x0, x1, y0, y1)
    (m), seeded by seed; length, width (m), each scaled by 1 +- spread; stations, rows: the
    leaf mesh (``shapes.leaf``); density (kg/m^2); stretch, shear, bend (N): stress/strain
    ratios; vein: stiffness factor of the midrib; mass_damping (1/s), stiffness_damping (s);
    dt (s), integrator, cg_tolerance of the leaves' simulation (one network for all)."""
    count: int = param(36, "leaves", ge=1, le=100_000, cost="points")
    area: tuple = param((-1.5, 1.5, -1.0, 1.0), "m", ge=-100.0, le=100.0,
                        check=intervals, doc="x0, x1, y0, y1 of the ground")
    seed: int = param(7, "-", ge=0, le=2 ** 32 - 1)
    length: float = param(0.10, "m", ge=0.005, le=2.0)
    width: float = param(0.05, "m", ge=0.005, le=2.0)
    spread: float = param(0.3, "-", ge=0.0, le=0.9, doc="sizes vary by 1 +- spread")
    # a leaf has about (2 rows + 1) x stations points
    stations: int = param(6, "-", ge=2, le=100, cost="points")
    rows: int = param(2, "-", ge=1, le=50, cost="points")
    density: float = param(0.12, "kg/m^2", ge=1e-4, le=100.0)  # a dry autumn leaf
    stretch: float = param(5.0, "N", ge=1e-6, le=1e9)
    shear: float = param(3.0, "N", ge=1e-6, le=1e9)
    bend: float = param(0.5, "N", ge=1e-6, le=1e9)
    vein: float = param(5.0, "-", ge=1e-3, le=1e4, doc="midrib stiffness factor")
    mass_damping: float = param(0.2, "1/s", ge=0.0, le=1e4)
    stiffness_damping: float = param(1e-4, "s", ge=0.0, le=1.0)
    dt: float = param(1.0 / 240.0, "s", ge=1e-9, le=0.1)
    integrator: str = param("implicit", choices=("explicit", "implicit", "localglobal"))
    cg_tolerance: float = param(1e-5, "-", ge=1e-14, le=0.1)


@dataclass(frozen=True)
class RiderParams:
    """The bicyclist rides along +x at y = 0 from start to end (m), passing x = 0 at
    pass_time (s) at speed (m/s). Its wake rides along in its own frame (x forward, z up): the
    low pressure behind the rider, a sink of `sink` (m^3/s) at (-behind, 0, height) m that
    draws the leaves up after it, and a swirl about a vertical axis there (`swirl`, m^2/s),
    both with core radius `core` (m) and gusting by `gust` (a turbulent wake)."""
    speed: float = param(5.5, "m/s", ge=0.01, le=100.0)
    pass_time: float = param(1.0, "s", ge=-1e4, le=1e4)
    start: float = param(-8.0, "m", ge=-1e4, le=-0.01, doc="x where the ride starts")
    end: float = param(12.0, "m", ge=0.01, le=1e4, doc="x where the ride ends")
    behind: float = param(0.8, "m", ge=-100.0, le=100.0)
    height: float = param(0.7, "m", ge=-100.0, le=100.0)
    sink: float = param(40.0, "m^3/s", ge=-1e4, le=1e4)
    swirl: float = param(3.0, "m^2/s", ge=-1e4, le=1e4)
    core: float = param(0.4, "m", ge=1e-3, le=100.0)
    gust: float = param(0.3, "-", ge=0.0, le=1.0)
    # rider and bicycle: what the logged wake force is divided by
    mass: float = param(85.0, "kg", ge=1e-3, le=1e4)


@dataclass(frozen=True)
class LeavesParams:
    leaves: LeafParams = LeafParams()
    rider: RiderParams = RiderParams()
    aero: AeroParams = AeroParams()
    # the ground's stiffness is per kg of the touching point's mass, but a leaf landing on one
    # corner at ~2 m/s stops its whole 40 points on that one: 3e7 per kg (1e4 damping, about
    # critical for the leaf) keeps the corner within ~1.3 mm of the ground (1e6 let it sink
    # 5 mm; implicit leaves take any stiffness)
    ground: GroundParams = GroundParams(stiffness=3.0e7, damping=1.0e4)


def scatter(p: LeafParams):
    """(vertices, triangles, vein vertices) of p.count leaves lying flat on the ground."""
    rng = np.random.default_rng(p.seed)
    verts, tris, veins, n = [], [], [], 0
    for _ in range(p.count):
        s = 1.0 + p.spread * rng.uniform(-1.0, 1.0)
        x, t, vein = shapes.leaf(p.length * s, p.width * s, p.stations, p.rows)
        yaw = rng.uniform(0.0, 2.0 * np.pi)
        c, si = np.cos(yaw), np.sin(yaw)
        x = (x - [0.5 * p.length * s, 0.0, 0.0]) @ np.array([[c, -si, 0], [si, c, 0], [0, 0, 1]]).T
        x += [rng.uniform(p.area[0], p.area[1]), rng.uniform(p.area[2], p.area[3]), 0.0]
        verts.append(x)
        tris.append(t + n)
        veins.append(vein + n)
        n += len(x)
    return np.concatenate(verts), np.concatenate(tris), np.concatenate(veins)


AUTUMN = ((0.80, 0.28, 0.04), (0.88, 0.55, 0.08), (0.62, 0.16, 0.05), (0.90, 0.72, 0.16),
          (0.55, 0.30, 0.08))  # linear RGB: orange, amber, red-brown, yellow, brown


def autumn(tris, n: int, seed: int) -> np.ndarray:
    """(n,3) a colour per point: each leaf (a connected piece of the mesh) one of AUTUMN."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    t = np.asarray(tris)
    a = coo_matrix((np.ones(2 * len(t)), (np.r_[t[:, 0], t[:, 1]], np.r_[t[:, 1], t[:, 2]])),
                   shape=(n, n))
    _, label = connected_components(a, directed=False)
    pick = np.random.default_rng(seed + 1).integers(0, len(AUTUMN), label.max() + 1)
    return np.asarray(AUTUMN)[pick[label]]


def rider_path(r: RiderParams, duration: float = 0.0) -> Path:
    """Constant speed along +x through x = 0 at pass_time, on to end (m) or, if the run lasts
    longer, as far as the rider gets by then: the rider never stops. Straight lines keep PCHIP
    exact."""
    end = max(r.end, r.speed * (duration - r.pass_time) + 1.0)
    ts = [r.pass_time + r.start / r.speed, r.pass_time, r.pass_time + end / r.speed]
    return Path(ts, [[r.start, 0, 0], [0, 0, 0], [end, 0, 0]], name="rider path")


def wake(r: RiderParams, path: Path) -> WindField:
    """The rider's wake: flow primitives riding along its path. A sink decays as 1/r^2, so
    only leaves the rider passes close to are lifted, and only while it is near."""
    at = (-r.behind, 0.0, r.height)
    common = dict(position=at, core=r.core, gust=r.gust, gust_period=0.4, path=path)
    return WindField("wake", [FlowPrimitive("sink", strength=r.sink, **common),
                              FlowPrimitive("vortex", axis=(0, 0, 1), strength=r.swirl,
                                            phase=1.3, **common)])


def build(coupling: str = "one-way", duration: float = 4.0, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: LeavesParams = LeavesParams()) -> Scene:
    """The scene; integrator and dt (s) override the leaves'. The wake ignores forces: the
    coupling is one-way (the air does not feel the leaves)."""
    lp = params.leaves
    if integrator is not None:
        lp = replace(lp, integrator=integrator)
    if dt is not None:
        lp = replace(lp, dt=dt)
    scene = Scene("leaves", duration=duration, fps=fps)
    path = rider_path(params.rider, duration)
    rider = scene.add(PathFollower("bicyclist", path, Bicyclist(), mass=params.rider.mass,
                                   dt=1.0 / fps))
    air = scene.add(wake(params.rider, path))
    x, t, vein = scatter(lp)
    x[:, 2] = params.ground.thickness  # resting on the contact surface
    area = 0.5 * np.linalg.norm(np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]), axis=1)
    leaves = scene.add(SpringNetwork.from_mesh(
        "leaves", x, t, lp.density * area.sum(), lp.stretch, lp.shear, lp.bend,
        stiffen=(vein, lp.vein), dt=lp.dt, integrator=lp.integrator,
        mass_damping=lp.mass_damping, stiffness_damping=lp.stiffness_damping,
        cg_tolerance=lp.cg_tolerance, strain_limit=0.5))
    leaves.color = autumn(t, len(x), lp.seed)
    # the road the rider rides (the leaves lie on it) and the grass verges beside it, which
    # the leaves never reach (no contact joins them)
    x0, x1 = path.position(path.t0)[0] - 3.0, path.position(path.t1)[0] + 3.0
    ground = scene.add(StaticPlane("road", extent=(x0, x1, -2.5, 2.5), color=(0.09, 0.09, 0.10),
                                   material="concrete"))
    for side in (-1, 1):
        scene.add(StaticPlane(f"verge{'-+'[side > 0]}", height=-0.01, color=(0.24, 0.36, 0.15),
                              extent=(x0, x1, *sorted((side * 2.5, side * 14.0)))))
    scene.connect(Aerodynamics("wake-leaves", air, leaves, params.aero, mode="one-way"))
    scene.connect(GroundContact("ground-leaves", ground, leaves, params.ground, mode="one-way"))
    scene.primary = rider
    scene.main = "wake-leaves"
    return scene


SPEC = SceneSpec(
    "leaves", "a passing bicyclist's wake stirs up leaves that settle again (one-way)", build,
    LeavesParams, couplings=("one-way",), duration=4.0, fps=60.0,
    integrators=("explicit", "implicit", "localglobal"),
    # low over the leaves, panning a little with the rider as he rides through
    camera=TrackingCamera("bicyclist", offset=(0.5, -4.3, 1.5), target_offset=(0.3, 0.4, 0.35),
                          axes=(0.15, 0.0, 0.0), fov_deg=40.0, smooth_s=0.3), key_time=1.25)
