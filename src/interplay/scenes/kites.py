"""Single-line kites (SPEC 4, the kites row): three kites of different shapes and sizes, a
diamond (bowed 10 deg) with a long tail of bows, a larger bowed diamond (the Eddy) and a
rokkaku, each flown on its own line from a flyer's winder in the same gusty, turbulent wind
that grows with height. Each kite is a cloth sail, a rigid frame, a bridle and line, and a
tail, simulated separately and coupled two-way (``kite_parts``); the wind holds it up against
the line's tension, the sail's ripple varies the forces on the frame, and the tail's drag
steadies it: ``--set diamond_parts.tail.length=0`` flies the diamond without its tail, and in
the same gusts it wanders off and dives into the ground (docs/kites.md). The flyers are
kinematic: they stand and hold their lines (one-way, in lock step with their kites).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..control.kite_pilot import heading, window_coordinates
from ..geometry.kite import DiamondParams, RokkakuParams, diamond, rokkaku
from ..outputs.render.camera import Camera
from ..params import param
from ..scene import Scene
from ..systems.pilot import Pilot, PilotParams
from ..systems.static import StaticPlane
from . import kite_parts as KP
from .contract import SceneSpec

GRASS = (0.30, 0.42, 0.20)
KITES = ("diamond", "eddy", "rokkaku")
DESIGNS = {"diamond": diamond, "eddy": diamond, "rokkaku": rokkaku}
# linear RGB: sail, tail
COLORS = {"diamond": ((0.80, 0.08, 0.06), (0.95, 0.80, 0.10)),
          "eddy": ((0.08, 0.25, 0.75), (0.95, 0.45, 0.05)),
          "rokkaku": ((0.92, 0.90, 0.85), (0.75, 0.06, 0.10))}
SETTLE = 10.0  # s: the launch; flight statistics are over the time after it


@dataclass(frozen=True)
class KitesParams:
    """Each kite's design and components (its line's length among them); spacing (m): the
    flyers stand this far apart across the wind; launch_elevation (deg) and launch_alpha (deg):
    where each kite is let go, and its sail's angle to the wind then; coupling_dt (s)."""
    # turbulence: the neutral surface layer's at 10 m over short grass (z0 = 0.03 m): sigma_u,
    # sigma_v, sigma_w = 2.4, 1.9, 1.25 u* (Panofsky & Dutton 1984) with u = u* ln(z / z0) /
    # 0.4, i.e. 16.5, 13 and 8.6% of the speed; the primitive is isotropic, so their rms, 13%
    wind: KP.KiteWind = KP.KiteWind(speed=6.0, turbulence=0.13)
    diamond: DiamondParams = DiamondParams(tow=0.295, dihedral=10.0)
    diamond_parts: KP.KiteParams = KP.KiteParams(
        tail=KP.TailParams(length=6.0, segments=24, bow_area=0.003))
    # the Eddy: its cross spar high up the spine and bowed back (Eddy, 1890s)
    eddy: DiamondParams = DiamondParams(length=1.3, span=1.15, cross=0.18, dihedral=15.0,
                                        bridle=(0.04, 0.8), tow=0.3, tow_height=0.4)
    eddy_parts: KP.KiteParams = KP.KiteParams(
        line=KP.LineParams(length=30.0, segments=30),
        tail=KP.TailParams(length=3.0, segments=12, bow_area=0.003))
    rokkaku: RokkakuParams = RokkakuParams()
    rokkaku_parts: KP.KiteParams = KP.KiteParams(
        line=KP.LineParams(length=22.0, segments=22),
        tail=KP.TailParams(length=4.0, segments=16, bow_area=0.004))
    spacing: float = param(12.0, "m", ge=0.0, le=1000.0)
    launch_elevation: float = param(20.0, "deg", gt=0.0, lt=90.0)
    launch_alpha: float = param(35.0, "deg", gt=0.0, lt=90.0)
    coupling_dt: float = param(1.0 / 240.0, "s", ge=1e-6, le=0.05)


