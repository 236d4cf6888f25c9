"""A two-line stunt kite flown by a pilot (SPEC 4, the kites row): the kite is a cloth delta,
its frame, two bridles each with its flying line, and a short tail, coupled two-way
(``kite_parts``); the lines' ground ends are the pilot's two handles, which a controller moves
as a person flies: it watches the kite, pulls one side to turn it, and flies a loop or a
figure-8 on command (``--set control.manoeuvre=figure8``). The pilot is kinematic (it stands
firm), so the lines act on it one-way, in lock step with the kite.

The kite is built to fly in the per-triangle aerodynamics of SPEC 2.2 (docs/kites.md derives
and measures each choice):

* its sail's centre of pressure moves along the chord with the angle of attack as a flat
  plate's does (``AeroParams(centre="chord")``), so the kite trims in pitch on its towing
  point and pulls with its sail's force, not with a weight behind it: no tail weight;
* its wingtips are swept forward of the spine, towards the flyer (dihedral -25 deg): with
  them back, a kite in this law turns away from the line that is pulled; forward, towards it;
* the pilot's full steering is a 0.8 m difference between the hands (``control.throw`` 0.4),
  and each loop begins high (``control.ready`` 50 deg, the window's top is 52-56 deg): the
  loops then clear the ground.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..control.kite_pilot import StuntPilot, StuntPilotParams, window_coordinates
from ..geometry.kite import SparParams, StuntParams, stunt
from ..interactions.aero import AeroParams
from ..outputs.render.camera import Camera
from ..params import param
from ..scene import Scene
from ..systems.pilot import Pilot, PilotParams
from ..systems.static import StaticPlane
from . import kite_parts as KP
from .contract import SceneSpec

GRASS = (0.30, 0.42, 0.20)
LAUNCH_ELEVATION = 20.0  # deg: where the kite is let go, lines laid out straight
LAUNCH_ALPHA = 25.0  # deg: its sail's angle to the wind then, near how it flies


@dataclass(frozen=True)
class StuntKiteParams:
    """The kite's design, its components, the pilot and how it flies, the wind; coupling_dt
    (s): the step at which the components exchange forces."""
    kite: StuntParams = StuntParams(dihedral=-25.0, ballast=0.0, tow=0.30, tow_height=0.6,
                                    spars=SparParams(radius=0.003, density=600.0))
    parts: KP.KiteParams = KP.KiteParams(
        line=KP.LineParams(radius=3e-4, density=3e-4),
        tail=KP.TailParams(length=2.5, segments=10, bow_area=0.01),
        aero=AeroParams(centre="chord"))
    pilot: PilotParams = PilotParams()
    control: StuntPilotParams = StuntPilotParams(throw=0.4, ready=50.0)
    wind: KP.KiteWind = KP.KiteWind(speed=8.0, turbulence=0.05)
    coupling_dt: float = param(1.0 / 240.0, "s", ge=1e-6, le=0.05)


def build(coupling: str = "two-way", duration: float = 24.0, fps: float = 30.0,
          integrator: str | None = None, dt: float | None = None,
          params: StuntKiteParams = StuntKiteParams()) -> Scene:
    scene = Scene("stunt-kite", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    ground = scene.add(StaticPlane("ground", height=0.0, size=45.0, color=GRASS,
                                   material="ground"))
    wind = scene.add(KP.kite_wind(params.wind))
    pilot = scene.add(Pilot("pilot", params.pilot))  # first: it looks before the kite moves
    g = stunt(params.kite)
    hands = pilot.handle_positions()
    towing = 0.5 * (g.bridles[0][1] + g.bridles[1][1])
    # both lines a centimetre short of straight: the launch lays them out, not stretched
    pos, R = KP.launch_pose(hands.mean(axis=0), params.parts.line.length - 0.01,
                            LAUNCH_ELEVATION, towing, pitch_deg=LAUNCH_ALPHA - 90.0,
                            heading=(math.cos(math.radians(params.wind.heading)),
                                     math.sin(math.radians(params.wind.heading)), 0.0))
    kite = KP.build_kite(scene, "stunt", g, params.parts, wind, ground, pos, R, list(hands),
                         holder=(pilot, ["l_handle", "r_handle"]), color=(0.10, 0.30, 0.85),
                         tail_color=(0.95, 0.85, 0.15), mode=coupling)
    pilot.controller = StuntPilot(kite.frame.contact_view(), kite.frame.inertia.axes[0],
                                  params.control)
    scene.primary = pilot
    scene.main = "stunt-l_handle"
    scene.meta = {"manoeuvres": pilot.controller.log, "hands": hands.mean(axis=0).tolist(),
                  "line_weight_n": params.parts.line.density * params.parts.line.length
                  * 9.81}
    return scene


TAUT = 5.0  # a line pulls its handle with more than this many times its own weight: taut


def figures(result) -> dict:
    """The flight as numbers: each manoeuvre's duration (s, a loop's full turn of the nose;
    an 8's two loops), the share of the time after the launch that each line was taut
    (pulling more than TAUT times its weight), when the kite came down (s, None: it did not)
    and its elevation (deg) range."""
    out = {}
    for k, (kind, sign, t0, t1) in enumerate(result.meta.get("manoeuvres", [])):
        side = "left" if sign > 0 else "right"
        out[f"{kind} {k + 1} ({side}) s"] = None if t1 is None else round(t1 - t0, 2)
    weight = result.meta.get("line_weight_n", 0.0)
    for part in ("l_handle", "r_handle"):
        log = result.logs.get(f"stunt-{part}")
        if log is not None and (log.t >= KP.LAUNCH).any():
            after = log.t >= KP.LAUNCH
            f = np.linalg.norm(log.force[after], axis=1)
            out[f"{part} taut share"] = round(float(np.mean(f > TAUT * weight)), 4)
    fr = result.frames.get("stunt-frame")
    if fr is not None and len(fr["t"]):
        out["came down at s"] = KP.came_down(fr)
        c = result.meta["hands"]
        el = [math.degrees(window_coordinates(p, c)[1]) for p in fr["position"]]
        out["elevation min deg"] = round(min(el), 1)
        out["elevation max deg"] = round(max(el), 1)
    return out


SPEC = SceneSpec(
    "stunt-kite", "a two-line stunt kite flown through loops by a pilot (two-way components)",
    build, StuntKiteParams, couplings=("two-way",), duration=24.0, fps=30.0,
    # behind the pilot, the wind window ahead: the kite loops 25 m downwind
    camera=Camera((-9.0, -3.5, 1.8), (14.0, 1.0, 8.5), 56.0), key_time=10.0,
    figures=figures)
