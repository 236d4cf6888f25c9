"""MeshContact response: resting without sinking or jitter, stick/slip on a slope, two-way
forces equal and opposite, no tunnelling, and the bad-input messages."""
import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry.shapes import grid
from interplay.interactions.mesh_contact import MeshContact, MeshContactParams
from interplay.scene import Scene
from interplay.systems.colliders import StaticBox, StaticCapsule, StaticMesh, StaticSphere, \
    box_surface
from interplay.systems.rigid import RigidBody, Sphere, SphereParams
from interplay.systems.springmass import SpringNetwork
from interplay.systems.static import StaticPlane

G = 9.81
A = 0.05  # m, the cube's half side
H = 1e-3  # s, the step


def cube(z=0.1, m=1.0, name="cube", surface=None):
    return RigidBody(name, m, [m * (2 * A) ** 2 / 6] * 3, H, position=(0, 0, z),
                     surface=box_surface([A] * 3) if surface is None else surface)


def step(systems, contacts, h=H):
    for s in systems:
        s.clear_forces()
    for c in contacts:
        c.exchange(True, True)
    for s in systems:
        s.advance(h)


def test_cube_rests_on_the_ground_through_the_scene():
    scene = Scene("rest", duration=2.0)
    box = scene.add(cube())
    floor = scene.add(StaticPlane("floor"))
    p = MeshContactParams()
    scene.connect(MeshContact("cube-floor", box, floor, p))
    res = scene.simulate()
    x, v = res.state_at("cube", 2.0)
    # rests at the contact thickness: within g h^2 (one step's fall) of it, not sinking
    assert x[2] == pytest.approx(A + p.thickness, abs=G * H * H)
    assert np.linalg.norm(v[:3]) < 1e-6  # no jitter
    for t in np.arange(1.0, 2.0, 0.1):
        assert res.state_at("cube", t)[0][2] > A + p.thickness - G * H * H
    # no bounce: after landing (0.94 m/s) it never rises above its resting height; the
    # critically damped contact (omega = 1/(10 h)) dips at most v/(omega e) = 3.5 mm
    z = np.array([res.state_at("cube", t)[0][2] for t in np.arange(0.0, 1.0, H)])
    landed = np.argmax(z < A + p.thickness)
    assert z[landed:].max() <= A + p.thickness + G * H * H
    assert z.min() > A + p.thickness - 0.94 / (np.e / (10 * H))


def run_slope(theta, mu=0.5, seconds=1.0):
    c, s = np.cos(theta), np.sin(theta)
    R = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])  # the slope's frame: x down-slope... up
    L = 2.0
    v = np.array([[-L, -L, 0], [L, -L, 0], [L, L, 0], [-L, L, 0]], float)
    slope = StaticMesh("slope", v @ R.T, [[0, 1, 2], [0, 2, 3]])
    p = MeshContactParams(friction=mu)
    box = cube()
    box.x[:] = R @ [0, 0, A + p.thickness]
    # the cube's orientation: the slope's rotation about y, as a quaternion (w, x, y, z)
    box.q[:] = [np.cos(-theta / 2), 0, np.sin(-theta / 2), 0]
    contact = MeshContact("c", box, slope, p)
    contact.prepare(H)
    pos = []
    for _ in range(int(seconds / H)):
        step([box], [contact])
        pos.append(box.x @ R[:, 0])  # distance along the slope (negative: down)
    return np.array(pos)


def test_block_sticks_below_the_friction_angle():
    mu = 0.5
    pos = run_slope(np.arctan(mu) - 0.05, mu)
    # the first 0.2 s settle the contact springs (sub-mm); after that it must not move:
    # 1e-6 m over 0.8 s is 1e-6 m/s, far below any creep the regularization would give
    assert abs(pos[-1] - pos[200]) < 1e-6
    assert abs(pos[200] - pos[0]) < 2e-3


def test_block_slides_above_it_with_the_coulomb_acceleration():
    mu, theta = 0.5, np.arctan(0.5) + 0.15
    pos = run_slope(theta, mu)
    # acceleration from second differences of the last half second (speed well above eps);
    # exact for constant acceleration up to the held-force error, O(h) relative: 2%
    t = np.arange(500, 1000)
    acc = -np.polyfit(t * H, pos[t], 2)[0] * 2
    assert acc == pytest.approx(G * (np.sin(theta) - mu * np.cos(theta)), rel=0.02)


