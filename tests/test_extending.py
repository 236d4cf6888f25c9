"""The worked example of docs/architecture.md: a new system (examples/capsule_pendulum.py's
pendulum) and a new interaction (its linear drag) work with the scheduler, MeshContact and the
outputs without any edit to Interplay's own modules."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from capsule_pendulum import CapsulePendulum, LinearDrag  # noqa: E402

from interplay.geometry import shapes  # noqa: E402
from interplay.interactions.mesh_contact import MeshContact, MeshContactParams  # noqa: E402
from interplay.scene import Scene  # noqa: E402
from interplay.systems.springmass import SpringNetwork  # noqa: E402
from interplay.systems.wind import WindField  # noqa: E402

L, G, DT = 0.5, 9.81, 1e-3


def swing(seconds, drag=None, theta=0.05):
    scene = Scene("pendulum", duration=seconds, fps=100)
    pend = scene.add(CapsulePendulum("pendulum", (0, 0, 1.0), length=L, theta=theta, dt=DT))
    if drag is not None:
        air = scene.add(WindField("air"))
        scene.connect(LinearDrag("drag", air, pend, drag))
    scene.primary = pend
    return scene.simulate()


def crossings(res):
    t, x = res.tracks["pendulum"].t, res.tracks["pendulum"].x[:, 0]
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


def test_the_new_system_swings_at_its_small_angle_period():
    """T = 2 pi sqrt(I_p / (m g L/2)) = 2 pi sqrt(2 L / (3 g)) for a rod on a pivot; at 0.05
    rad the large-angle correction is theta^2/16 = 1.6e-4 and semi-implicit Euler's error is
    O((omega dt)^2) ~ 1e-5 of the period: 5e-4 relative covers both."""
    res = swing(4.0)
    period = np.diff(crossings(res)).mean()
    assert period == pytest.approx(2 * math.pi * math.sqrt(2 * L / (3 * G)), rel=5e-4)


def test_the_new_interaction_damps_it_at_the_closed_form_rate():
    """Drag -c v at the centre of mass (L/2 from the pivot) is a damping torque -c (L/2)^2
    omega: the amplitude decays as exp(-c L^2 t / (8 I_p)). Peaks are read from the track at
    the coupling step (1 ms: 4e-5 of the period's phase, well inside 1%)."""
    c = 0.4
    res = swing(4.0, drag=c)
    x = res.tracks["pendulum"].x[:, 0]
    t = res.tracks["pendulum"].t
    peaks = [i for i in range(1, len(x) - 1) if x[i] > x[i - 1] and x[i] >= x[i + 1]]
    rate = -np.polyfit(t[peaks], np.log(x[peaks]), 1)[0]
    assert rate == pytest.approx(c * L * L / (8 * (1.0 * L * L / 3)), rel=0.01)
    assert res.summary()["interactions"][0]["force_N"]["max"] > 0  # logged on the air


def test_it_collides_with_a_cloth_through_mesh_contact_two_way():
    """The pendulum swings into a hanging sheet: forces equal and opposite at every exchange,
    the sheet is pushed, and the pendulum's swing is cut short."""
    scene = Scene("pendulum-cloth", duration=0.6, fps=60, coupling_dt=DT)
    pend = scene.add(CapsulePendulum("pendulum", (0, 0, 1.0), length=L, theta=1.0, dt=DT))
    x, t = shapes.grid(0.4, 0.6, 9, 13, origin=(0.12, -0.2, 1.1), u=(0, 1, 0), v=(0, 0, -1))
    sheet = scene.add(SpringNetwork.from_mesh("sheet", x, t, 0.4, 30.0, dt=DT,
                                              integrator="implicit", mass_damping=0.5,
                                              fixed=range(9)))
    scene.connect(MeshContact("hit", pend, sheet, MeshContactParams(thickness=0.003)))
    scene.primary = pend
    free = swing(0.6, theta=1.0)
    res = scene.simulate()
    assert res.logs["hit"].active.any()
    # free, it swings through to -1 rad; the 0.4 kg sheet stops it at -0.73 rad
    assert res.tracks["pendulum"].x[:, 0].min() > free.tracks["pendulum"].x[:, 0].min() + 0.1
    pushed = np.abs(res.frames["sheet"]["points"] - x).max()
    assert pushed > 0.01  # m: the sheet is pushed out of its plane


def test_the_outputs_draw_it(tmp_path):
    from interplay.outputs.writer import OutputOptions, write_outputs
    res = swing(0.2)
    paths = write_outputs(res, tmp_path, OutputOptions(video=False, report=False, obj=False))
    from interplay.outputs.usd import validate
    usd = next(p for p in paths if str(p).endswith(".usdc"))
    assert validate(usd) == []
