"""The child on a swing (issue 16): a playground swing (a seat on two chains from a frame's
top bar, simulated: systems/swing.py) and a child (1.2 m, 25 kg: the Figure at a child's
height and mass) seated on it, holding the chains, pumping (control/pump.py): she leans back
with her legs out on the forward swing and sits up with them tucked on the backward swing,
and the swing's amplitude grows from a small push.

The swing and the child are one MuJoCo model (her seat is a contact, her grips ball-joint
equalities), so nothing is coupled between systems here: the skirt the issue puts on her is
not built yet (docs/swing.md says what is missing).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..control.fsm import Controller, State
from ..control.pump import Pump, PumpParams
from ..geometry.anthropometry import BodyParams
from ..geometry.setpieces import merge, rod
from ..outputs.render.camera import TrackingCamera
from ..params import param
from ..scene import Scene
from ..systems.colliders import StaticMesh
from ..systems.figure import FigureParams
from ..systems.figure_model import EnvironmentParams
from ..systems.static import StaticPlane
from ..systems.swing import SEATED, SwingFigure, SwingParams
from .contract import SceneSpec

ARM_OMEGA = 20.0  # rad/s: her arms hold her on the seat through the grips (softer: she tips)
G = 9.81


@dataclass(frozen=True)
class ChildParams:
    """The child: mass (kg) and height (m) (a 7-8 year old: 1.2 m, 25 kg)."""
    mass: float = param(25.0, "kg", ge=10.0, le=120.0)
    height: float = param(1.2, "m", ge=0.8, le=2.0)


@dataclass(frozen=True)
class SwingSceneParams:
    """child: her size; swing: the swing; pump: her pumping; dt (s): MuJoCo's step."""
    child: ChildParams = ChildParams()
    swing: SwingParams = SwingParams()
    pump: PumpParams = PumpParams()
    dt: float = param(1e-3, "s", ge=1e-5, le=5e-3)


def child(p: SwingSceneParams, dt: float | None = None) -> SwingFigure:
    """The child seated on the swing, pumping (or still, ``pump.enabled=false``)."""
    ctrl = Controller((State("seated", pose=SEATED, blend=0.0,
                             gains=(("shoulder", ARM_OMEGA), ("elbow", ARM_OMEGA),
                                    ("wrist", ARM_OMEGA))),), "seated")
    env = EnvironmentParams(floor=0.0, air_density=1.2)
    fig = SwingFigure("child", FigureParams(body=BodyParams(p.child.mass, p.child.height),
                                            environment=env, dt=p.dt if dt is None else dt),
                      p.swing, ctrl)
    fig.feedback = Pump(p.pump, fig.joints)
    fig.color = None  # dressed in the figure's default clothes
    return fig


def frame_mesh(s: SwingParams):
    """The swing's frame: the top bar and an A-frame of two legs at each end (m)."""
    half = 0.5 * s.width + 0.45
    parts = [rod([0.0, -half - 0.1, s.bar], [0.0, half + 0.1, s.bar], 0.04)]
    for y in (-half, half):
        for x in (-0.9, 0.9):
            parts.append(rod([x, y, 0.0], [0.0, y, s.bar + 0.03], 0.035))
    return merge(*parts)


def build(coupling: str = "one-way", duration: float = 30.0, fps: float = 30.0,
          integrator: str | None = None, dt: float | None = None,
          params: SwingSceneParams = SwingSceneParams()) -> Scene:
    """The scene; dt overrides MuJoCo's step (s)."""
    scene = Scene("swing", duration=duration, fps=fps, coupling_dt=1.0 / 120.0)
    fig = scene.add(child(params, dt))
    scene.primary = fig
    scene.add(StaticMesh("frame", *frame_mesh(params.swing), color=(0.15, 0.35, 0.55),
                         material="paint"))
    scene.add(StaticPlane("ground", height=0.0, size=8.0, color=(0.22, 0.36, 0.16)))
    I, Md = fig.swing_inertia()
    scene.meta = {"child_mass_kg": fig.mass, "swing_mass_kg": fig.swing_mass,
                  "pendulum_period_s": 2 * np.pi * np.sqrt(I / (Md * G)),
                  "pumping": bool(params.pump.enabled), "skirt": "not built"}
    return scene


def swing_angles(result) -> tuple[np.ndarray, np.ndarray]:
    """(t (s), the swing's angle (rad, forward positive)) at every frame, from its part's
    orientation (a turn about -y)."""
    fr = result.frames["child"]
    q = fr["segment_orientations"][:, -1]
    return np.asarray(fr["t"]), -2.0 * np.arctan2(q[:, 2], q[:, 0])


def amplitudes(t, angle) -> tuple[np.ndarray, np.ndarray]:
    """(times (s), amplitudes (rad)) per cycle: half the swing from each forward turning
    point to the backward one after it."""
    up = np.flatnonzero((angle[1:-1] > angle[:-2]) & (angle[1:-1] >= angle[2:])) + 1
    down = np.flatnonzero((angle[1:-1] < angle[:-2]) & (angle[1:-1] <= angle[2:])) + 1
    out_t, out_a = [], []
    for i in up:
        after = down[down > i]
        if len(after):
            out_t.append(t[i])
            out_a.append(0.5 * (angle[i] - angle[after[0]]))
    return np.array(out_t), np.array(out_a)


def figures(result) -> dict:
    """Amplitude per cycle (deg), the measured period against the compound pendulum's."""
    if "child" not in result.frames:
        return {}
    t, a = swing_angles(result)
    ct, amp = amplitudes(t, a)
    out = {"amplitude per cycle (deg)": [round(float(np.degrees(v)), 2) for v in amp],
           "pendulum period, closed form (s)": result.meta.get("pendulum_period_s"),
           "pumping": result.meta.get("pumping"), "skirt": result.meta.get("skirt")}
    if len(ct) > 1:
        out["period measured (s)"] = float(np.mean(np.diff(ct)))
    return out


SPEC = SceneSpec(
    "swing", "a child on a playground swing pumps it higher (leans back, legs out, on the "
    "forward swing; sits up, legs tucked, on the backward one)", build, SwingSceneParams,
    couplings=("one-way",), duration=30.0, fps=30.0,
    # from the side, a little in front: the whole arc of the swing and the frame
    camera=TrackingCamera("child", offset=(1.2, -4.6, -0.1), target_offset=(0.0, 0.0, 0.3),
                          axes=(0.0, 0.0, 0.0), hold=(0.0, 0.0, 1.2), fov_deg=45.0,
                          smooth_s=0.3),
    key_time=20.0, figures=figures, heavy=True)