def cloth(n=21, z=0.32, fixed=(), integrator="implicit", mass=0.1, stretch=200.0):
    v, t = grid(0.8, 0.8, n, n, origin=(-0.4, -0.4, z))
    return SpringNetwork.from_mesh("cloth", v, t, mass, stretch=stretch, dt=2e-3,
                                   integrator=integrator, mass_damping=0.5, fixed=fixed)


def test_cloth_rests_on_a_sphere_without_sinking_or_jitter():
    c = cloth()
    ball = StaticSphere("ball", (0, 0, 0), 0.3)
    p = MeshContactParams()
    contact = MeshContact("c", c, ball, p)
    contact.prepare(2e-3)
    ke, depth = [], []
    for _ in range(1000):
        step([c], [contact], 2e-3)
        ke.append(c.kinetic_energy())
        depth.append((np.linalg.norm(c.x, axis=1) - 0.3).min())
    # no point sinks below the sphere's surface by more than the fall of one step at the
    # impact speed (~0.6 m/s * 2e-3 s = 1.2 mm) beyond the thickness; resting: inside it
    assert min(depth) > -0.0015
    assert min(depth[-200:]) > p.thickness - p.skin
    # settling: the last 0.4 s carry far less energy than the impact, and it does not grow
    assert max(ke[-200:]) < 0.1 * max(ke)
    assert np.mean(ke[-100:]) <= np.mean(ke[-200:-100]) * 1.5 + 1e-6


def test_two_way_forces_sum_to_zero():
    c = cloth(integrator="implicit")
    ball = Sphere("ball", SphereParams(radius=0.1, mass=0.5), position=(0.01, 0.02, 0.2),
                  velocity=(0.3, 0, 1.0))
    contact = MeshContact("c", ball, c, MeshContactParams())
    contact.prepare(2e-3)
    seen = 0
    for _ in range(100):
        for s in (c, ball):
            s.clear_forces()
        f, tau, on = contact.exchange(True, True)
        if on:
            seen += 1
            net = c.fext.sum(axis=0)
            assert np.allclose(ball.force + net, 0.0, atol=1e-9 * np.abs(net).max())
            assert np.allclose(f, ball.force)
        for s in (c, ball):
            s.advance(2e-3)
    assert seen > 10


def test_one_way_leaves_the_primary_alone():
    c = cloth()
    ball = Sphere("ball", SphereParams(radius=0.1, mass=0.5), position=(0, 0, 0.4))
    contact = MeshContact("c", ball, c, MeshContactParams(), mode="one-way")
    contact.prepare(2e-3)
    ball.clear_forces()
    f, _, on = contact.exchange(False, True)
    assert on and np.linalg.norm(f) > 0  # measured and logged ...
    assert np.all(ball.force == 0.0)  # ... but not applied


def test_fast_small_sphere_does_not_tunnel_through_cloth():
    n = 31
    corners = [0, n - 1, n * (n - 1), n * n - 1]
    c = cloth(n=n, z=0.0, fixed=corners, stretch=2000.0, mass=0.2)
    c.dt = 1e-3
    ball = Sphere("ball", SphereParams(radius=0.03, mass=0.1, dt=1e-3), position=(0.01, 0.0, 0.1),
                  velocity=(0, 0, -10.0))
    contact = MeshContact("c", ball, c, MeshContactParams())
    contact.prepare(1e-3)
    for _ in range(150):
        step([c, ball], [contact], 1e-3)
        near = np.argmin(np.linalg.norm(c.x[:, :2] - ball.x[:2], axis=1))
        assert ball.x[2] > c.x[near, 2]  # the ball's centre stays above the cloth
    assert ball.v[2] > -10.0 * 0.5  # and the cloth caught it


@pytest.mark.parametrize("shape,inside,outside", [
    (StaticBox("b", (0, 0, 0), (1, 2, 3)), (0.5, 0, 0), (1.5, 0, 0)),
    (StaticCapsule("c", (0, 0, 0), (0, 0, 1), 0.5), (0, 0.2, 0.5), (0, 0.8, 0.5)),
    (StaticSphere("s", (0, 0, 1), 0.5), (0, 0, 1.2), (0, 0, 1.8)),
])
def test_static_shapes_signed_distance(shape, inside, outside):
    s, n = shape.distance(np.array([inside, outside], float))
    assert s[0] < 0 < s[1]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)


