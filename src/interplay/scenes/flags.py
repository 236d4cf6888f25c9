"""Flags in the wind: several flags of different sizes and materials on poles, pinned along
the pole edge, in a gusty wind (one-way: the air does not feel the cloth)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..geometry import shapes
from ..interactions.aero import AeroParams, Aerodynamics
from ..outputs.render.camera import Camera
from ..scene import Scene
from ..systems.colliders import StaticMesh
from ..systems.springmass import SpringNetwork
from ..systems.static import StaticPlane
from ..systems.wind import FlowPrimitive, WindField
from .contract import SceneSpec
from ..params import param


@dataclass(frozen=True)
class FlagParams:
    """One flag. pole (m): where its pole stands, pole_height (m): the flag's top edge height;
    width, height (m); nu, nv: vertices along and down the flag; density (kg/m^2); stretch,
    shear, bend: stress/strain ratios (N), k = ratio / rest length; mass_damping (1/s),
    stiffness_damping (s): Rayleigh; dt (s) and integrator of its own simulation; cg_tolerance:
    the implicit solve's relative residual (1e-5 moves a point ~1e-5 of its step's change:
    invisible, and it halves the CG iterations of 1e-8)."""
    pole: tuple = param((0.0, 0.0, 0.0), "m", ge=-100.0, le=100.0, doc="foot of the pole")
    pole_height: float = param(3.0, "m", ge=0.01, le=100.0, doc="the flag's top edge")
    width: float = param(1.5, "m", ge=0.01, le=50.0)
    height: float = param(1.0, "m", ge=0.01, le=50.0)
    nu: int = param(30, "vertices", ge=2, le=2000, cost="points", doc="along the flag")
    nv: int = param(20, "vertices", ge=2, le=2000, cost="points", doc="down the flag")
    density: float = param(0.15, "kg/m^2", ge=1e-4, le=100.0)  # cotton bunting
    # ~3000 N/m membrane stiffness at this spacing, cotton-like
    stretch: float = param(150.0, "N", ge=1e-6, le=1e9, doc="stress/strain ratio")
    shear: float = param(50.0, "N", ge=1e-6, le=1e9)
    bend: float = param(0.5, "N", ge=1e-6, le=1e9)
    mass_damping: float = param(0.05, "1/s", ge=0.0, le=1e4)
    stiffness_damping: float = param(2e-4, "s", ge=0.0, le=1.0)
    dt: float = param(1.0 / 240.0, "s", ge=1e-9, le=0.1)
    integrator: str = param("implicit", choices=("explicit", "implicit", "localglobal"))
    cg_tolerance: float = param(1e-5, "-", ge=1e-14, le=0.1, doc="implicit solve's residual")


@dataclass(frozen=True)
class GustyWind:
    """speed (m/s) towards heading (deg from +x, counter-clockwise), gusting by +-gust of it
    with main period gust_period (s); cross (m/s): a sideways component gusting out of phase
    from 0 to 2 cross, so the wind's direction swings too."""
    speed: float = param(6.0, "m/s", ge=0.0, le=100.0)
    heading: float = param(0.0, "deg", ge=-360.0, le=360.0)
    gust: float = param(0.4, "-", ge=0.0, le=1.0, doc="share of the speed")
    gust_period: float = param(2.5, "s", ge=0.01, le=1000.0)
    cross: float = param(1.0, "m/s", ge=-100.0, le=100.0)


@dataclass(frozen=True)
class FlagsParams:
    wind: GustyWind = GustyWind()
    aero: AeroParams = AeroParams()
    cotton: FlagParams = FlagParams()
    # light nylon, small and fast
    nylon: FlagParams = FlagParams(pole=(0.0, 3.0, 0.0), pole_height=2.5, width=0.9, height=0.6,
                                   nu=24, nv=16, density=0.06, stretch=60.0, shear=20.0,
                                   bend=0.1)
    # heavy canvas banner, large and slow
    canvas: FlagParams = FlagParams(pole=(0.0, -3.5, 0.0), pole_height=4.0, width=2.0,
                                    height=1.2, nu=32, nv=20, density=0.35, stretch=400.0,
                                    shear=150.0, bend=3.0)


