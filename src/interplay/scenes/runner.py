"""A motion-captured runner in a tee-shirt and sweat pants (the paper's Figure 5, SPEC 4's
clothing row), coupled one-way: the clip drives the body; the garments follow it, kept
outside its skinned surface (interactions/skin_contact.py) and apart from themselves
(interactions/mesh_contact.SelfContact).

The body is the CMU jog (``clip``) played by a MocapFigure, drawn as its skinned body surface
(geometry/body_surface.py). The garments are cut to that body (geometry/garment.py), dressed
on it before t = 0 (systems/garments.dress: the skin moves from the A-pose they were cut in
to the clip's first pose), and certify themselves at every output frame (systems/garments:
cloth-body triangle intersections, penetration, self-intersections, stretch). Without the
clip the runner is a keyframed run (``keyframed_run``, a BVH written from a few sine
harmonics of a running gait), and the scene says so.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry.body_surface import SurfaceParams, figure_surface
from ..geometry.clearance import ClearanceParams
from ..geometry.garment import PANTS_FIT, Fit, join, network, sweatpants, tee
from ..interactions.mesh_contact import MeshContactParams, SelfContact
from ..interactions.skin_contact import PosedSkin, SkinContact, SkinContactParams
from ..outputs.render.camera import TrackingCamera
from ..params import param
from ..scene import Scene
from ..systems.garment_layers import Layers
from ..systems.garments import dress
from ..systems.mocap import MocapFigure, check_clip, clip_path
from .contract import SceneSpec


# m: the gap the clip's hands and forearms keep off her trunk and thighs. They swing past the
# hips over the tee's hem and the pants' waist, two layers each kept the skin contact's
# thickness (5 mm) off both surfaces: 2 cm, and the hem's folds as much again. Measured on the
# CMU jog: 2 cm left the hands crossing the hem in 7 of 43 frames, 3 cm in 4, 4 cm in none
# (docs/clothing.md)
ARM_ROOM = 0.04
# m: the gap her legs keep off each other. Two layers of pants between the thighs, each kept
# 5 mm off the skin and 8 mm off the other: at 1 cm the guard against crossings (systems/
# garment_layers.Layers.guard) held them pinched there and the left leg's springs strained
# 2.7x; at 2 cm 1.2x at worst (docs/clothing.md)
LEG_ROOM = 0.02
# s: dressing moves the skin from the A-pose to the first pose while the garments follow, no
# new crossing let through; carried there at once by the skin's weights they crossed
# themselves 553 times, and carried through 40 poses between with the guard on, they were
# held in zones 5 cm off where the weights put them, and the settle could not relax them
DRESS_S = 0.4


@dataclass(frozen=True)
class RunnerParams:
    """clip: a BVH clip in the mocap folder ("" or absent: the keyframed run); clearance: the
    gaps its limbs keep on our body (geometry/clearance.py); skin: the body surface; tee,
    pants: how each garment is cut; contact: cloth on skin (two relimits and two final limits
    that may bring the cloth to 2 mm off the skin: the tee within 5% in every frame, at
    0.78-0.86x the speed of one of each at the thickness, whose tee reaches 8.7%;
    docs/clothing.md);
    self_thickness (m): the garments' contact skin against themselves (0: no
    self-collision); cloth_dt (s): the cloth's step, which is the coupling step (the skin
    contact resolves every step); lg_iterations: the cloth solver's iterations per step;
    dress_s (s): dressing by moving the skin from the A-pose to the first frame's pose (0:
    the garments carried there by the skin's weights at once), settle_s (s): then settling
    on the still body, before t = 0."""
    clip: str = param("cmu_02_03_run.bvh", check=check_clip,
                      doc="a BVH clip in the mocap folder or a path; empty: keyframes")
    clearance: ClearanceParams = ClearanceParams(arms=ARM_ROOM, legs=LEG_ROOM)
    skin: SurfaceParams = SurfaceParams()
    tee: Fit = Fit(spacing=0.016)
    pants: Fit = replace(PANTS_FIT, spacing=0.016)
    contact: SkinContactParams = SkinContactParams(final_limits=2, final_gap=0.002, relimits=2)
    self_thickness: float = param(0.0, "m", ge=0.0, le=0.05)
    layers: float = param(0.008, "m", ge=0.0, le=0.02, doc="0: the layers not held apart")
    cloth_dt: float = param(1.0 / 240.0, "s", ge=1e-5, le=0.02)
    lg_iterations: int = param(10, "iterations", ge=1, le=500)
    dress_s: float = param(DRESS_S, "s", ge=0.0, le=10.0)
    settle_s: float = param(0.4, "s", ge=0.0, le=10.0)


#: the limbs each garment is worn over (geometry.body_surface.LIMBS)
COVERS = {"tee": ("trunk", "l_arm", "r_arm"), "pants": ("trunk", "l_leg", "r_leg")}
TEE_COLOR = (0.62, 0.06, 0.05)  # linear RGB: a red tee
PANTS_COLOR = (0.10, 0.11, 0.14)  # charcoal fleece


def keyframed_run(path, duration: float = 2.0, cadence: float = 2.8, speed: float = 3.2,
                  fps: float = 120.0) -> None:
    """Write a BVH of a keyframed run (CMU joint names, lengths in cm, y up, z forward): the
    root moves forward at ``speed`` (m/s) and bobs at the step rate; hips, knees, ankles and
    arms swing as the first harmonic of a running gait at ``cadence`` steps per second (the
    stride at half that), the elbows bent, the spine leaning 8 deg forward."""
    names = ["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg",
             "RightFoot", "RightToeBase", "Spine", "Spine1", "Head", "LeftShoulder", "LeftArm",
             "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm",
             "RightHand"]
    off = {"Hips": (0, 0, 0), "LeftUpLeg": (9, 0, 0), "LeftLeg": (0, -43, 0),
           "LeftFoot": (0, -43, 0), "LeftToeBase": (0, -6, 14), "Spine": (0, 10, 0),
           "Spine1": (0, 20, 0), "Head": (0, 30, 0), "LeftShoulder": (4, 26, 0),
           "LeftArm": (14, 0, 0), "LeftForeArm": (0, -31, 0), "LeftHand": (0, -25, 0)}
    for k in list(off):
        if k.startswith("Left"):
            x, y, z = off[k]
            off[k.replace("Left", "Right")] = (-x, y, z)
    parent = {"LeftUpLeg": "Hips", "LeftLeg": "LeftUpLeg", "LeftFoot": "LeftLeg",
              "LeftToeBase": "LeftFoot", "Spine": "Hips", "Spine1": "Spine", "Head": "Spine1",
              "LeftShoulder": "Spine1", "LeftArm": "LeftShoulder", "LeftForeArm": "LeftArm",
              "LeftHand": "LeftForeArm"}
    for k in list(parent):
        if k.startswith("Left"):
            parent[k.replace("Left", "Right")] = parent[k].replace("Left", "Right")
    children = {n: [c for c in names if parent.get(c) == n] for n in names}

    def write(n, depth):
        pad = "  " * depth
        lines = [f"{pad}{'ROOT' if n == 'Hips' else 'JOINT'} {n}", f"{pad}{{",
                 f"{pad}  OFFSET {off[n][0]} {off[n][1]} {off[n][2]}",
                 f"{pad}  CHANNELS " + ("6 Xposition Yposition Zposition " if n == "Hips"
                                        else "3 ") + "Zrotation Xrotation Yrotation"]
        for c in children[n]:
            lines += write(c, depth + 1)
        if not children[n]:
            lines += [f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET 0 -5 0", f"{pad}  }}"]
        return lines + [f"{pad}}}"]

    t = np.arange(0.0, duration, 1.0 / fps)
    w = 2 * np.pi * cadence / 2.0  # stride frequency (rad/s)
    rows = []
    for tk in t:
        ph = w * tk
        ang = {n: (0.0, 0.0, 0.0) for n in names}
        for side, sgn in (("Left", 1.0), ("Right", -1.0)):
            p = ph + (0.0 if sgn > 0 else np.pi)
            ang[f"{side}UpLeg"] = (0.0, -(10 + 35 * np.sin(p)), 0.0)  # flexion forward
            ang[f"{side}Leg"] = (0.0, 45 + 40 * np.sin(p - 1.2), 0.0)  # knee flexes back
            ang[f"{side}Foot"] = (0.0, -10 * np.sin(p), 0.0)
            ang[f"{side}Arm"] = (sgn * 75.0, 30 * np.sin(p + np.pi), 0.0)  # arms down, swing
            ang[f"{side}ForeArm"] = (0.0, -80.0, 0.0)  # elbows bent forward
        ang["Spine"] = (0.0, 8.0, 6 * np.sin(ph))
        root = (0.0, 95.0 + 3.0 * np.cos(2 * ph), 100.0 * speed * tk)
        vals = list(root)
        for n in names:
            z, x, y = ang[n]
            vals += [z, x, y]
        rows.append(" ".join(f"{v:.4f}" for v in vals))
    text = ["HIERARCHY"] + write("Hips", 0) + ["MOTION", f"Frames: {len(t)}",
                                               f"Frame Time: {1.0 / fps:.6f}"] + rows
    with open(path, "w") as f:
        f.write("\n".join(text) + "\n")


def _runner(params: RunnerParams):
    """(the runner MocapFigure, where its motion comes from)."""
    path = clip_path(params.clip) if params.clip else None
    if path is not None and path.exists():
        return (MocapFigure("runner", path, ground=0.0, units=None,
                            clearance=params.clearance), f"clip {params.clip}")
    import tempfile
    from pathlib import Path
    tmp = Path(tempfile.mkdtemp(prefix="interplay-run-")) / "keyframed_run.bvh"
    keyframed_run(tmp)
    return (MocapFigure("runner", tmp, ground=0.0, units="cm", skip_tpose=False,
                        clearance=params.clearance),
            "keyframed run (no clip in the mocap folder)")


_DRESSED: dict = {}  # (params, step, motion) -> the dressed garments' state, per process


def _dressed(runner, params: RunnerParams, h: float, source: str):
    """(skin, garment network, tee, pants, dressing report) for this runner: cut, joined and
    dressed on the clip's first pose. The cutting and dressing (tens of seconds) are done
    once per process for the same parameters; a rebuild restores the dressed state."""
    key = (repr(params), h, source)
    if key not in _DRESSED:
        surface = figure_surface(runner, params.skin)
        pants = sweatpants(surface, params.pants)
        shirt = tee(surface, params.tee, over=pants)
        clothes = join("clothes", pants, shirt)
        net = _network(clothes, params, h, surface)
        runner.set_time(0.0)
        pos, R = runner.part_poses()
        selfc = None
        if params.self_thickness > 0:
            selfc = SelfContact("clothes-self", net, MeshContactParams(
                thickness=params.self_thickness, friction=0.3, depth=0.01))
            selfc.prepare(h)
        # dressing slides the fabric into place: little friction, so that what an arm folds
        # in against the side slips out rather than being held and stretched
        dressed = dress(net, surface, pos, R, params.dress_s, params.settle_s, h,
                        replace(params.contact, friction=0.05), selfc,
                        skin_velocity=PosedSkin(runner, surface).now()[1],
                        tether=params.contact.tether)
        _DRESSED.clear()
        _DRESSED[key] = (surface, clothes, shirt, pants, net.x.copy(), net.v.copy(), dressed)
    surface, clothes, shirt, pants, x, v, dressed = _DRESSED[key]
    net = _network(clothes, params, h, surface)
    net.x[:], net.v[:] = x, v
    return surface, net, shirt, pants, dict(dressed)


def _network(clothes, params, h, surface):
    colors = np.empty((len(clothes.vertices), 3))
    colors[clothes.groups["pants"]] = PANTS_COLOR
    colors[clothes.groups["tee"]] = TEE_COLOR
    # a spring caught in a pinch (an arm against the side) may strain far locally without
    # the cloth being unstable; the certificates report the stretch frame by frame
    net = network(clothes, dt=h, lg_iterations=params.lg_iterations, color=colors,
                  strain_limit=20.0)
    if params.layers > 0:
        net.layers = Layers(net, surface, params.layers, covers=COVERS)
    return net


def build(coupling: str = "one-way", duration: float = 1.4, fps: float = 30.0,
          integrator: str | None = None, dt: float | None = None,
          params: RunnerParams = RunnerParams()) -> Scene:
    """The scene; dt overrides the cloth's step (s)."""
    h = params.cloth_dt if dt is None else float(dt)
    scene = Scene("runner", duration=duration, fps=fps, coupling_dt=h)
    runner, source = _runner(params)
    surface, net, shirt, pants, dressed = _dressed(runner, params, h, source)
    runner.wear_skin(surface)
    skin = PosedSkin(runner, surface)
    selfc = None
    if params.self_thickness > 0:
        selfc = SelfContact("clothes-self", net, MeshContactParams(
            thickness=params.self_thickness, friction=0.3, depth=0.01))
    scene.add(runner)
    scene.add(net)
    contact = SkinContact("clothes-body", runner, net, surface, params.contact, mode=coupling)
    scene.connect(contact)
    if selfc is not None:
        scene.connect(selfc)
    net.watch(skin)
    scene.primary = runner
    scene.meta = {"motion": source, "dressing": dressed,
                  "vertices": {"tee": int(len(shirt.vertices)),
                               "pants": int(len(pants.vertices)),
                               "skin": int(len(surface.vertices0))},
                  "garments": {g.name: {"mass_kg": g.mass, "fabric": g.fabric.name,
                                        "sizes": g.sizes} for g in (shirt, pants)},
                  # the abduction the clip gained so its limbs clear each other on our body
                  "clearance_deg": {k: {"max": round(float(np.degrees(a.max())), 1),
                                        "mean": round(float(np.degrees(a.mean())), 1)}
                                    for k, a in runner.clearance.items()}}
    scene.runner_contact = contact
    return scene


def figures(result) -> dict:
    """The certificates (per frame in diagnostics.clothes.certificates) and the tunnelling
    margin, in the summary's figures."""
    cert = result.diagnostics.get("clothes", {}).get("certificates", {})
    out = {k: v for k, v in cert.items() if k != "per_frame"}
    out["motion"] = result.meta.get("motion")
    out["vertices"] = result.meta.get("vertices")
    out["clearance_deg"] = result.meta.get("clearance_deg")
    return out


SPEC = SceneSpec(
    "runner", "a motion-captured runner in a tee-shirt and sweat pants, the garments colliding "
    "with her skinned body (one-way)", build, RunnerParams, couplings=("one-way",),
    # the clip is 1.43 s long
    duration=1.4, fps=30.0,
    camera=TrackingCamera("runner", offset=(0.6, -3.4, 0.0), target_offset=(0.0, 0.0, 0.0),
                          axes=(1.0, 1.0, 0.0), hold=(0.0, 0.0, 0.95), fov_deg=36.0,
                          smooth_s=0.15),
    key_time=0.7, figures=figures, heavy=True)
