"""A diver entering the water from a 10 m platform (SPEC 4), coupled hybrid as in the paper:
the figure dives under its state machine (control/dive.py: stand at the edge, arm swing and
take-off, a forward dive in pike, open out, hands-first "rip" entry) with a viscous drag
field standing in for the water below the surface, acting on each submerged segment by its
submerged volume with buoyancy; his recorded motion then drives the pool, whose columns his
segments displace, making the splash and spray.

The set: a platform 10 m above the water (FINA: 6 m long, 3 m wide, its front edge 1.5 m past
the pool's wall) on its tower, and a diving pool of the paper's scale (16 m x 16 m, 241 x 241
columns: 58,081 over 256 m^2, as the paper's water) 5 m deep. ``--set dive.entry=flat`` opens
the dive early for a belly-flop; ``--coupling two-way`` runs the figure and the pool in lock
step through the same segment-by-segment interaction, for comparison.

Before anything is simulated the scene flies the dive alone against the stand-in (its first
pass, about a second of wall time) and refuses a dive that misses the pool or a pool too
shallow for it.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from ..control.dive import BOUNDS, DiveParams, diver, fly, nudged_loss
from ..control.search import Search
from ..errors import SceneError
from ..geometry.basin import BasinParams, basin
from ..interactions.buoyancy import BodyInWater, BuoyancyParams
from ..interactions.standins import ViscousDragField, ViscousDragFieldParams
from ..outputs.render.camera import Camera
from ..scene import Scene
from ..systems.colliders import StaticBox
from ..systems.water import SprayParams, Water, WaterParams
from .contract import SceneSpec

LEVEL = 0.0  # m: the still water surface
EDGE = 0.0  # m: x of the platform's front edge (the diver faces +x)
STANCE_X = -0.32  # m: ankle x at rest, the toes 5 cm short of the edge
SURROUND = 4.0  # m: the pool deck drawn around the water
MARGIN = 0.5  # m: the entry must be this far inside the walls; the dive this far above the bed
UNDERWATER = 2.0  # s the check follows the dive under still water
SPLASH_DROPS = 50  # drops in the air for a frame to count in the splash height


@dataclass(frozen=True)
class PlatformParams:
    """height (m) of the platform above the water; length and width (m) of its deck;
    overhang (m): how far its front edge reaches past the pool's wall."""
    height: float = 10.0  # m
    length: float = 6.0  # m
    width: float = 3.0  # m
    overhang: float = 1.5  # m


@dataclass(frozen=True)
class PoolParams:
    """size (m): the pool's side (square; the grid covers it, walls included); cells: columns
    along a side; depth (m): of the water, flat bed."""
    size: float = 16.0  # m
    cells: int = 241
    depth: float = 5.0  # m


@dataclass(frozen=True)
class DiverParams:
    """air_density (kg/m^3): drag on the diver's segments in flight (0: none); coupling_dt:
    the coupling step (s)."""
    dive: DiveParams = DiveParams()
    platform: PlatformParams = PlatformParams()
    pool: PoolParams = PoolParams()
    # drops of 1 cm (a 10 m entry throws drops of a few mm to a few cm), at most 12,000 in
    # the air (50 L); spray where the surface rises faster than 1 m/s
    water: WaterParams = WaterParams(spray=SprayParams(threshold=1.0, radius=0.01,
                                                       capacity=12000))
    buoyancy: BuoyancyParams = BuoyancyParams()
    # the stand-in: still water at the surface, buoyancy and the same form drag as the two-way
    # interaction (``buoyancy``) against it; no extra damping
    field: ViscousDragFieldParams = ViscousDragFieldParams(linear=0.0, quadratic=0.0,
                                                           density=1000.0)
    coupling_dt: float = 2e-3  # s
    air_density: float = 1.2  # kg/m^3


def pool(p: PoolParams, overhang: float, wp: WaterParams) -> Water:
    """The pool: the still surface at LEVEL, its near wall ``overhang`` m behind the
    platform's edge, centred across the platform."""
    geo = basin(BasinParams(size_x=p.size, size_y=p.size, cells=p.cells, depth=p.depth,
                            shore=0.0, shape="rectangle"))
    near = geo.origin[0] + geo.spacing * (np.argmax(geo.fluid.any(axis=1)) - 0.5)
    shift = EDGE - overhang - near
    water = Water("pool", geo.bed + LEVEL - p.depth, geo.fluid, geo.depth, geo.spacing,
                  (geo.origin[0] + shift, geo.origin[1]), wp)
    water.color = (0.25, 0.5, 0.75)
    return water


def footprint(water: Water):
    """(x0, x1, y0, y1) m: the rectangle the fluid columns cover."""
    X, Y = water.column_centres()
    h = 0.5 * water.spacing
    x, y = X[water.fluid], Y[water.fluid]
    return float(x.min() - h), float(x.max() + h), float(y.min() - h), float(y.max() + h)