# linear RGB: cream cotton, red nylon, navy canvas (apart from each other and from the sky)
COLORS = {"cotton": (0.85, 0.82, 0.70), "nylon": (0.75, 0.06, 0.05),
          "canvas": (0.06, 0.12, 0.30)}


# the wind near the ground is turbulent: eddies of a few metres carried along by it, at 10-20%
# of its speed (the surface layer's turbulence intensity); they shake the flags at the time
# scales flags flutter on (U / L ~ 4 Hz), where gusts of seconds only swing them
TURBULENCE = 0.15  # rms speed per component / mean speed
TURBULENCE_SCALE = 2.0  # m
SEED_RIPPLE = 2e-3  # m: no flag hangs perfectly flat; this ripple breaks the flat symmetry


def wind_field(w: GustyWind, turbulence: float = TURBULENCE) -> WindField:
    """The mean wind (gusting, its direction swinging with the cross component) and the
    turbulence it carries (turbulence: rms per component / mean speed; 0 for none)."""
    h = math.radians(w.heading)
    along, across = (math.cos(h), math.sin(h), 0.0), (-math.sin(h), math.cos(h), 0.0)
    prims = [FlowPrimitive("uniform", axis=along, strength=w.speed, gust=w.gust,
                           gust_period=w.gust_period),
             FlowPrimitive("uniform", axis=across, strength=w.cross,
                           gust=1.0 if w.cross else 0.0, gust_period=1.7 * w.gust_period,
                           phase=2.0)]
    if turbulence > 0.0:
        prims.append(FlowPrimitive("turbulence", strength=turbulence * w.speed,
                                   core=TURBULENCE_SCALE, phase=0.7,
                                   velocity=tuple(w.speed * np.asarray(along))))
    return WindField("wind", prims)


def flag(name: str, p: FlagParams, ripple: float = SEED_RIPPLE,
         scheme: str = "bdf2") -> SpringNetwork:
    """A flag streaming along +x from its pole in the xz plane, pinned along the pole edge,
    with a lateral ripple (m) of one wave along it. Implicit flags step by BDF2 (scheme;
    "theta" is backward Euler): backward
    Euler's damping of (w h)^2/2 per step takes ~40% of a 6 Hz flutter's amplitude per
    cycle at h = 1/240 s (docs/cloth.md, the flutter measurement)."""
    top = np.asarray(p.pole, float) + [0.0, 0.0, p.pole_height]
    x, tris = shapes.grid(p.width, p.height, p.nu, p.nv, origin=top, u=(1, 0, 0), v=(0, 0, -1))
    s = (x[:, 0] - top[0]) / p.width
    x[:, 1] += ripple * np.sin(np.pi * s) * s
    net = SpringNetwork.from_mesh(name, x, tris, p.density * p.width * p.height, p.stretch,
                                  p.shear, p.bend, dt=p.dt, integrator=p.integrator,
                                  scheme=scheme, mass_damping=p.mass_damping,
                                  stiffness_damping=p.stiffness_damping,
                                  cg_tolerance=p.cg_tolerance, fixed=np.arange(p.nv) * p.nu)
    return net


