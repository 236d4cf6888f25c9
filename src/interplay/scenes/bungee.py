"""A man on a bungee cord (SPEC 4): a figure on a bridge platform 40 m up leaps under its state
machine; a tension-only spring-mass cord tied to both ankles and to the bridge arrests the
fall; he bounces and comes to hang. Tune the leap with ``--set cord.enabled=false`` (the figure
alone, fast), then run two-way."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..control import behaviours as B
from ..control.fsm import Controller
from ..geometry.anthropometry import BodyParams
from ..interactions.attachment import AttachmentParams, SegmentAttachment
from ..scene import Scene
from ..systems.figure import Figure, FigureParams
from ..systems.figure_model import EnvironmentParams
from ..systems.springmass import SpringNetwork, Springs

BRIDGE = 40.0  # m, the platform's top


@dataclass(frozen=True)
class CordParams:
    """rest length (m), effective stiffness of the whole cord (N/m), mass (kg), points, damping
    (stiffness-proportional, s); enabled=false leaves the jumper alone (leap tuning)."""
    enabled: bool = True
    length: float = 15.0  # m
    stiffness: float = 150.0  # N/m, whole cord: k = n k_segment / ... in series
    mass: float = 1.0  # kg
    points: int = 21
    damping: float = 0.02  # s
    dt: float = 1e-3  # s


@dataclass(frozen=True)
class JumperParams:
    """The jumper (the paper's gymnast: 64.38 kg, 1.70 m); lean (rad) of the dive, how long
    he stands (s) before leaning out."""
    mass: float = 64.38  # kg
    height: float = 1.70  # m
    stand: float = 0.5  # s
    lean: float = 0.5  # rad


@dataclass(frozen=True)
class BungeeParams:
    jumper: JumperParams = JumperParams()
    cord: CordParams = CordParams()
    tie: AttachmentParams = AttachmentParams()
    coupling_dt: float = 1e-3  # s


PARAMS = BungeeParams


def controller(p: JumperParams) -> Controller:
    """Stand, then dive: lean out over the edge (ankles and hips), push off, layout."""
    return Controller((B.stand(next="leap", after=p.stand),
                       B.leap(next="layout", power=0.6),
                       B.layout()), start="stand")


def build(coupling: str = "two-way", duration: float = 8.0, fps: float = 30.0,
          integrator: str | None = None, dt: float | None = None,
          params: BungeeParams = BungeeParams()) -> Scene:
    j, c = params.jumper, params.cord
    scene = Scene("bungee", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    env = EnvironmentParams(floor=None, platform=(-3.0, 0.0, -1.5, 1.5, BRIDGE))
    fig = scene.add(Figure("jumper", FigureParams(body=BodyParams(j.mass, j.height),
                                                  environment=env, position=(-0.15, 0.0, BRIDGE)),
                           controller(j)))
    scene.primary = fig
    if c.enabled:
        n = c.points
        anchor = np.array([-0.3, 0.0, BRIDGE])
        ankle = fig.data.xpos[fig.seg_body[11]] * [1, 0, 1]
        x = anchor + np.linspace(0.0, 1.0, n)[:, None] * (ankle - anchor)
        seg_k = c.stiffness * (n - 1)  # n-1 springs in series give the cord's stiffness
        springs = Springs(np.arange(n - 1), np.arange(1, n), np.full(n - 1, c.length / (n - 1)),
                          np.full(n - 1, seg_k), np.ones(n - 1, dtype=bool))
        net = scene.add(SpringNetwork("cord", x, c.mass / n, springs,
                                      dt=dt or c.dt, integrator=integrator or "implicit",
                                      stiffness_damping=c.damping, fixed=[0]))
        for side in ("l", "r"):
            scene.connect(SegmentAttachment(f"cord-{side}-ankle", fig, net, n - 1,
                                            f"{side}_foot", params=params.tie, mode=coupling))
    scene.meta = {"bridge_height": BRIDGE}
    return scene
