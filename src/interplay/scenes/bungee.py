"""A man on a bungee cord (SPEC 4): a figure on a bridge platform 40 m up leaps under its state
machine; a tension-only spring-mass cord tied to both ankles and to the bridge arrests the
fall; he bounces and comes to hang. Tune the leap with ``--set cord.enabled=false`` (the figure
alone, fast), then run two-way.

The leap: stand, crouch, tip forward over the toes (ankles dorsiflex with balance off) until
the centre of mass is far enough ahead, then a timed hip-knee-ankle extension with an arm
swing, a tuck so the feet clear the edge, and a layout (swan dive) for the rest. The defaults
of ``JumperParams`` were found by ``tune_leap`` (simulated annealing over the leap's parameters
with the cord disabled; ``interplay tune bungee`` runs it on every core), rounded and checked
again; docs/figures.md has the search and its result.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..control import behaviours as B
from ..control.search import Search
from ..control.fsm import Controller
from ..geometry.anthropometry import SEGMENTS, BodyParams
from ..geometry.setpieces import bridge
from ..interactions.attachment import AttachmentParams, SegmentAttachment
from ..outputs.render.camera import TrackingCamera
from ..scene import Scene
from ..systems.colliders import set_pieces
from ..systems.figure import Figure, FigureParams
from ..systems.figure_model import EnvironmentParams
from ..systems.springmass import SpringNetwork, Springs
from ..systems.static import StaticPlane
from .contract import SceneSpec
from ..params import param

BRIDGE = 40.0  # m, the platform's top
EDGE = 0.0  # m, x of the platform's front edge (the jumper faces +x)
STANCE_X = -0.32  # m, ankle x at rest: the toes end 5 cm short of the edge
STRAP = 0.25  # m, how far below the ankles the cord's end meets the two ankle straps
STRAP_STIFFNESS = 2.0e4  # N/m, each strap (webbing: stiff beside the cord)
TIP_MAX = 1.5  # s: the leap starts by then even if the lean never gets far enough
STRAIN_LIMIT = 3.0  # a bungee cord is made to stretch (15 m to ~26 m at the bottom here)
ANCHOR_HEIGHT = 0.5  # m above the deck: the jump arm the cord hangs from
PLATFORM = (-3.0, EDGE, -1.5, 1.5)  # m: x0, x1, y0, y1 of the jump platform's top
CORD_RADIUS = 0.016  # m: a jumper's bungee, a bundle of latex strands ~3 cm across


@dataclass(frozen=True)
class CordParams:
    """rest length (m), effective stiffness of the whole cord (N/m), mass (kg), points, damping
    (stiffness-proportional, s), dt (s) of its implicit integrator, reach (m): how far past the
    deck's edge its anchor is (a jump arm, so the cord hangs near plumb when it goes taut);
    enabled=false leaves the jumper alone (leap tuning).

    Stiffness: k L0 = 3 m g would put the cord's bounce at exactly twice the pendulum
    frequency, where an elastic pendulum pumps its bounce into a growing swing; 250 N/m keeps
    the 64 kg jumper well clear of it (k L0 / m g = 5.9). Damping 0.05 s gives the bounce a
    damping ratio of about 0.05 (k beta / 2 sqrt(k m)), a rubber cord's hysteresis."""
    enabled: bool = param(True, doc="false: the jumper alone (leap tuning)")
    length: float = param(15.0, "m", ge=0.1, le=1000.0, doc="rest length")
    # whole cord: its n-1 springs in series
    stiffness: float = param(250.0, "N/m", ge=1e-3, le=1e7, doc="the whole cord's")
    mass: float = param(1.0, "kg", ge=1e-3, le=1000.0)
    points: int = param(21, "points", ge=3, le=10_000, cost="points")
    damping: float = param(0.05, "s", ge=0.0, le=10.0, doc="stiffness-proportional")
    dt: float = param(1e-3, "s", ge=1e-9, le=0.1)
    reach: float = param(1.8, "m", ge=0.0, le=100.0, doc="anchor past the deck's edge")


@dataclass(frozen=True)
class JumperParams:
    """The jumper (the paper's gymnast: 64.38 kg, 1.70 m) and his leap: stand (s) before the
    crouch; crouch (s) and its depth (-, 1 = deep) and trunk lean (rad); then he tips forward
    over the toes with the ankles driven to tip_ankle (rad of dorsiflexion) until his centre of
    mass is lead (m) ahead of the middle of his feet; the push:
    hip (rad of hip flexion it extends to: a forward dive), power (-, scales the extension's
    velocity targets), arm_swing (rad of shoulder flexion the arms swing to); tuck (s) the knees
    are pulled up after takeoff so the feet clear the edge, before the layout."""
    mass: float = param(64.38, "kg", ge=10.0, le=500.0)
    height: float = param(1.70, "m", ge=0.5, le=3.0)
    stand: float = param(0.3, "s", ge=0.0, le=100.0)
    crouch: float = param(0.7, "s", ge=0.0, le=100.0)
    depth: float = param(0.65, "-", ge=0.0, le=2.0, doc="crouch depth, 1 = deep")
    lean: float = param(0.36, "rad", ge=-1.6, le=1.6, doc="trunk lean in the crouch")
    lead: float = param(0.16, "m", ge=-1.0, le=1.0, doc="centre of mass ahead of the feet")
    tip_ankle: float = param(0.52, "rad", ge=-1.6, le=1.6, doc="ankle dorsiflexion to tip")
    hip: float = param(0.67, "rad", ge=-1.6, le=2.6, doc="hip flexion of the push")
    power: float = param(1.24, "-", ge=0.0, le=5.0, doc="scales the extension's velocities")
    arm_swing: float = param(1.00, "rad", ge=-3.2, le=3.2, doc="shoulder flexion of the swing")
    tuck: float = param(0.75, "s", ge=0.0, le=100.0, doc="knees pulled up after takeoff")