def build(coupling: str = "one-way", duration: float = 4.0, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: FlagsParams = FlagsParams()) -> Scene:
    """The scene; integrator and dt (s) override every flag's. The wind ignores forces: the
    coupling is one-way (the air does not feel the cloth). The poles are set pieces (static
    meshes: drawn, costing no pass), standing on the ground."""
    scene = Scene("flags", duration=duration, fps=fps)
    scene.add(StaticPlane("ground", height=0.0, size=12.0, color=(0.30, 0.42, 0.20)))
    wind = scene.add(wind_field(params.wind))
    for name in ("cotton", "nylon", "canvas"):
        p = getattr(params, name)
        if integrator is not None:
            p = replace(p, integrator=integrator)
        if dt is not None:
            p = replace(p, dt=dt)
        cloth = scene.add(flag(name, p))
        cloth.color = COLORS[name]
        pv, pt = shapes.pole(p.pole_height + 0.1)
        scene.add(StaticMesh(f"{name}-pole", pv + np.asarray(p.pole, float), pt,
                             color=(0.78, 0.78, 0.80), material="metal"))
        scene.connect(Aerodynamics(f"wind-{name}", wind, cloth, params.aero, mode="one-way"))
    scene.primary = wind
    return scene


SPEC = SceneSpec(
    "flags", "flags of cotton, nylon and canvas on poles in a gusty wind (one-way)", build,
    FlagsParams, couplings=("one-way",), duration=4.0, fps=60.0,
    integrators=("explicit", "implicit", "localglobal"),
    # downwind and to the side, the small nylon flag nearest: all three fill the frame
    camera=Camera((4.6, 7.4, 2.3), (0.9, -0.4, 2.9), 32.0), key_time=2.5)


def flutter_trial(p: FlagParams, speed: float = 8.0, duration: float = 6.0,
                  settle: float = 2.0, fps: float = 240.0, ripple: float = SEED_RIPPLE,
                  scheme: str = "bdf2") -> dict:
    """One flag alone in a steady uniform wind of speed (m/s) along its length (no gust, no
    turbulence): the free edge's lateral motion after ``settle`` (s). frequency_hz: the
    dominant frequency of the middle of the free edge (Hann-windowed spectrum, resolution
    1 / (duration - settle)); amplitude_m: half its peak-to-peak excursion; reduced_frequency
    f L / U; wave_speed_m_s: the phase speed of that frequency along the flag's midline (its
    phase against distance from the pole, fitted over the outer three quarters); ripple (m):
    the seed of the instability (0: a perfectly flat flag, which stays flat); scheme: the
    implicit integrator's (flag())."""
    from ..scene import Scene
    p = replace(p, pole=(0.0, 0.0, 0.0))
    scene = Scene("flutter", duration=duration, fps=fps)
    wind = scene.add(WindField("wind", [FlowPrimitive("uniform", axis=(1, 0, 0),
                                                      strength=speed)]))
    cloth = scene.add(flag("flag", p, ripple, scheme))
    scene.connect(Aerodynamics("wind-flag", wind, cloth, AeroParams(), mode="one-way"))
    scene.primary = wind
    fr = scene.simulate().frames["flag"]
    t, pts = np.asarray(fr["t"]), np.asarray(fr["points"])
    keep = t >= settle
    mid = pts[keep][:, (p.nv // 2) * p.nu + np.arange(p.nu)]  # root to free edge
    y = mid[:, :, 1] - mid[:, :, 1].mean(axis=0)
    edge = y[:, -1]
    spectrum = np.abs(np.fft.rfft(edge * np.hanning(len(edge))))
    freqs = np.fft.rfftfreq(len(edge), 1.0 / fps)
    f = float(freqs[1:][np.argmax(spectrum[1:])])
    phase = np.unwrap(np.angle(np.exp(-2j * np.pi * f * t[keep]) @ y))
    x = mid[0, :, 0] - mid[0, 0, 0]
    outer = slice(p.nu // 4, p.nu)
    k = -np.polyfit(x[outer], phase[outer], 1)[0]  # rad/m, positive for waves going downwind
    return {"frequency_hz": f, "amplitude_m": 0.5 * float(np.ptp(edge)),
            "amplitude_over_length": 0.5 * float(np.ptp(edge)) / p.width,
            "reduced_frequency": f * p.width / speed,
            "wave_speed_m_s": float(2 * np.pi * f / k) if k else float("nan"),
            "edge_rms_m": float(edge.std()), "length_m": p.width, "speed_m_s": speed}
