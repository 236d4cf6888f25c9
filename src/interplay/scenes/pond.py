"""Balls floating in a pond (SPEC 4): rigid balls of different densities dropped into a small
pond with a sloping shore, coupled two-way with the water: the light balls bob and float and
drift on the waves they make, the dense one sinks to the bed with a larger splash.
One-way drives the water with balls that fell through it unhindered; hybrid floats them on a
still-water stand-in (buoyancy and drag below a flat surface) and then drives the water."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError
from ..geometry.basin import BasinParams, basin, banks
from ..interactions.buoyancy import BodyInWater, BuoyancyParams
from ..interactions.contact import ContactParams, SpherePlaneContact
from ..interactions.standins import ViscousDragField, ViscousDragFieldParams
from ..params import param
from ..scene import Scene
from ..outputs.render.camera import Camera
from ..systems.colliders import set_pieces
from ..systems.rigid import Sphere, SphereParams
from ..systems.static import StaticPlane
from ..systems.water import Water, WaterParams
from .contract import SceneSpec


@dataclass(frozen=True)
class BallsParams:
    """The first ``count`` entries of each tuple: radius (m), density (kg/m^3; water is 1000),
    x and y of the drop (m), drop height of the ball's bottom above the still surface (m).
    dt: the balls' step (s)."""
    count: int = param(5, "balls", ge=1, le=100)
    radius: tuple = param((0.07, 0.06, 0.05, 0.065, 0.055), "m", ge=1e-3, le=1.0, length=None)
    density: tuple = param((500.0, 300.0, 700.0, 850.0, 2500.0), "kg/m^3", ge=1.0, le=1e5,
                           length=None)
    x: tuple = param((-0.35, 0.3, -0.2, 0.35, 0.0), "m", ge=-1e3, le=1e3, length=None)
    y: tuple = param((0.25, 0.3, -0.35, -0.2, 0.0), "m", ge=-1e3, le=1e3, length=None)
    height: tuple = param((0.25, 0.4, 0.15, 0.3, 0.5), "m", ge=-100.0, le=1e3, length=None,
                          doc="drop height of each ball's bottom above the still surface")
    dt: float = param(1e-3, "s", ge=1e-9, le=0.1)

    def __post_init__(self):
        for key in ("radius", "density", "x", "y", "height"):
            if len(getattr(self, key)) < self.count:
                raise ParameterError(f"count={self.count} but {key} lists "
                                     f"{len(getattr(self, key))} values; give one per ball")


@dataclass(frozen=True)
class PondParams:
    basin: BasinParams = BasinParams(size_x=2.0, size_y=2.0, cells=128, depth=0.3, shore=0.3)
    water: WaterParams = WaterParams()
    balls: BallsParams = BallsParams()
    buoyancy: BuoyancyParams = BuoyancyParams()
    # the muddy flat bed at z = 0 under the sinking ball: stops it within ~1 cm, damping
    # ratio ~0.7 for a 1.7 kg ball (a ball does not bounce off a pond's bed)
    bed: ContactParams = ContactParams(stiffness=2.0e4, damping=250.0, friction=0.3, eps=0.05,
                                       thickness=0.0)
    # hybrid: still water at the basin's depth, damping fitted by eye to the two-way bobbing
    field: ViscousDragFieldParams = ViscousDragFieldParams(linear=2.0, quadratic=20.0,
                                                           density=1000.0)
    coupling_dt: float = param(2e-3, "s", ge=1e-7, le=0.1)


# linear RGB, one per ball: apart from each other, the water and the banks
BALL_COLORS = ((0.85, 0.38, 0.08), (0.95, 0.80, 0.12), (0.75, 0.12, 0.40), (0.90, 0.90, 0.88),
               (0.25, 0.25, 0.28))


def build(coupling: str = "two-way", duration: float = 4.0, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: PondParams = PondParams()) -> Scene:
    """The scene. dt overrides the water's largest step (s); the water has one integrator."""
    b, wp = params.balls, params.water
    n = int(b.count)
    for key in ("radius", "density", "x", "y", "height"):
        if not 1 <= n <= len(getattr(b, key)):
            raise ParameterError(f"pond: balls.count={n} but balls.{key} lists "
                                 f"{len(getattr(b, key))} values; give one per ball")
    if dt is not None:
        from dataclasses import replace
        wp = replace(wp, dt=dt)
    geo = basin(params.basin)
    scene = Scene("pond", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    water = scene.add(Water("water", geo.bed, geo.fluid, geo.depth, geo.spacing, geo.origin,
                            wp))
    # the water draws its own bed and shore; the grass banks around the basin meet its rim
    scene.add(set_pieces([banks(geo, "banks", 6.0)])[0])
    # the flat of the bed under the balls, as a collider (the water's bed mesh draws it)
    floor = scene.add(StaticPlane("bed", height=0.0, drawn=False))
    level = params.basin.depth
    field = ViscousDragFieldParams(**{**params.field.__dict__, "surface": level,
                                      "gravity": wp.gravity})
    balls = []
    for k in range(n):
        r, rho = b.radius[k], b.density[k]
        mass = rho * 4.0 / 3.0 * math.pi * r ** 3
        ball = scene.add(Sphere(f"ball{k}", SphereParams(radius=r, mass=mass, shell=False,
                                                         dt=b.dt),
                                position=(b.x[k], b.y[k], level + b.height[k] + r)))
        ball.color = BALL_COLORS[k % len(BALL_COLORS)]
        standin = ViscousDragField(field)
        scene.connect(BodyInWater(f"ball{k}-water", ball, water, params.buoyancy,
                                  mode=coupling, standin=standin))
        scene.connect(SpherePlaneContact(f"ball{k}-bed", ball, floor, params.bed))
        balls.append(ball)
    scene.primary = balls[0]
    scene.checkpoints = {bl.name: [1.0, 2.0, 3.0] for bl in balls}
    scene.meta = {"still_level": level, "densities": list(b.density[:n])}
    return scene


SPEC = SceneSpec(
    "pond", "balls of different densities float, bob and sink in a pond (two-way)", build,
    PondParams, couplings=("two-way", "one-way", "hybrid"), duration=4.0, fps=60.0,
    # from the bank, a little above: the pond and its balls fill the frame
    camera=Camera((1.1, -1.75, 1.05), (0.0, 0.0, 0.25), 45.0), key_time=0.7)