def set_pieces(platform: PlatformParams, area) -> list:
    """The platform's deck and tower, and the pool's deck around the water (drawn only: the
    diver stands on his own copy of the deck, his model's platform)."""
    top, L, W = LEVEL + platform.height, platform.length, platform.width
    x0, x1, y0, y1 = area
    s = SURROUND
    deck = 0.15  # m: the pool deck's top above the water
    pieces = [StaticBox("platform", (EDGE - L / 2, 0.0, top - 0.25), (L / 2, W / 2, 0.25)),
              StaticBox("tower", (EDGE - L + 0.6, 0.0, 0.5 * (top - 0.5 + deck)),
                        (0.6, W / 2 - 0.2, 0.5 * (top - 0.5 - deck))),
              StaticBox("deck-back", (x0 - s / 2, 0.5 * (y0 + y1), deck - 0.5),
                        (s / 2, 0.5 * (y1 - y0) + s, 0.5)),
              StaticBox("deck-front", (x1 + s / 2, 0.5 * (y0 + y1), deck - 0.5),
                        (s / 2, 0.5 * (y1 - y0) + s, 0.5)),
              StaticBox("deck-left", (0.5 * (x0 + x1), y1 + s / 2, deck - 0.5),
                        (0.5 * (x1 - x0), s / 2, 0.5)),
              StaticBox("deck-right", (0.5 * (x0 + x1), y0 - s / 2, deck - 0.5),
                        (0.5 * (x1 - x0), s / 2, 0.5))]
    for piece in pieces:
        piece.color = (0.82, 0.8, 0.76)
    return pieces


def check(trial, area, depth: float):
    """Refuse a dive that misses the pool or reaches its bed (SceneError naming the numbers
    and the fix); trial: the dive flown against still water (control/dive.py ``fly``)."""
    e = trial.entry
    x0, x1, y0, y1 = area
    if e is None:
        raise SceneError("diver: the dive never reaches the water (it stays on the platform or "
                         "lands back on it); check the dive.* take-off parameters")
    x, y = e.point[0], e.point[1]
    if not (x0 + MARGIN <= x <= x1 - MARGIN and y0 + MARGIN <= y <= y1 - MARGIN):
        raise SceneError(
            f"diver: the dive misses the pool: it enters the water's plane at x={x:.2f} m, "
            f"y={y:.2f} m, and the pool spans x {x0:.2f}..{x1:.2f} m, y {y0:.2f}..{y1:.2f} m "
            f"(entries must be {MARGIN} m inside its walls); move the pool under the dive "
            "(platform.overhang, pool.size) or change the take-off (dive.*)")
    need = LEVEL - trial.deepest + MARGIN
    if depth < need:
        raise SceneError(
            f"diver: the pool is too shallow for this dive: it enters at {e.speed:.1f} m/s and "
            f"reaches {LEVEL - trial.deepest:.2f} m below the surface in still water, but "
            f"pool.depth is {depth:g} m; use pool.depth >= {need:.1f} m")


def deck_of(pf: PlatformParams) -> tuple:
    """The platform's top (x0, x1, y0, y1, z) in m: its front edge at EDGE."""
    return (EDGE - pf.length, EDGE, -pf.width / 2, pf.width / 2, LEVEL + pf.height)


@lru_cache(maxsize=8)
def still_water_trial(dive: DiveParams, pf, air_density: float, field, buoyancy, h: float,
                      duration: float):
    """The dive alone against still water with no floor (the field on, whatever the run
    uses): where it enters, how deep it goes. A pure function of its arguments (frozen
    parameters), remembered for the process: compare's three builds and a sweep's runs of one
    dive fly it once (seconds each)."""
    still = ViscousDragField(replace(field, enabled=True), buoyancy)
    return fly(diver(dive, deck_of(pf), STANCE_X, floor=None, air_density=air_density,
                     level=LEVEL), still, LEVEL, duration=duration, h=h, underwater=UNDERWATER)


