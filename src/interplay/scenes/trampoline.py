"""A gymnast bouncing on a trampoline (SPEC 4; the paper's most complex two-way example).

The trampoline is a spring-mass bed hung from a rigid frame by springs around its edge
(geometry/trampoline.py: a competition bed of 4.28 x 2.14 m on 108 coil springs, 20 kg with
its springs, as the paper's). The gymnast (64.38 kg, 1.70 m) is the 17-segment figure under a
bounce controller (control/bounce.py): layout in the air, legs prepared for landing, an absorb
and a thrust timed to the bed's recoil, the arms swinging up with it, and foot placement that
keeps her over the bed's centre. Every segment collides with the bed's webbing through the
generic rigid-parts contact, sub-cycled in the bed's substeps (interactions/part_contact.py):
two-way, the interaction changes both systems' motion a lot. The two-way run is too slow to
tune by hand, so the controller's parameters were found by simulated annealing on it
(``interplay tune trampoline``; the defaults are that search's output, docs/trampoline.md).

Hybrid (beyond the paper): the bed is replaced for the gymnast by vertical spring-dampers
under her contact points fitted to the bed's load-deflection (interactions/bed_springs.py),
and her recorded motion then drives the bed one-way.

The frame, the floor and the springs are drawn (set pieces and the bed's cords); the figure
also has MuJoCo's floor under the trampoline, so a bed too soft to hold her lands her on it,
and the summary says so.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..control.bounce import BounceBalance, BounceParams, controller
from ..control.bounce_modes import GROWTH
from ..control.bounce_search import BASIN, BOUNCE
from ..outputs.render.camera import Camera
from ..geometry.anthropometry import BodyParams
from ..geometry.trampoline import BedParams, build_bed, frame_mesh
from ..interactions.bed_springs import BedSprings, BedSpringsParams
from ..interactions.part_contact import PartContact, PartContactParams
from ..scene import Scene
from ..systems.colliders import StaticMesh
from ..systems.figure import Figure, FigureParams
from ..systems.figure_model import EnvironmentParams
from ..systems.relaxation import relax
from ..systems.springmass import SpringNetwork, Springs
from ..systems.static import StaticPlane
from ..params import param
from .contract import SceneSpec


BED_COLOR = (0.05, 0.05, 0.06)  # the black webbing of a competition bed
FRAME_COLOR = (0.1, 0.25, 0.6)  # painted steel (linear RGB)
CENTRE_ZONE = (1.0, 0.5)  # m: half extents (x, y) of the bed's central zone she must keep to


@dataclass(frozen=True)
class GymnastParams:
    """The gymnast: mass (kg), height (m) (the paper's Table I gymnast: 64.38 kg); drop (m):
    her soles' height above the bed at the start (dropped from rest at her first apex);
    air_density (kg/m^3) of the drag on her segments."""
    mass: float = param(64.38, "kg", ge=10.0, le=500.0)
    height: float = param(1.70, "m", ge=0.5, le=3.0)
    drop: float = param(1.0, "m", ge=0.0, le=10.0, doc="soles above the bed at the start")
    air_density: float = param(1.2, "kg/m^3", ge=0.0, le=100.0)


@dataclass(frozen=True)
class TrampolineParams:
    """coupling_dt (s): the step at which the gymnast and the bed exchange forces (the
    figure's own step)."""
    bed: BedParams = BedParams()
    gymnast: GymnastParams = GymnastParams()
    bounce: BounceParams = BounceParams()
    # the faces as well as the edges: a foot is narrower than the bed's facets; her feet's
    # edges rounded by 2 cm (soft tissue): a sharp box's normal flips at its edges, and a
    # sharp foot on the bed turned a nanometre of the drop into 0.02 kg m^2/s at takeoff; the
    # deepest point along a bed edge to 4e-9 of it (at 1e-3 its steps did the same); a penalty
    # law, without the constraint term (which switches with the sign of the relative
    # acceleration under her feet): the controller searched on it bounces 4-5 times from every
    # drop within 2 mm of the scene's, and 2-3 times with the term (docs/trampoline.md)
    contact: PartContactParams = PartContactParams(faces=True, rounding=0.02, golden_steps=40,
                                                   constraint=False)
    standin: BedSpringsParams = BedSpringsParams()
    coupling_dt: float = param(1e-3, "s", gt=0.0, le=0.01)


#: the share of symplectic Euler's stability limit, h^2 w^2 + 2 h c/m < 4, that the bed's own
#: springs and damping may use; the rest is the sub-cycled contact's (w h = 1/3, critically
#: damped: 1/9 + 4/3 of it)
EXPLICIT_SHARE = 2.5


def bed(p: BedParams, integrator: str = "explicit", dt: float | None = None) -> SpringNetwork:
    """The bed and its frame springs as one network (frame points fixed), settled under its
    own weight; the frame springs are drawn as cords. An explicit step past the bed's bound
    (with its damping and the contact's share) is refused before anything runs."""
    b = build_bed(p)
    # a strap stretched by half is torn (numbers blew up); a frame spring is made to stretch
    # (its strain counts only when its rest length is positive): it cannot get longer than
    # from the rail to the floor and back up, however soft
    reach = (p.gap + 2.0 * p.height) / (b.rest[b.kind == 3][0] if b.rest[-1] > 0 else np.inf)
    net = SpringNetwork("trampoline", b.x, b.masses,
                        Springs(b.i, b.j, b.rest, b.k, b.tension_only), dt=dt or p.dt,
                        integrator=integrator, mass_damping=p.mass_damping,
                        stiffness_damping=p.stiffness_damping, fixed=b.frame,
                        triangles=b.triangles, cords=b.frame_springs,
                        strain_limit=max(0.5, float(reach)),
                        cord_radius=0.012, color=BED_COLOR, stability_share=EXPLICIT_SHARE,
                        dt_key="bed.dt", step_cure="less stretch or stiffness_damping")
    net.bed_points, net.rest_height = b.bed_points, p.height
    # 1 s of damped relaxation, not the exact rest (1e-8 m from it): the shipped bounce
    # controller was tuned from this state, and its bounces change with that difference
    # (docs/trampoline.md, "A controller without margin")
    net.settle(relaxed=1.0)
    return net


def pressed_points(net: SpringNetwork, half: float = 0.15) -> np.ndarray:
    """Indices of the bed's grid points within ``half`` (m) of its centre in x and y."""
    bedpts = net.x[:net.bed_points]
    return np.flatnonzero((np.abs(bedpts[:, 0]) <= half) & (np.abs(bedpts[:, 1]) <= half))


def press(net: SpringNetwork, load: float, half: float = 0.15, seconds: float = 3.0,
          damping: float = 20.0) -> float:
    """Settle the bed ``net`` under a downward load (N) spread evenly over the grid points
    within ``half`` (m) of its centre in x and y (two feet side by side: a 0.3 m square), by
    heavily damped backward-Euler steps; returns the depression (m) of its lowest point below
    the rest plane. The network's own state is left at that rest."""
    sel = pressed_points(net, half)
    saved = net.fext.copy()
    net.fext[:] = 0.0
    net.fext[sel, 2] = -load / len(sel)
    relax(net, seconds, 2e-3, damping, 2000)
    net.fext[:] = saved
    return float(net.rest_height - net.x[:net.bed_points, 2].min())


def load_deflection(p: BedParams, loads) -> np.ndarray:
    """(loads (N), depressions (m)) of the bed under each load (``press``), in order."""
    net = bed(p)
    return np.array([(f, press(net, f)) for f in loads])


def gymnast(p: GymnastParams, bounce: BounceParams, bed_height: float) -> Figure:
    """The gymnast at rest in the air over the bed's centre, her soles ``drop`` above it."""
    env = EnvironmentParams(floor=0.0, air_density=p.air_density)
    fp = FigureParams(body=BodyParams(p.mass, p.height), environment=env,
                      position=(0.0, 0.0, bed_height + p.drop))
    ctrl = controller(bounce)
    fig = Figure("gymnast", fp, ctrl, feedback=None)
    fig.feedback = BounceBalance(bounce, fig.joints)
    return fig


def build(coupling: str = "two-way", duration: float = 20.0, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: TrampolineParams = TrampolineParams()) -> Scene:
    scene = Scene("trampoline", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    scene.add(StaticPlane("floor", height=0.0, size=5.0))
    fv, ft = frame_mesh(params.bed)
    frame = scene.add(StaticMesh("frame", fv, ft))
    frame.color = FRAME_COLOR
    tramp = scene.add(bed(params.bed, integrator or "explicit", dt))
    fig = scene.add(gymnast(params.gymnast, params.bounce, params.bed.height))
    scene.primary = fig
    # the stand-in's springs begin where the resting bed's top is: its centre plus the skin
    centre = tramp.x[:tramp.bed_points][np.argmin(np.hypot(*tramp.x[:tramp.bed_points, :2].T))]
    standin = BedSprings(params.standin, fig, centre[2] + params.contact.thickness)
    scene.connect(PartContact("gymnast-bed", fig, tramp, params.contact, mode=coupling,
                              standin=standin))
    scene.meta = {"bed_height": params.bed.height, "centre_zone": list(CENTRE_ZONE),
                  "bed_half": [params.bed.length / 2, params.bed.width / 2]}
    return scene


def figures(result) -> dict:
    """The scene's key figures for summary.json: good bounces in a row, each flight's height
    and each landing's bed depression, the landings' offsets from the centre, the flight
    heights' variation after the second bounce ((max - min) / mean), and named warnings (she
    reached the floor: the bed is too soft; she fell or left the central zone)."""
    from ..control.bounce_search import TILT_FALLEN, TILT_GOOD, record_of, rises, score
    height = result.meta["bed_height"]
    rec, depressions, lowest, where = record_of(result, height)
    _, metrics = score(rec, tuple(result.meta["centre_zone"]))
    good = metrics["bounces"]
    rise = rises(rec)
    later = rise[2:good]
    out = {"bounces": good, "landings": len(rec.landings),
           "flight_heights_m": [round(float(r), 4) for r in rise],
           "depressions_m": [round(d, 4) for d in depressions],
           "landing_offsets_m": [[round(x, 3), round(y, 3)] for _, x, y, _, _ in rec.landings],
           "flight_height_variation": (float((later.max() - later.min()) / later.mean())
                                       if len(later) > 1 else None),
           "lowest_point_m": round(lowest, 4), "warnings": []}
    half = result.meta.get("bed_half", (np.inf, np.inf))
    if rec.floor and (abs(where[0]) > half[0] or abs(where[1]) > half[1]):
        # the frame and its springs are drawn, not collided: off the bed's edge she falls
        out["warnings"].append(
            f"she slid off the bed onto the floor at ({where[0]:.2f}, {where[1]:.2f}) m, past "
            f"its edge (the frame and its springs do not hold her: they are drawn only)")
    elif rec.floor:
        out["warnings"].append(
            f"bed too soft: the gymnast reached the floor (her lowest point {lowest:.3f} m, the "
            f"bed's rest plane {height} m up); raise bed.spring_tension or bed.stretch")
    if good < len(rec.landings):
        t, x, y, _, tilt = rec.landings[good]
        why = (f"tilted {tilt:.2f} rad" if tilt > TILT_GOOD else
               f"landed at ({x:.2f}, {y:.2f}) m, outside the central zone")
        out["warnings"].append(f"bounce {good + 1} failed at t={t:.2f} s: {why}")
    elif rec.max_tilt > TILT_FALLEN:
        # every landing was upright, but after the last she did not take off again
        out["warnings"].append(
            f"she fell on the bed after landing {good} (pelvis tilted {rec.max_tilt:.2f} rad): "
            f"{good - 1} full bounces")
    return out


SPEC = SceneSpec(
    "trampoline", "a gymnast bounces on a spring-mass trampoline (two-way)", build,
    TrampolineParams, couplings=("two-way", "hybrid", "one-way"), duration=20.0, fps=60.0,
    integrators=("explicit",), searches=(BOUNCE, BASIN, GROWTH), figures=figures,
    camera=Camera((2.6, -7.6, 2.6), (0.0, 0.0, 1.8), 40.0), key_time=0.65, heavy=True,
    warm_time=0.5)  # she lands at 0.45 s
