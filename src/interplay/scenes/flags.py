"""Flags in the wind: several flags of different sizes and materials on poles, pinned along
the pole edge, in a gusty wind (one-way: the air does not feel the cloth)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..geometry import shapes
from ..interactions.aero import AeroParams, Aerodynamics
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


def wind_field(w: GustyWind) -> WindField:
    h = math.radians(w.heading)
    along, across = (math.cos(h), math.sin(h), 0.0), (-math.sin(h), math.cos(h), 0.0)
    return WindField("wind", [
        FlowPrimitive("uniform", axis=along, strength=w.speed, gust=w.gust,
                      gust_period=w.gust_period),
        FlowPrimitive("uniform", axis=across, strength=w.cross, gust=1.0 if w.cross else 0.0,
                      gust_period=1.7 * w.gust_period, phase=2.0)])


def flag(name: str, p: FlagParams) -> SpringNetwork:
    """A flag streaming along +x from its pole in the xz plane, pinned along the pole edge."""
    top = np.asarray(p.pole, float) + [0.0, 0.0, p.pole_height]
    x, tris = shapes.grid(p.width, p.height, p.nu, p.nv, origin=top, u=(1, 0, 0), v=(0, 0, -1))
    net = SpringNetwork.from_mesh(name, x, tris, p.density * p.width * p.height, p.stretch,
                                  p.shear, p.bend, dt=p.dt, integrator=p.integrator,
                                  mass_damping=p.mass_damping,
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
    scene.add(StaticPlane("ground", height=0.0, size=8.0))
    wind = scene.add(wind_field(params.wind))
    for name in ("cotton", "nylon", "canvas"):
        p = getattr(params, name)
        if integrator is not None:
            p = replace(p, integrator=integrator)
        if dt is not None:
            p = replace(p, dt=dt)
        cloth = scene.add(flag(name, p))
        pv, pt = shapes.pole(p.pole_height + 0.1)
        scene.add(StaticMesh(f"{name}-pole", pv + np.asarray(p.pole, float), pt))
        scene.connect(Aerodynamics(f"wind-{name}", wind, cloth, params.aero, mode="one-way"))
    scene.primary = wind
    return scene


SPEC = SceneSpec(
    "flags", "flags of cotton, nylon and canvas on poles in a gusty wind (one-way)", build,
    FlagsParams, couplings=("one-way",), duration=4.0, fps=60.0,
    integrators=("explicit", "implicit", "localglobal"))