@dataclass(frozen=True)
class BungeeParams:
    """air_density (kg/m^3): the drag on the jumper's segments (0: none)."""
    jumper: JumperParams = JumperParams()
    cord: CordParams = CordParams()
    tie: AttachmentParams = AttachmentParams()
    coupling_dt: float = param(1e-3, "s", ge=1e-7, le=0.1)
    air_density: float = param(1.2, "kg/m^3", ge=0.0, le=100.0, doc="0: no drag")


def controller(p: JumperParams) -> Controller:
    """stand -> crouch -> tip -> leap -> tuck (the feet clear the edge) -> layout (the rest
    of the flight, the bounces and the hang)."""
    return Controller((B.stand(next="crouch", after=p.stand),
                       B.crouch(next="tip", after=p.crouch, depth=p.depth, lean=p.lean),
                       B.tip(next="leap", ankle=p.tip_ankle, lead=p.lead, after=TIP_MAX),
                       B.leap(next="tuck", power=p.power, arm_swing=p.arm_swing, hip=p.hip),
                       B.tuck(next="layout", after=p.tuck),
                       B.layout()), start="stand")


def jumper(p: JumperParams, air_density: float = 1.2) -> Figure:
    """The jumper on the bridge platform, under his leap controller; air_density (kg/m^3)."""
    env = EnvironmentParams(floor=None, platform=(*PLATFORM, BRIDGE),
                            air_density=air_density)
    return Figure("jumper", FigureParams(body=BodyParams(p.mass, p.height), environment=env,
                                         position=(STANCE_X, 0.0, BRIDGE)), controller(p))


def cord(c: CordParams, anchor, ankles, integrator="implicit", dt=None) -> SpringNetwork:
    """The cord from ``anchor`` (m, fixed) hanging slack in a V down and back up to a point
    below the ankles, where two short straps (stiff tension-only springs) lead to the ankles
    ``ankles`` (2,3) m: points 0..n-1 are the cord, n and n+1 the strap ends; the cord's mass
    is shared equally by all n+2 points. Settled under gravity with both ends held."""
    n = c.points
    anchor, ankles = np.asarray(anchor, float), np.asarray(ankles, float)
    end = ankles.mean(axis=0) + [0.0, 0.0, -STRAP]
    s = np.linspace(0.0, 1.0, n)
    drop = c.length * np.minimum(s, 1.0 - s)  # two legs, each half the rest length long
    x = np.vstack([anchor + s[:, None] * (end - anchor) - drop[:, None] * [0.0, 0.0, 1.0],
                   ankles])
    seg_k = c.stiffness * (n - 1)  # n-1 springs in series give the cord's stiffness
    strap = np.linalg.norm(ankles - end, axis=1)
    springs = Springs(np.r_[np.arange(n - 1), n - 1, n - 1], np.r_[np.arange(1, n), n, n + 1],
                      np.r_[np.full(n - 1, c.length / (n - 1)), strap],
                      np.r_[np.full(n - 1, seg_k), STRAP_STIFFNESS, STRAP_STIFFNESS],
                      np.ones(n + 1, dtype=bool))
    net = SpringNetwork("cord", x, c.mass / (n + 2), springs, dt=dt or c.dt, integrator=integrator,
                        stiffness_damping=c.damping, fixed=[0, n, n + 1],
                        strain_limit=STRAIN_LIMIT, cord_radius=CORD_RADIUS,
                        color=(0.95, 0.75, 0.10))
    net.settle()
    net.fixed[[n, n + 1]] = False  # the straps move with the ankles from here on
    return net