def build(coupling: str = "hybrid", duration: float = 5.5, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: DiverParams = DiverParams()) -> Scene:
    """The scene. dt overrides the pool's largest step (s); the pool has one integrator."""
    wp = params.water if dt is None else replace(params.water, dt=dt)
    pf, dive = params.platform, params.dive.validated()
    deck = deck_of(pf)
    water = pool(params.pool, pf.overhang, wp)
    area = footprint(water)

    field = replace(params.field, surface=LEVEL, gravity=wp.gravity)
    trial = still_water_trial(dive, pf, params.air_density, field, params.buoyancy,
                              params.coupling_dt, max(duration, 6.0))
    check(trial, area, params.pool.depth)
    scene = Scene("diver", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    fig = scene.add(diver(dive, deck, STANCE_X, floor=LEVEL - params.pool.depth,
                          air_density=params.air_density, level=LEVEL))
    scene.add(water)
    for piece in set_pieces(pf, area):
        scene.add(piece)
    scene.connect(BodyInWater("diver-water", fig, water, params.buoyancy, mode=coupling,
                              standin=ViscousDragField(field, params.buoyancy)))
    scene.primary = fig
    scene.meta = {"still_level": LEVEL, "platform_height": pf.height, "entry": dive.entry,
                  "predicted": trial.entry.as_dict(), "pool_area_m": list(area)}
    return scene


def dive_figures(result) -> dict:
    """The entry and the splash: entry time, speed (m/s) and angle from vertical (deg) at the
    first coupling step the water (or its stand-in) acts; the centre of mass's speed when the
    lower wrist is 1 m under; splash: the spray volume thrown (m^3), the most in the air at
    once (m^3), its height (m above the surface: the highest 95th percentile of the airborne
    drops' heights over the frames with at least SPLASH_DROPS in the air) and the highest
    drop's."""
    from ..control.dive import WRISTS, body_angles
    fr = result.frames.get("diver")
    log = result.logs.get("diver-water")
    if fr is None or log is None:
        return {}
    log = log.standin if result.coupling == "hybrid" and log.standin is not None else log
    wet = np.flatnonzero(log.active)
    if not len(wet):
        return {}
    t, com, seg = fr["t"], fr["com"], fr["segment_positions"]
    vel = np.gradient(com, t, axis=0)
    t_in = float(log.t[wet[0]])
    at = lambda a: np.array([np.interp(t_in, t, a[:, i]) for i in range(a.shape[1])])  # noqa
    origins = np.stack([at(seg[:, k]) for k in range(seg.shape[1])])
    v_in = at(vel)
    down, along = body_angles(origins, v_in)
    out = {"entry time (s)": t_in, "entry speed (m/s)": float(np.linalg.norm(v_in)),
           "entry angle from vertical (deg)": down,
           "entry angle to the flight path (deg)": along}
    level = result.meta.get("still_level", LEVEL)
    wrist = seg[:, list(WRISTS), 2].min(axis=1)
    deep = np.flatnonzero(wrist < level - 1.0)
    if len(deep) and deep[0] > 0:
        k = deep[0]
        t1 = float(np.interp(level - 1.0, [wrist[k], wrist[k - 1]], [t[k], t[k - 1]]))
        out["speed 1 m under (m/s)"] = float(np.linalg.norm(
            [np.interp(t1, t, vel[:, i]) for i in range(3)]))
    water = result.diagnostics.get("pool", {})
    pool = result.frames.get("pool")
    if "spray_emitted_m3" in water and pool is not None:
        top = water["spray_top_m"]
        z = pool["particles"][:, :, 2]
        count = pool["particle_count"]
        high = [np.nanpercentile(zk, 95) for zk, n in zip(z, count) if n >= SPLASH_DROPS]
        out["spray thrown (m^3)"] = water["spray_emitted_m3"]
        if count.max() > 0:
            radius = float(np.nanmax(pool["particle_radius"]))
            out["spray in the air at most (m^3)"] = float(count.max()) * 4.0 / 3.0 * np.pi \
                * radius ** 3
        out["splash height (m)"] = float(max(high)) - level if high else 0.0
        out["highest drop (m)"] = None if top is None else top - level
    return out


def dive_search_loss(coupling: str, kw: dict) -> float:
    """The dive's loss for ``interplay tune diver`` (control/dive.py ``nudged_loss``): the dive
    in air to the water from this scene's platform; the water and the coupling play no part."""
    params = kw["params"]
    deck = deck_of(params.platform)
    return nudged_loss(lambda q: diver(q, deck, STANCE_X, air_density=params.air_density,
                                       level=LEVEL), params.dive.validated(), EDGE, LEVEL)


# the shipped DiveParams: `interplay tune diver --seed 4` (one chain, step 0.2; docs/diver.md)
DIVE_SEARCH = Search("dive", "the dive in air to the water: vertical, hands first, clear of "
                     "the platform, for the dive and its nudges",
                     bounds={f"dive.{k}": v for k, v in BOUNDS.items()},
                     loss=dive_search_loss, budget=400, chains=1, step=0.2, t_start=0.24)

SPEC = SceneSpec(
    "diver", "a diver enters a pool from a 10 m platform; a drag field stands in for the "
    "water, then his motion drives the splash (hybrid)", build, DiverParams,
    couplings=("hybrid", "two-way", "one-way"), duration=5.5, fps=60.0,
    camera=Camera(eye=(7.0, -15.0, 5.5), target=(1.5, 0.0, 5.0), fov_deg=45.0),
    figures=dive_figures, searches=(DIVE_SEARCH,), heavy=True)
