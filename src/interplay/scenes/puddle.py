"""A runner's foot stepping in a shallow puddle (SPEC 4, the runner's splash), coupled
one-way: the foot's motion is the animation's and stays unchanged; the water is pushed out
from under it and splashes.

The runner is the CMU motion-capture jog (``clip``, from ../shared/data/mocap, played by a
MocapFigure), placed so that its right foot's second stance lands in the middle of the puddle.
The water feels an ellipsoid the size of a shoe that follows the midpoint of the clip's right
ankle and toe joints (position only: it stays level, so heel strike and toe-off are not
resolved). Without the clip the foot follows the keyframed running step of FootParams.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry.anthropometry import SEGMENTS
from ..geometry.basin import BasinParams, banks, basin, terrain
from ..interactions.buoyancy import BodyInWater, BuoyancyParams
from ..interactions.standins import ViscousDragField, ViscousDragFieldParams
from ..outputs.render.camera import TrackingCamera
from ..params import param
from ..scene import Scene
from ..systems.colliders import set_pieces
from ..systems.kinematic import KeyframedBody, KeyframedBodyParams
from ..systems.mocap import MocapFigure, check_clip, clip_path
from ..systems.water import SprayParams, Water, WaterParams
from .contract import SceneSpec


@dataclass(frozen=True)
class FootParams(KeyframedBodyParams):
    """A running step: the foot swings in at about 2 m/s down and forward, lands flat on the
    bed (centre one semi-axis above it), rolls forward 3 cm in 0.2 s of stance and pushes off.
    times in s, positions m (x, y, z per key)."""
    times: tuple = param((0.0, 0.12, 0.2, 0.4, 0.52, 0.75), "s", ge=0.0, le=1e5, length=None,
                         doc="key times, increasing")
    positions: tuple = param((-0.55, 0.0, 0.28,
                              -0.2, 0.0, 0.15,
                              -0.06, 0.0, 0.045,
                              -0.03, 0.0, 0.045,
                              0.12, 0.0, 0.14,
                              0.55, 0.0, 0.3), "m", ge=-1e4, le=1e4, length=None,
                             doc="x, y, z of each key")
    # a shoe 26 cm long, 10 cm wide
    semi_axes: tuple = param((0.13, 0.05, 0.045), "m", ge=1e-3, le=10.0)
    mass: float = param(1.2, "kg", ge=1e-3, le=1e4, doc="foot and shank")
    dt: float = param(0.002, "s", ge=1e-9, le=1.0)


@dataclass(frozen=True)
class PuddleParams:
    basin: BasinParams = BasinParams(size_x=1.2, size_y=0.8, cells=120, depth=0.02, shore=0.2,
                                     rim=1.5)
    # light damping under the foot: the water it squeezes out must leave fast to splash
    water: WaterParams = WaterParams(body_damping=20.0,
                                     spray=SprayParams(threshold=0.4, fraction=0.3,
                                                       radius=0.002, capacity=6000))
    foot: FootParams = FootParams()
    buoyancy: BuoyancyParams = BuoyancyParams()
    field: ViscousDragFieldParams = ViscousDragFieldParams(linear=2.0, quadratic=20.0)
    coupling_dt: float = param(2e-3, "s", ge=1e-7, le=0.1)
    # the runner; "": the keyframed foot
    clip: str = param("cmu_02_03_run.bvh", check=check_clip,
                      doc="a BVH clip in the mocap folder or a path; empty: keyframes")


PAVEMENT = (0.30, 0.30, 0.31)  # linear RGB
STANCE = (0.8, 1.1)  # s: the right foot's second stance in the jog clip


def _runner(params: PuddleParams, geo):
    """(foot keyframes, the runner figure or None) from the clip, placed so that the right
    foot's stance is over the puddle's middle; every stance's sole on the ground (the puddle's
    bed in it, the ground at the rim's height around it), and the shoe ellipsoid following
    the midpoint of the right ankle and toes with its bottom on the bed in the puddle."""
    path = clip_path(params.clip) if params.clip else None
    if path is None or not path.exists():
        return params.foot, None
    names = list(SEGMENTS)

    def foot_centres(clip):
        t = np.arange(0.0, clip.duration, clip.motion.frame_time)
        centre = np.empty((len(t), 3))
        for k, tk in enumerate(t):
            clip.set_time(tk)
            seg = clip.segment_positions()
            centre[k] = 0.5 * (seg[names.index("r_foot")] + seg[names.index("r_toes")])
        return t, centre

    t, centre = foot_centres(MocapFigure("runner", path))
    stance = (t >= STANCE[0]) & (t <= STANCE[1])
    low = np.argmin(np.where(stance, centre[:, 2], np.inf))
    runner = MocapFigure("runner", path, position_offset=(-centre[low, 0], -centre[low, 1], 0.0),
                         ground=terrain(geo))
    t, centre = foot_centres(runner)
    runner.set_time(0.0)
    low = np.argmin(np.where(stance, centre[:, 2], np.inf))
    keys = centre + [0.0, 0.0, params.foot.semi_axes[2] - centre[low, 2]]
    return replace(params.foot, times=tuple(t), positions=tuple(keys.ravel())), runner


def build(coupling: str = "one-way", duration: float = 1.5, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: PuddleParams = PuddleParams()) -> Scene:
    """The scene. dt overrides the water's largest step (s). Every coupling mode gives the
    same foot (nothing moves an animation); one-way is the honest one."""
    wp = params.water if dt is None else replace(params.water, dt=dt)
    geo = basin(params.basin)
    scene = Scene("puddle", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    foot_params, runner = _runner(params, geo)
    if runner is not None:
        scene.add(runner)
    foot = scene.add(KeyframedBody("foot", foot_params))
    foot.color = (0.06, 0.06, 0.07)
    water = scene.add(Water("water", geo.bed, geo.fluid, geo.depth, geo.spacing, geo.origin,
                            wp))
    # the pavement the puddle lies in, level with the basin's rim (the water draws its bed:
    # wet, dark pavement)
    water.bed_color, water.bank_color = (0.10, 0.10, 0.10), PAVEMENT
    scene.add(set_pieces([banks(geo, "pavement", 12.0, PAVEMENT)])[0])
    field = ViscousDragField(replace(params.field, surface=params.basin.depth))
    scene.connect(BodyInWater("foot-water", foot, water, params.buoyancy, mode=coupling,
                              standin=field))
    scene.primary = foot
    scene.checkpoints = {"foot": [0.2, 0.4]}
    scene.meta = {"still_level": params.basin.depth}
    return scene


SPEC = SceneSpec(
    "puddle", "a motion-captured runner's foot steps in a shallow puddle and splashes it "
    "(one-way)", build, PuddleParams, couplings=("one-way",), duration=1.5, fps=60.0,
    # low and to the side of the puddle, panning half way with the runner
    camera=TrackingCamera("runner", offset=(0.3, -3.6, 0.45), target_offset=(0.0, 0.0, 0.75),
                          axes=(0.5, 0.0, 0.0), fov_deg=40.0, smooth_s=0.3), key_time=0.95)
