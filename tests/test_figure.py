"""The human figure: model, PD servos, standing balance, state, bad parameters."""
import numpy as np
import pytest

pytest.importorskip("mujoco")

from interplay.control.fsm import Controller, State, Transition  # noqa: E402
from interplay.control import behaviours as B  # noqa: E402
from interplay.errors import ParameterError  # noqa: E402
from interplay.geometry.anthropometry import SEGMENTS, BodyParams  # noqa: E402
from interplay.systems.figure import Figure, FigureParams  # noqa: E402

GYMNAST = BodyParams(mass=64.38, height=1.70)


def test_model_has_17_segments_30_dofs_and_the_requested_mass():
    f = Figure("gymnast", FigureParams(body=GYMNAST))
    assert len(SEGMENTS) == 17 and len(f.seg_body) == 17
    assert len(f.joints) == 30 and f.model.nu == 30
    assert f.model.nv == 36  # 30 hinges + the free root
    assert f.mass == pytest.approx(64.38, rel=1e-12)
    alien = Figure("alien", FigureParams(body=BodyParams(mass=46.56, height=1.5)))
    assert alien.mass == pytest.approx(46.56, rel=1e-12)
    lo, hi = f.model.jnt_range[1:].T
    assert np.all(lo < 0.0 + 1e-12) and np.all(hi > 0.0)  # the rest pose is inside every range
    fr = f.frame()
    assert fr["segment_positions"].shape == (17, 3)
    assert fr["segment_orientations"].shape == (17, 4)
    v, t = f.surface()
    assert t.max() < len(v) and abs(f.lowest_z()) < 1e-3  # feet on the ground at rest


def _oscillation(th, dt):
    """Damped natural frequency (rad/s) and damping ratio from successive extrema of th."""
    pk = [k for k in range(1, len(th) - 1)
          if abs(th[k]) > abs(th[k - 1]) and abs(th[k]) >= abs(th[k + 1])][:5]
    period = 2.0 * np.diff(pk).mean() * dt
    dec = np.log(np.abs(th[pk[:-1]]) / np.abs(th[pk[1:]])).mean()  # per half period
    zeta = dec / np.sqrt(np.pi ** 2 + dec ** 2)
    return 2 * np.pi / period / np.sqrt(1 - zeta ** 2), zeta


@pytest.mark.parametrize("joint", ["l_elbow", "waist_flex", "r_shoulder_flex"])
def test_single_joint_step_response_has_the_designed_frequency_and_damping(joint):
    # base welded, no gravity; every other joint held by stiff servos (w = 300 rad/s) so the
    # joint under test moves its own subtree only: g_s = I w^2, g_d = 2 zeta I w must then give
    # exactly a mass-spring-damper with w = 20 rad/s, zeta = 0.2
    dt, w, zeta = 1e-3, 20.0, 0.2
    f = Figure("f", FigureParams(dt=dt, omega=w, zeta=zeta), fixed_base=True, gravity=False)
    i = f.joints.index(joint)
    f.omega[:], f.zeta[:] = 300.0, 1.0
    f.omega[i], f.zeta[i] = w, zeta
    f.apply_gains()
    start = np.zeros(30)
    start[i] = 0.5
    x, v = f.generalized_state()
    x = x.copy()
    x[f.qadr[i]] = 0.5
    f.set_generalized_state(x, np.zeros_like(v))
    f.set_targets(start + np.eye(30)[i] * 0.2)
    th = []
    for _ in range(1200):
        f.advance(dt)
        th.append(f.angles()[i] - 0.7)
    w_meas, z_meas = _oscillation(np.array(th), dt)
    # peak timing is quantised to dt (w dt = 2 % per period over ~2 periods) and the hinge's
    # coupling to the held joints leaves ~1 %: 3 % on w, 0.01 on zeta
    assert w_meas == pytest.approx(w, rel=0.03)
    assert z_meas == pytest.approx(zeta, abs=0.01)


def test_servo_torque_is_the_pd_law():
    from interplay.control.pd import pd_torque
    f = Figure("f", FigureParams(), fixed_base=True, gravity=False)
    f.set_targets(np.full(30, 0.1), np.full(30, 0.5))
    f.advance(f.dt)
    # MuJoCo computed the force from the state at the start of the step: redo it from there
    x, v = f.generalized_state()
    f2 = Figure("f", FigureParams(), fixed_base=True, gravity=False)
    f2.set_targets(np.full(30, 0.1), np.full(30, 0.5))
    ref = pd_torque(0.1, np.zeros(30), 0.5, np.zeros(30), f2.kp, f2.kd, f2.model.actuator_forcerange[:, 1])
    assert np.allclose(f.data.actuator_force, ref, rtol=1e-12)


