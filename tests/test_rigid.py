"""Rigid bodies: closed-form ballistic flight and free rotation."""
import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.kernels.rigid import quat_to_matrix
from interplay.systems.rigid import Sphere, SphereParams

G = np.array([0.0, 0.0, -9.81])


def test_ballistic_flight_is_exact():
    # x += h v + h^2 a / 2 is exact for constant acceleration: only round-off remains,
    # which grows like (steps) * eps * |x| ~ 1e3 * 2e-16 * 10 m.
    ball = Sphere("ball", SphereParams(dt=1e-3), position=(0.1, -0.2, 3.0),
                  velocity=(1.0, 0.5, 4.0))
    for _ in range(1000):
        ball.clear_forces()
        ball.advance(1e-3)
    t = 1.0
    x0, v0 = np.array([0.1, -0.2, 3.0]), np.array([1.0, 0.5, 4.0])
    np.testing.assert_allclose(ball.x, x0 + v0 * t + 0.5 * G * t * t, atol=1e-11)
    np.testing.assert_allclose(ball.v, v0 + G * t, atol=1e-11)


def test_constant_force_adds_to_gravity():
    ball = Sphere("ball", SphereParams(mass=2.0, dt=1e-2))
    for _ in range(50):
        ball.clear_forces()
        ball.add_wrench([4.0, 0.0, 0.0])
        ball.advance(1e-2)
    # a = F/m = 2 m/s^2 along x for 0.5 s: x = a t^2 / 2 exactly (see above)
    assert ball.x[0] == pytest.approx(0.25, abs=1e-12)


def test_shell_and_solid_inertia():
    shell = Sphere("a", SphereParams(radius=0.12, mass=0.68, shell=True))
    solid = Sphere("b", SphereParams(radius=0.12, mass=0.68, shell=False))
    assert shell.inertia_body[0] == pytest.approx(2 / 3 * 0.68 * 0.12 ** 2)
    assert solid.inertia_body[0] == pytest.approx(2 / 5 * 0.68 * 0.12 ** 2)


def test_free_spin_rotates_by_omega_t():
    # A sphere's inertia is isotropic: w stays constant and q(t) = exp(w t) exactly.
    w = np.array([0.0, 0.0, 3.0])
    ball = Sphere("ball", SphereParams(dt=1e-3), angular_velocity=w)
    ball.gravity[:] = 0.0
    for _ in range(500):
        ball.clear_forces()
        ball.advance(1e-3)
    ang = 3.0 * 0.5
    R = quat_to_matrix(ball.q)
    expected = np.array([[np.cos(ang), -np.sin(ang), 0], [np.sin(ang), np.cos(ang), 0], [0, 0, 1]])
    np.testing.assert_allclose(R, expected, atol=1e-12)
    np.testing.assert_allclose(ball.w, w)


def test_generalized_state_round_trip():
    ball = Sphere("ball", SphereParams(), velocity=(1, 2, 3), angular_velocity=(0.3, -0.2, 5.0))
    ball.q[:] = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
    x, xdot = (a.copy() for a in ball.generalized_state())
    other = Sphere("other", SphereParams())
    other.set_generalized_state(x, xdot)
    np.testing.assert_allclose(other.w, ball.w, atol=1e-14)
    np.testing.assert_allclose(other.v, ball.v)


@pytest.mark.parametrize("field,value,word", [("mass", -1.0, "mass"), ("mass", 0.0, "mass"),
                                              ("radius", 0.0, "radius"), ("dt", 0.0, "dt")])
def test_bad_sphere_parameters(field, value, word):
    p = SphereParams(**{field: value})
    with pytest.raises(ParameterError, match=word):
        Sphere("ball", p)


def bounce(dt, drop=1.0):
    from interplay.interactions.contact import ContactParams, SpherePlaneContact
    from interplay.scene import Scene
    from interplay.systems.static import StaticPlane
    scene = Scene("drop", duration=1.2, coupling_dt=dt)
    ball = scene.add(Sphere("ball", SphereParams(dt=dt), position=(0, 0, 0.12 + drop)))
    floor = scene.add(StaticPlane("floor"))
    scene.connect(SpherePlaneContact("floor", ball, floor, ContactParams(
        stiffness=1e5, damping=40.0, friction=0.6, thickness=0.0)))
    r = scene.simulate()
    v = r.tracks["ball"].xdot[:, 2]
    z = r.tracks["ball"].x[:, 2]
    hit = np.argmax(z <= 0.12)  # first touch
    after = hit + np.argmax(z[hit:] > 0.12)  # back at touching height, leaving
    return -v[after] / v[hit], z[after:].max() - 0.12


