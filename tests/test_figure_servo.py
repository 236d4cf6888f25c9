"""The figure's servos with gravity compensation: the feed-forward is MuJoCo's inverse
dynamics, it holds poses without steady error, and a crouch no longer chatters."""
import numpy as np
import pytest

pytest.importorskip("mujoco")

import mujoco  # noqa: E402

from interplay.control import behaviours as B  # noqa: E402
from interplay.control.fsm import Controller  # noqa: E402
from interplay.geometry.anthropometry import BodyParams  # noqa: E402
from interplay.systems.figure import Figure, FigureParams  # noqa: E402

GYMNAST = BodyParams(mass=64.38, height=1.70)
POSE = {"l_shoulder_flex": 1.2, "r_shoulder_flex": 1.0, "l_elbow": 0.8, "waist_flex": 0.3,
        "neck_flex": 0.2, "l_hip_flex": 0.7, "l_knee": 1.0}


def _pose(f):
    target = np.zeros(30)
    for name, value in POSE.items():
        target[f.joints.index(name)] = value
    return target


def test_fixed_base_feedforward_is_mj_inverse_at_the_desired_pose():
    f = Figure("f", FigureParams(body=GYMNAST), fixed_base=True)
    target = _pose(f)
    tau = f.gravity.torques(f.data.qpos, target, np.zeros(0, np.int64))
    d = mujoco.MjData(f.model)
    d.qpos[f.qadr] = target
    mujoco.mj_inverse(f.model, d)  # qvel = qacc = 0: the force that holds the pose
    assert np.allclose(tau, d.qfrc_inverse[f.vadr], atol=1e-9)
    assert np.abs(tau).max() > 10.0  # N m: the raised arm and leg do weigh something


def test_standing_feedforward_puts_the_weight_on_the_feet():
    f = Figure("f", FigureParams(body=GYMNAST), Controller((B.crouch(),)))
    for _ in range(200):
        f.advance(1e-3)
    target = f._reference(f.time)[0]
    tau = f.gravity.torques(f.data.qpos, target, np.array([0, 1]))
    # the feet's upward pushes balance gravity on the root: no force or moment left over
    assert np.abs(f.gravity.root_residual).max() < 1e-9
    knee = f.joints.index("l_knee")
    assert tau[knee] < -20.0  # the bent stance knee holds the body up (extension torque)


@pytest.mark.parametrize("compensate, bound", [(True, 0.01), (False, 0.03)])
def test_pose_held_against_gravity(compensate, bound):
    # pelvis welded, gravity on, default servos (w = 20 rad/s, zeta = 1): with tau_g the pose
    # is held with no steady error; without it each joint sags by tau_gravity / g_s
    f = Figure("f", FigureParams(body=GYMNAST, gravity_compensation=compensate),
               fixed_base=True)
    target = _pose(f)
    f.set_targets(target)
    for _ in range(1500):
        f.advance(1e-3)
    err = np.abs(f.angles() - target).max()
    if compensate:
        assert err < bound
    else:
        assert err > bound


def test_crouch_and_rise_without_chatter():
    c = Controller((B.stand(next="crouch", after=0.3), B.crouch(next="up", after=1.0),
                    B.stand("up")), start="stand")
    f = Figure("man", FigureParams(body=GYMNAST), c)
    limit = f.model.actuator_forcerange[:, 1]
    legs = f.leg
    taus, coms, refs = [], [], []
    for _ in range(2500):
        f.advance(1e-3)
        taus.append(f.data.actuator_force.copy())
        refs.append(f._reference(f.time)[0])
        coms.append(f.com())
    taus, coms = np.array(taus), np.array(coms)
    hold = slice(800, 1300)  # the crouch held, after its 0.5 s blend
    assert coms[hold, 2].max() < coms[0, 2] - 0.1  # crouched by > 10 cm ...
    assert np.ptp(coms[hold, 2]) < 0.02  # ... and holding still
    assert coms[-1, 2] > coms[0, 2] - 0.05  # back up, still on his feet
    # no leg servo reaches its torque limit (the old chatter: stiff stance gains slammed them
    # from limit to limit every control tick), and the desired angles move smoothly: at most
    # 0.01 rad in one 1 ms step
    assert not np.any(np.abs(taus[:, legs]) >= limit[legs] - 1e-6)
    assert np.abs(np.diff(np.array(refs), axis=0)).max() < 0.01
    # what is left are single-step kicks when a heel or toe corner touches or leaves the
    # floor (the damping term meets the contact's velocity jump); they are rare
    jump = (np.abs(np.diff(taus[:, legs], axis=0)) / limit[legs]).max(axis=1)
    assert np.mean(jump > 0.05) < 0.05


def test_servo_reference_moves_at_every_step():
    c = Controller((B.stand(next="crouch", after=0.1), B.crouch()), start="stand")
    f = Figure("man", FigureParams(body=GYMNAST), c)
    ctrl = []
    for _ in range(400):
        f.advance(1e-3)
        ctrl.append(f.data.act.copy())
    step = np.abs(np.diff(np.array(ctrl)[150:350], axis=0)).max(axis=1)
    # inside the blend the reference changes at every 1 ms step, not once per 5 ms tick
    assert np.all(step > 0.0)
    assert step.max() < 3.0 * np.median(step)


def test_capture_and_restore_replay_the_controlled_motion_exactly():
    # the snapshot holds the servo reference (act), its rate (ctrl), the held drag and the
    # controller's state: a rerun from it repeats the run bit for bit
    from interplay.scenes import bungee
    f = bungee.jumper(bungee.JumperParams())
    for _ in range(1200):  # into the crouch, mid-blend
        f.advance(1e-3)
    snap = f.capture()
    for _ in range(600):  # through the tip and the leap
        f.advance(1e-3)
    first = f.data.qpos.copy()
    f.restore(snap)
    for _ in range(600):
        f.advance(1e-3)
    assert np.array_equal(f.data.qpos, first)