def build(coupling: str = "two-way", duration: float = 30.0, fps: float = 30.0,
          integrator: str | None = None, dt: float | None = None,
          params: KitesParams = KitesParams(), kites=KITES) -> Scene:
    """The scene; kites: which of KITES fly (each in its own place: a benchmark flies one)."""
    scene = Scene("kites", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    ground = scene.add(StaticPlane("ground", height=0.0, size=50.0, color=GRASS,
                                   material="ground"))
    wind = scene.add(KP.kite_wind(params.wind))
    wh = math.radians(params.wind.heading)
    downwind = np.array([math.cos(wh), math.sin(wh), 0.0])
    across = np.array([-downwind[1], downwind[0], 0.0])
    flyers, noses = {}, {}
    for k, name in enumerate(KITES):
        if name not in kites:
            continue
        y = (k - 1) * params.spacing
        flyer = scene.add(Pilot(f"{name}-flyer", PilotParams(
            position=tuple(y * across), heading=params.wind.heading, handles=1)))
        parts = getattr(params, f"{name}_parts")
        g = DESIGNS[name](getattr(params, name))
        hand = flyer.handle_positions()[0]
        pos, R = KP.launch_pose(hand, parts.line.length, params.launch_elevation,
                                g.bridles[0][1], pitch_deg=params.launch_alpha - 90.0,
                                heading=downwind)
        sail, tail = COLORS[name]
        kite = KP.build_kite(scene, name, g, parts, wind, ground, pos, R, [hand],
                             holder=(flyer, ["winder"]), color=sail, tail_color=tail,
                             mode=coupling)
        flyers[name] = hand.tolist()
        noses[name] = kite.frame.inertia.axes[0].tolist()  # the nose in the frame's axes
    scene.primary = wind
    scene.main = f"{next(k for k in KITES if k in kites)}-sail-ties"
    scene.meta = {"hands": flyers, "noses": noses}
    return scene


def flight(result, name: str) -> dict:
    """One kite's flight from a run: flew_s (s aloft from the start until its frame first
    came below ``kite_parts.LANDED`` after the launch, or the whole run), and over the time
    after the launch (SETTLE s) while it flew: the line elevation (deg: the kite seen from
    the hand, mean, its standard deviation, min, max), the azimuth's rms (deg) and the yaw
    wander (deg, the rms of its nose's heading in the wind window, 0 being straight up)."""
    fr = result.frames[f"{name}-frame"]
    t, pos, q = np.asarray(fr["t"]), np.asarray(fr["position"]), np.asarray(fr["orientation"])
    hand = result.meta["hands"][name]
    down = KP.came_down(fr)
    flew = float(t[-1]) if down is None else down
    keep = (t >= SETTLE) & (t <= flew)
    out = {"flew_s": round(flew, 2), "crashed": down is not None}
    if not keep.any():
        return out
    from ..kernels.rigid import quat_to_matrix
    nose = result.meta["noses"][name]
    phi, eps, chi = [], [], []
    for p, qq in zip(pos[keep], q[keep]):
        a, e = window_coordinates(p, hand)
        phi.append(a)
        eps.append(e)
        chi.append(heading(quat_to_matrix(qq) @ np.asarray(nose), a, e))
    el, az, yaw = (np.degrees(np.asarray(v)) for v in (eps, phi, chi))
    out.update({"elevation_mean_deg": round(float(el.mean()), 1),
                "elevation_sd_deg": round(float(el.std()), 2),
                "elevation_min_deg": round(float(el.min()), 1),
                "elevation_max_deg": round(float(el.max()), 1),
                "azimuth_rms_deg": round(float(np.sqrt(np.mean(az ** 2))), 2),
                "yaw_wander_rms_deg": round(float(np.sqrt(np.mean(yaw ** 2))), 2)})
    return out


def figures(result) -> dict:
    """Each kite's flight (``flight``), flattened for summaries."""
    return {f"{name} {k}": v for name in KITES if f"{name}-frame" in result.frames
            for k, v in flight(result, name).items()}


SPEC = SceneSpec(
    "kites", "a diamond, an Eddy and a rokkaku on their lines in a gusty wind (two-way "
    "components)", build, KitesParams, couplings=("two-way",), duration=30.0, fps=30.0,
    # behind the flyers and to one side, looking up along the lines at the three kites
    camera=Camera((-13.0, -23.0, 2.2), (14.0, -1.0, 12.0), 50.0), key_time=25.0,
    figures=figures)
