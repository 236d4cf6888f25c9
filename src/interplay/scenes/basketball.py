"""A basketball through a net (the paper's Figure 2): a rigid ball falls through a spring-mass
net hung from a fixed rim, coupled two-way, one-way or hybrid (a damping field stand-in)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError
from ..geometry.net import NetParams, basketball_net
from ..geometry.setpieces import hoop
from ..interactions.contact import ContactParams, SphereCordContact, SpherePlaneContact
from ..interactions.standins import DampingField, DampingFieldParams
from ..outputs.render.camera import Camera
from ..scene import Scene
from ..systems.base import GRAVITY
from ..systems.colliders import set_pieces
from ..systems.rigid import Sphere, SphereParams
from ..systems.static import StaticPlane
from .contract import SceneSpec
from ..params import param


@dataclass(frozen=True)
class BallParams(SphereParams):
    """The ball: a regulation basketball, hollow shell. position m, velocity m/s, spin rad/s."""
    position: tuple = param((0.02, 0.0, 3.65), "m", ge=-100.0, le=100.0,
                           doc="centre at t = 0 (x, y, z)")
    # 100 m/s moves the ball 1 mm per net step of 1e-5 s: faster tunnels through the cords
    velocity: tuple = param((0.3, 0.0, -1.0), "m/s", ge=-100.0, le=100.0,
                           doc="velocity at t = 0")
    spin: tuple = param((0.0, 0.0, 0.0), "rad/s", ge=-1000.0, le=1000.0,
                       doc="angular velocity at t = 0")


@dataclass(frozen=True)
class BasketballParams:
    ball: BallParams = BallParams()
    net: NetParams = NetParams()
    # nylon cord on a rubber ball; light contact damping so impacts do not spike the force
    contact: ContactParams = ContactParams(stiffness=2.0e3, damping=0.5, friction=1.0)
    # floor: stiff enough to stop a 7 m/s ball within ~2 cm; damping for restitution ~0.75
    floor: ContactParams = ContactParams(stiffness=1.0e5, damping=40.0, friction=0.6,
                                         eps=0.05, thickness=0.0)
    field: DampingFieldParams = DampingFieldParams()
    settle: bool = param(True, doc="let the net sag to rest under gravity before t = 0")
    # s: forces are exchanged every coupling_dt; the net sub-cycles the ball contact inside it.
    # Set it to the net's dt for strict lock step (the reference).
    coupling_dt: float = param(1e-3, "s", ge=1e-7, le=0.1, doc="force exchange step")
    # "cords": the specialised sphere-cord contact (sub-cycled in the net's kernel); "mesh":
    # the general MeshContact between the ball's icosphere (mesh_subdivisions) and the cords as
    # segments, exchanged every net step (lock step: it is not sub-cycled), docs/collision.md
    contact_model: str = param("cords", choices=("cords", "mesh"), doc="ball-net contact")
    mesh_subdivisions: int = param(3, "-", ge=0, le=6,
                                   doc="icosphere subdivisions of the ball (3: 642 vertices)")


FIT_TIME = 0.6  # s: the ball has left the net and not yet reached the floor
CHECKPOINTS = [0.2, 0.3, 0.4, 0.5, 0.6]  # s, the ball's state is reported at these times


def seams(verts) -> np.ndarray:
    """(n,3) linear RGB per vertex of the ball: orange leather with a basketball's black seams
    (two great circles and two rings), so its spin shows."""
    n = verts / np.linalg.norm(verts, axis=1, keepdims=True)
    seam = (np.abs(n[:, 0]) < 0.06) | (np.abs(n[:, 2]) < 0.06) | (np.abs(np.abs(n[:, 1]) - 0.72)
                                                                  < 0.05)
    return np.where(seam[:, None], (0.06, 0.04, 0.03), (0.80, 0.33, 0.08))


def build(coupling: str = "two-way", duration: float = 1.5, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: BasketballParams = BasketballParams()) -> Scene:
    """The scene. integrator and dt override the net's (dt in s)."""
    net_p = params.net
    if integrator is not None:
        net_p = replace(net_p, integrator=integrator)
    if dt is not None:
        net_p = replace(net_p, dt=dt)
    b = params.ball
    scene = Scene("basketball", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    ball = scene.add(Sphere("ball", SphereParams(b.radius, b.mass, b.shell, b.dt),
                            subdivisions=params.mesh_subdivisions, position=b.position,
                            velocity=b.velocity, angular_velocity=b.spin))
    net = scene.add(basketball_net(net_p))
    if params.settle:
        net.settle()
    floor = scene.add(StaticPlane("floor", height=0.0, size=15.0, color=(0.62, 0.44, 0.26),
                                  material="wood"))
    # the hoop the net hangs from (Figure 2): rim, backboard and pole, drawn; the ball's
    # default path stays inside the rim and clear of the board, so no contact joins them
    for piece in set_pieces(hoop((0.0, 0.0, net_p.rim_height), net_p.rim_radius)):
        scene.add(piece)
    ball.color = seams(ball.surface[0])
    net.color = (0.95, 0.95, 0.93)
    field_ = DampingField(net.x, net.segments(), params.field, thickness=net_p.cord_radius)
    contact = replace(params.contact, thickness=net_p.cord_radius)
    if params.contact_model == "mesh":
        from ..interactions.mesh_contact import MeshContact, MeshContactParams
        scene.coupling_dt = net.dt
        # the sphere-cord contact's law (its stiffness, damping, friction), with MeshContact's
        # skin: without it a cord at the thickness's edge flickers in and out of contact and
        # loses its stick spring, and the ball leaves the net 20 cm ahead by t = 0.6 s
        mp = MeshContactParams(thickness=contact.thickness, friction=contact.friction,
                               eps=contact.eps, stiffness=contact.stiffness,
                               damping=contact.damping, constraint=contact.constraint)
        scene.connect(MeshContact("ball-net", ball, net, mp, mode=coupling, standin=field_))
    elif params.contact_model == "cords":
        scene.connect(SphereCordContact("ball-net", ball, net, contact, mode=coupling,
                                        standin=field_))
    else:
        raise ParameterError(f"basketball: contact_model must be 'cords' or 'mesh', got "
                             f"{params.contact_model!r}")
    scene.connect(SpherePlaneContact("ball-floor", ball, floor, params.floor))
    scene.primary = ball
    scene.checkpoints = {"ball": CHECKPOINTS}
    scene.meta = {"rim_center": (0.0, 0.0, net_p.rim_height), "rim_radius": net_p.rim_radius}
    return scene


def exit_figures(result) -> dict:
    """The ball as it leaves the net (the end of the first contact period): its velocity and
    speed, and the speed free flight would have given it then (v(t) = v(0) + g t)."""
    it = result.main_interaction
    stats = next(s for s in result.interaction_stats() if s["name"] == it["name"])
    if not stats["contact_s"] or result.primary not in result.tracks:
        return {}
    t_exit = stats["contact_s"][1]
    _, v = result.state_at(result.primary, t_exit)
    _, v0 = result.state_at(result.primary, 0.0)
    free = v0[:3] + GRAVITY * t_exit
    return {"exit time (s)": t_exit, "exit velocity (m/s)": v[:3].tolist(),
            "exit speed (m/s)": float(np.linalg.norm(v[:3])),
            "free-flight speed then (m/s)": float(np.linalg.norm(free))}


SPEC = SceneSpec(
    "basketball", "a basketball falls through a spring-mass net (two-way, one-way or hybrid)",
    build, BasketballParams, couplings=("two-way", "one-way", "hybrid"), duration=1.5, fps=60.0,
    integrators=("explicit", "implicit", "localglobal"), standin="field", fit_time=FIT_TIME,
    # the net and the ball in it fill the frame (Figure 2), a little below the rim
    camera=Camera((1.25, -2.55, 3.35), (0.0, 0.0, 3.05), 24.0), key_time=0.33,
    figures=exit_figures, warm_time=0.3)  # the ball within the net's reach from 0.23 s