def test_bad_input_messages():
    box = cube()
    floor = StaticPlane("floor")
    with pytest.raises(ParameterError, match=r"c: friction must be zero or positive, got -0.2; "
                                             r"use 0 for frictionless"):
        MeshContact("c", box, floor, MeshContactParams(friction=-0.2))
    with pytest.raises(ParameterError, match=r"c: contact thickness must be zero or positive "
                                             r"\(m\), got -0.01"):
        MeshContact("c", box, floor, MeshContactParams(thickness=-0.01))
    with pytest.raises(ParameterError, match=r"c: both floor and ground are static"):
        MeshContact("c", floor, StaticPlane("ground"))
    contact = MeshContact("c", box, floor)
    contact.prepare(H)
    box.x[2] = np.nan
    with pytest.raises(ParameterError, match=r"cube: positions of point 0 is not finite.*reduce "
                                             r"the step"):
        contact.exchange(True, True)
    with pytest.raises(ParameterError, match=r"cube: a collision mesh needs at least one"):
        MeshContact("c", cube(surface=(np.zeros((3, 3)), np.zeros((0, 3), np.int64))), floor)


def test_cube_stacked_on_a_cube_on_a_table_rests_and_forces_balance():
    lower = cube(0.06, 1.0, "lower")
    upper = cube(0.2, 0.5, "upper")
    table = StaticBox("table", (0, 0, -0.5), (1, 1, 0.5))
    on_table = MeshContact("lower-table", lower, table)
    stacked = MeshContact("upper-lower", upper, lower)
    for c in (on_table, stacked):
        c.prepare(H)
    seen = 0
    for _ in range(2000):
        for s in (lower, upper):
            s.clear_forces()
        on_table.exchange(True, True)
        before = lower.force.copy()
        _, _, on = stacked.exchange(True, True)
        if on:  # rigid-rigid: what the upper cube gets, the lower loses
            seen += 1
            assert np.allclose(lower.force - before + upper.force, 0.0, atol=1e-9)
        for s in (lower, upper):
            s.advance(H)
    assert seen > 1000
    p = MeshContactParams()
    # the lower cube carries the upper one's weight (4.9 N) on its corners' penalty, which
    # the constraint term does not see (it is computed first): 0.5 kg g / (4 c_s) = 0.5 mm
    assert lower.x[2] == pytest.approx(A + p.thickness, abs=1e-3)
    assert upper.x[2] == pytest.approx(lower.x[2] + 2 * A + p.thickness, abs=p.skin)
    assert np.linalg.norm(lower.v) + np.linalg.norm(upper.v) < 1e-6


def test_keyframed_body_presses_cloth_without_passing_through():
    from interplay.systems.kinematic import KeyframedBody, KeyframedBodyParams
    # a foot (the puddle's ellipsoid) comes down onto a cloth lying on the floor and stops
    # 7 mm above the floor, squeezing the cloth (resting at the 5 mm thickness) against it:
    # the cloth is pushed down and aside, never inside the foot
    foot = KeyframedBody("foot", KeyframedBodyParams(
        times=(0.0, 0.3), positions=(0.0, 0.0, 0.2, 0.0, 0.0, 0.052), dt=H))
    c = cloth(n=21, z=0.005)
    c.dt = H
    p = MeshContactParams()
    press = MeshContact("foot-cloth", foot, c, p, mode="one-way")
    floor = MeshContact("cloth-floor", c, StaticPlane("floor"), p)
    for it in (press, floor):
        it.prepare(H)
    axes = np.array(foot.params.semi_axes)
    logged = []
    for _ in range(500):
        c.clear_forces()
        floor.exchange(True, True)
        f, _, _ = press.exchange(False, True)
        logged.append(f[2])
        foot.advance(H)
        c.advance(H)
        # implicit surface of the ellipsoid: < 1 inside. The contact keeps points outside
        # the icosphere (faces up to 0.3% inside the ellipsoid) less the step's approach
        inside = (((c.x - foot.x) / axes) ** 2).sum(axis=1)
        assert inside.min() > (1 - 0.05) ** 2
    assert max(logged) > 0  # the cloth pushes back up on the foot: logged, not applied
    assert np.allclose(foot.x, (0, 0, 0.052))