def test_figure_stands_balanced_for_5_s():
    f = Figure("man", FigureParams(body=GYMNAST), Controller((B.stand(),)))
    com0 = f.com()
    for _ in range(5000):
        f.clear_forces()
        f.advance(1e-3)
    com = f.com()
    # standing: the centre of mass stays within 3 cm of where it started, over the feet
    # (the balance feedback leans it toward the middle of the feet, ~2 cm ahead of the ankles)
    assert abs(com[2] - com0[2]) < 0.03
    assert np.linalg.norm(com[:2] - com0[:2]) < 0.03
    assert f.health() == []


def test_pushed_figure_recovers():
    f = Figure("man", FigureParams(body=GYMNAST), Controller((B.stand(),)))
    for k in range(3000):
        f.clear_forces()
        if 500 <= k < 600:
            f.add_wrench([60.0, 0.0, 0.0], body="torso")  # 6 N s shove
        f.advance(1e-3)
    assert f.com()[2] > 0.9 and abs(f.com()[0]) < 0.05


def test_sideways_shove_is_absorbed_by_the_two_foot_stance():
    # balance feedback is sagittal only (ankles); sideways the stance's width and the soft
    # stance servos with gravity compensation absorb a 12 N s shove at the chest
    f = Figure("man", FigureParams(body=GYMNAST), Controller((B.stand(),)))
    for k in range(3000):
        f.clear_forces()
        if 500 <= k < 600:
            f.add_wrench([0.0, 120.0, 0.0], body="torso")
        f.advance(1e-3)
    assert f.com()[2] > 0.95 and abs(f.com()[1]) < 0.02


def test_generalized_state_round_trip_keeps_the_velocity():
    f = Figure("man", FigureParams(body=GYMNAST))
    f.data.qvel[:] = np.linspace(-1, 1, f.model.nv)
    q = np.array([0.9, 0.1, -0.3, 0.2])
    f.data.qpos[3:7] = q / np.linalg.norm(q)
    qvel = f.data.qvel.copy()
    x, xd = (a.copy() for a in f.generalized_state())
    f.set_generalized_state(x * np.r_[np.ones(3), 2 * np.ones(4), np.ones(30)], xd)
    assert np.allclose(f.data.qvel, qvel, atol=1e-12)  # the quaternion was renormalised
    assert np.linalg.norm(f.data.qpos[3:7]) == pytest.approx(1.0)


def test_wrench_on_a_segment_moves_the_figure_by_its_impulse():
    f = Figure("man", FigureParams(body=GYMNAST, environment=_no_ground()), gravity=False)
    for _ in range(100):
        f.clear_forces()
        f.add_wrench([10.0, 0.0, 0.0], point=f.data.xpos[f.seg_body[3]], body="l_upper_arm")
        f.advance(1e-3)
    # p = F t = 1 N s, whatever segment it hits; implicitfast linearises the servo damping
    # within a step, which leaves a few 1e-6 of the impulse in rounding of internal forces
    assert f.momentum()[0] == pytest.approx(1.0, rel=1e-5)
    assert f.segment_wrenches()[3, 0] == 10.0


def _no_ground():
    from interplay.systems.figure_model import EnvironmentParams
    return EnvironmentParams(floor=None)


def test_state_machine_transitions_on_time():
    c = Controller((B.stand(next="crouch", after=0.2), B.crouch(next="stand", after=5.0),
                    B.stand()), start="stand")
    with pytest.raises(ParameterError, match="state names must be unique"):
        Figure("man", FigureParams(), c)
    c = Controller((B.stand(next="crouch", after=0.2), B.crouch()), start="stand")
    f = Figure("man", FigureParams(), c)
    for _ in range(300):
        f.advance(1e-3)
    assert f.fsm.state.name == "crouch"
    assert f.fsm.entered == pytest.approx(0.2, abs=f.control_dt)  # on the first tick past 0.2 s


@pytest.mark.parametrize("body, message", [
    (BodyParams(height=0.0), "height must be a positive finite number m, got 0.0"),
    (BodyParams(mass=-60.0), "mass must be a positive finite number kg, got -60.0"),
    (BodyParams(height=12.0), "height 12.0 m is not a human height"),
])
def test_impossible_figure_parameters(body, message):
    with pytest.raises(ParameterError, match=message):
        Figure("man", FigureParams(body=body))


@pytest.mark.parametrize("state, message", [
    (State("s", pose=(("elbo", 1.0),)), "joint key 'elbo' names no joint"),
    (State("s", transitions=(Transition("jump", "s"),)), "unknown event 'jump'"),
    (State("s", transitions=(Transition("time", "t"),)), "transition to unknown state 't'"),
    (State("s", entry=("wave",)), "unknown entry action 'wave'"),
])
def test_bad_controller_is_refused_with_its_reason(state, message):
    with pytest.raises(ParameterError, match=message):
        Figure("man", FigureParams(), Controller((state,)))