def test_floor_bounce_keeps_its_restitution():
    # a spring-damper contact gives e = exp(-zeta pi / sqrt(1 - zeta^2)) = 0.785 for
    # zeta = c / (2 sqrt(k m)) = 0.077; the contact only pushes (the force is clamped at zero as
    # the ball leaves), which returns a little more (0.794 measured at 1e-5 s). The trapezoidal
    # step adds no energy: at the coarse 1e-3 s step (w h = 0.38) e is within (w h)^2 / 6 of
    # the fine one, and the rebound height is e^2 times the drop (energy, not an artefact).
    e_coarse, top = bounce(1e-3)
    e_fine, _ = bounce(1e-5)
    assert 0.785 <= e_fine <= 0.81
    assert e_coarse == pytest.approx(e_fine, abs=0.03)
    assert top == pytest.approx(1.0 * e_coarse ** 2, abs=0.01)


def on_floor(shell: bool, v0=(0.0, 0.0, 0.0), seconds=1.0, h=1e-3, mu=0.6, eps=0.05):
    """The basketball's ball on its floor (1e5 N/m, 40 N s/m, friction mu, eps m/s) set down
    touching it at rest or sliding at v0 (m/s) without spin; returns (track, force log)."""
    from interplay.interactions.contact import ContactParams, SpherePlaneContact
    from interplay.scene import Scene
    from interplay.systems.static import StaticPlane
    scene = Scene("floor", duration=seconds, fps=100, coupling_dt=h)
    p = SphereParams(shell=shell, dt=h)
    ball = scene.add(Sphere("ball", p, position=(0.0, 0.0, p.radius), velocity=v0))
    floor = scene.add(StaticPlane("floor", height=0.0, size=15.0))
    law = ContactParams(stiffness=1e5, damping=40.0, friction=mu, eps=eps, thickness=0.0)
    scene.connect(SpherePlaneContact("ball-floor", ball, floor, law))
    scene.primary = ball
    r = scene.simulate()
    return r.tracks["ball"], r.logs["ball-floor"]


def test_a_ball_set_down_on_the_floor_rests():
    """Issue 22 item 5: set down touching the floor, it is in contact every step, with no
    vertical speed, carried by exactly its weight, at exactly its radius. Before the contact
    kept a skin above the plane, the law's spring on top of the constraint force lifted it off
    every other step: it hopped at up to 5.6 cm/s, pressing 1.035 m g on average."""
    tr, log = on_floor(shell=True)
    m, g = SphereParams().mass, 9.81
    assert log.active.all()
    assert np.abs(tr.xdot[:, 2]).max() < 1e-12
    assert log.force[:, 2] == pytest.approx(m * g, rel=1e-12)
    assert tr.x[:, 2] == pytest.approx(SphereParams().radius, abs=1e-12)


@pytest.mark.parametrize("shell,k,ratio", [(False, 7 / 2, 5 / 7), (True, 5 / 2, 3 / 5)])
def test_a_sliding_ball_starts_rolling_when_and_as_fast_as_the_closed_form(shell, k, ratio):
    """A ball sliding at v0 without spin: Coulomb friction mu m g slows the slip at
    mu g k (k = 1 + m r^2 / I: 7/2 solid, 5/2 shell) until it rolls at 5/7 v0 (solid) or 3/5
    v0 (shell). The regularised law is full Coulomb down to a slip of eps, reached at
    (v0 - eps) / (mu g k): within two steps of it; the rolling speed within 1e-3 v0 (the
    viscous tail below eps decays at mu g k / eps, 300/s, and the friction cap of the held
    force lets the slip's last 1e-3 go in the tail), and it then rolls on at that speed."""
    v0, mu, eps, h, g = 2.0, 0.6, 0.05, 1e-3, 9.81
    tr, _ = on_floor(shell=shell, v0=(v0, 0.0, 0.0), seconds=0.5, h=h, mu=mu, eps=eps)
    r = SphereParams().radius
    # the track's state: position and orientation (w, x, y, z); its rate: velocity and the
    # quaternion's; world angular velocity = 2 vec(qdot q*) = 2 (w vdot - wdot v - vdot x v)
    w, v = tr.x[:, 3], tr.x[:, 4:7]
    wd, vd = tr.xdot[:, 3], tr.xdot[:, 4:7]
    omega = 2.0 * (w[:, None] * vd - wd[:, None] * v - np.cross(vd, v))
    slip = tr.xdot[:, 0] - r * omega[:, 1]  # the contact point's speed along +x
    t_eps = tr.t[np.argmax(slip < eps)]
    assert t_eps == pytest.approx((v0 - eps) / (mu * g * k), abs=2 * h)
    end = tr.t > 0.3
    assert tr.xdot[end, 0] == pytest.approx(ratio * v0, abs=1e-3 * v0)
    assert np.ptp(tr.xdot[end, 0]) < 1e-6