def build(coupling: str = "two-way", duration: float = 8.0, fps: float = 30.0,
          integrator: str | None = None, dt: float | None = None,
          params: BungeeParams = BungeeParams()) -> Scene:
    c = params.cord
    scene = Scene("bungee", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    fig = scene.add(jumper(params.jumper, params.air_density))
    scene.primary = fig
    anchor = [EDGE + c.reach, 0.0, BRIDGE + ANCHOR_HEIGHT]
    # the bridge he leaps from: its deck, the platform (the figure's own collision model
    # holds it), the jump arm the cord hangs from, and the valley floor far below
    for piece in set_pieces(bridge(BRIDGE, EDGE, PLATFORM, anchor)):
        scene.add(piece)
    scene.add(StaticPlane("valley", height=0.0, size=80.0, color=(0.28, 0.40, 0.20)))
    if c.enabled:
        feet = ("l_foot", "r_foot")
        ankles = fig.contact_view().poses()[0][[SEGMENTS.index(f) for f in feet]]
        net = scene.add(cord(c, anchor, ankles, integrator or "implicit", dt))
        n = c.points
        scene.connect(SegmentAttachment("cord", fig, net, ((n, feet[0]), (n + 1, feet[1])),
                                        params=params.tie, mode=coupling))
    scene.meta = {"bridge_height": BRIDGE, "platform_edge": EDGE}
    return scene


def leap_trial(p: JumperParams, duration: float = 3.0) -> dict:
    """The figure alone (cord disabled) from stand to dive: takeoff (s, both feet off the
    deck in the leap), rise (m, highest centre of mass above its standing height), clear_x (m,
    the centre of mass's distance past the edge when it falls 1 m below the deck; None if it
    has not by ``duration``), touched (s of deck contact after takeoff), final centre of mass."""
    fig = jumper(p)
    z0 = fig.com()[2]
    out = {"takeoff": None, "rise": 0.0, "clear_x": None, "touched": 0.0}
    steps = int(round(duration / fig.dt))
    for _ in range(steps):
        fig.advance(fig.dt)
        c = fig.com()
        out["rise"] = max(out["rise"], c[2] - z0)
        state = fig.fsm.state.name
        if out["takeoff"] is None and state == "tuck":
            out["takeoff"] = fig.time
        elif out["takeoff"] is not None and fig.data.ncon:
            out["touched"] += fig.dt
        if out["clear_x"] is None and c[2] < BRIDGE - 1.0:
            out["clear_x"] = c[0] - EDGE
    out["com"] = fig.com()
    return out


def leap_loss(p: JumperParams) -> float:
    """What the search minimises, averaged over the leap and its NUDGES (so the optimum is not
    a knife edge where a hair's change makes a toe catch the edge): minus the clearance past
    the edge (capped at CLEAR), minus twice the rise (capped at 0.4 m), plus a penalty per
    second of deck contact after takeoff."""
    total = 0.0
    for nudge in NUDGES:
        q = replace(p, **{k: getattr(p, k) + d for k, d in nudge})
        r = leap_trial(q)
        clear = r["clear_x"] if r["clear_x"] is not None else r["com"][0] - EDGE - 1.0
        total += -min(clear, CLEAR) - 2.0 * min(r["rise"], 0.4) + 50.0 * r["touched"]
    return total / len(NUDGES)


NUDGES = ((), (("lead", -0.02),), (("lead", 0.02),), (("lean", -0.03),), (("lean", 0.03),))
CLEAR = 0.6  # m past the edge: enough to clear the deck; more only swings him on the cord
TUNED = ("depth", "lean", "lead", "hip", "power", "arm_swing", "tuck")
BOUNDS = {"depth": (0.3, 1.1), "lean": (0.0, 0.8), "lead": (0.0, 0.3), "hip": (-0.2, 1.4),
          "power": (0.5, 2.0), "arm_swing": (1.0, 3.0), "tuck": (0.1, 0.8)}


def tune_leap(evaluations: int = 150, seed: int = 0, start: JumperParams = JumperParams()):
    """Simulated annealing over the leap parameters in TUNED (cord disabled), one candidate at
    a time in this process; returns the best JumperParams and the SearchResult. ``interplay
    tune bungee --chains 1`` runs the same search (on the executor)."""
    from ..control.search import anneal
    res = anneal(lambda d: leap_loss(replace(start, **d)),
                 {k: getattr(start, k) for k in TUNED}, BOUNDS, evaluations, seed)
    return replace(start, **res.best), res


def leap_search_loss(coupling: str, kw: dict) -> float:
    """The leap's loss for ``interplay tune bungee``: the jumper's parameters in the build
    keywords kw; the cord and the coupling play no part (the figure leaps alone)."""
    return leap_loss(kw["params"].jumper)


LEAP_SEARCH = Search("leap", "the leap off the deck (figure alone): clear the edge, rise, "
                     "never touch the deck after takeoff",
                     bounds={f"jumper.{k}": v for k, v in BOUNDS.items()},
                     loss=leap_search_loss, budget=150, chains=4)

SPEC = SceneSpec(
    "bungee", "a figure leaps off a bridge on a spring-mass bungee cord (two-way)", build,
    BungeeParams, couplings=("two-way", "one-way"), duration=8.0, fps=30.0,
    integrators=("explicit", "implicit", "localglobal"), searches=(LEAP_SEARCH,),
    # beside him and a little above, 6.7 m off: he stays a third of the frame tall all the way
    camera=TrackingCamera("jumper", offset=(5.2, -4.0, 1.2), target_offset=(0.4, 0.0, -0.3),
                          fov_deg=38.0, smooth_s=0.35), key_time=3.4)
