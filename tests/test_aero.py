"""Per-triangle drag and lift: the kernel against the formula, lift across the wind, and the
terminal velocity of a plate falling flat."""
import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry import shapes
from interplay.interactions.aero import AeroParams, Aerodynamics
from interplay.kernels import aero as K
from interplay.systems.springmass import SpringNetwork, Springs
from interplay.systems.wind import FlowPrimitive, WindField


def reference(x, v, tris, wind, cn, ct):
    """Plain NumPy: f = -cn s |v| (n.v) n - ct s (v - (n.v) n), f/3 to each point."""
    f = np.zeros_like(x)
    for t, (i, j, k) in enumerate(tris):
        cr = np.cross(x[j] - x[i], x[k] - x[i])
        s, n = 0.5 * np.linalg.norm(cr), cr / np.linalg.norm(cr)
        vr = v[[i, j, k]].mean(0) - wind[t]
        fa = -cn * s * np.linalg.norm(vr) * (n @ vr) * n - ct * s * (vr - (n @ vr) * n)
        for p in (i, j, k):
            f[p] += fa / 3
    return f


def random_sheet(seed):
    """A jittered 5x4 sheet (m) with random point velocities and winds at its centroids (m/s)."""
    rng = np.random.default_rng(seed)
    x, tris = shapes.grid(1.0, 0.7, 5, 4)
    x = x + rng.normal(0, 0.05, x.shape)
    return x, tris, rng.normal(0, 2.0, x.shape), rng.normal(0, 3.0, (len(tris), 3))


def test_kernel_matches_formula():
    x, tris, v, wind = random_sheet(1)
    f = np.zeros_like(x)
    total = K.triangle_forces(x, v, tris, wind, 0.7, 0.05, f, np.zeros((len(x), 3, 3)), False)
    assert np.allclose(f, reference(x, v, tris, wind, 0.7, 0.05), rtol=1e-10, atol=1e-13)
    assert np.allclose(total, f.sum(0))
    # reversing every triangle's winding flips n: the force is the same
    f2 = np.zeros_like(x)
    K.triangle_forces(x, v, tris[:, ::-1].copy(), wind, 0.7, 0.05, f2, np.zeros((len(x), 3, 3)),
                      False)
    assert np.allclose(f, f2)


def plate_forces(angle, speed=10.0, cn=0.7, ct=0.0):
    """A 1 m^2 plate at rest pitched by `angle` (rad) about y, in a uniform wind along +x."""
    x, tris = shapes.grid(1.0, 1.0, 2, 2, origin=(-0.5, -0.5, 0.0))
    c, s = np.cos(angle), np.sin(angle)
    x = x @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T  # tilt the leading edge up
    wind = np.tile([speed, 0.0, 0.0], (len(tris), 1))
    f = np.zeros_like(x)
    return K.triangle_forces(x, np.zeros_like(x), tris, wind, cn, ct, f,
                             np.zeros((len(x), 3, 3)), False)


def test_lift_is_perpendicular_to_the_wind():
    cn, U = 0.7, 10.0
    for deg in (10, 30, 45, 60):
        a = np.radians(deg)
        F = plate_forces(a, U, cn)
        # the normal force c_n s U^2 sin(a) splits into drag sin^2(a) along the wind and lift
        # sin(a) cos(a) across it (up, in +z, with the leading edge raised), none sideways
        assert F[0] == pytest.approx(cn * U ** 2 * np.sin(a) ** 2, rel=1e-12)
        assert F[2] == pytest.approx(cn * U ** 2 * np.sin(a) * np.cos(a), rel=1e-12)
        assert F[1] == pytest.approx(0.0, abs=1e-12)
    # no lift edge-on (only skin friction, along the wind) or face-on
    F = plate_forces(0.0, U, cn, ct=0.05)
    assert F[2] == pytest.approx(0.0, abs=1e-12) and F[0] == pytest.approx(0.05 * U)
    assert plate_forces(np.pi / 2, U, cn)[2] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("integrator", ["explicit", "implicit"])
def test_falling_plate_reaches_terminal_velocity(integrator):
    m, side, cn, g = 0.01, 0.2, 0.7, 9.81
    x, tris = shapes.grid(side, side, 3, 3, origin=(0, 0, 100.0))
    h = 1e-3
    plate = SpringNetwork.from_mesh("plate", x, tris, m, stretch=20.0, dt=h, integrator=integrator)
    air = Aerodynamics("air", WindField("still", [FlowPrimitive("uniform", strength=0.0)]), plate,
                       AeroParams(drag=cn, friction=0.1))
    for _ in range(3000):
        plate.clear_forces()
        air.exchange(False, True)
        plate.advance(h)
    vt = np.sqrt(m * g / (cn * side * side))  # 2.65 m/s; time constant vt/g = 0.27 s
    # after 3 s = 11 time constants v = vt tanh(g t / vt) is within 1e-9 of vt, and the
    # steady state of either discrete step is exact (drag = weight), so 1e-6 is all rounding
    assert np.allclose(plate.v[:, 2], -vt, rtol=1e-6)
    assert np.allclose(plate.v[:, :2], 0.0, atol=1e-9)  # it stays flat: no sideways lift


def test_aero_needs_a_surface():
    x = np.array([[0, 0, 0], [1, 0, 0.0]])
    cord = SpringNetwork("cord", x, 1.0, Springs.from_ratio(x, [(0, 1)], 1.0))
    with pytest.raises(ParameterError, match="cord has no triangles"):
        Aerodynamics("air", WindField("w"), cord)


def spec_plate_force(x, v, tris, wind, cn, ct):
    """SPEC 2.2's law evaluated in plain Python floats in the kernel's own order of operations
    (IEEE doubles, no fused or reordered arithmetic): the plate law must give these bits."""
    f = np.zeros_like(x)
    for t, (i, j, k) in enumerate(tris):
        e1, e2 = [x[j, c] - x[i, c] for c in range(3)], [x[k, c] - x[i, c] for c in range(3)]
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
             e1[0] * e2[1] - e1[1] * e2[0]]
        a2 = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        n = [c / a2 for c in n]
        s = 0.5 * a2
        r = [(v[i, c] + v[j, c] + v[k, c]) / 3.0 - wind[t, c] for c in range(3)]
        speed = np.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        vn = n[0] * r[0] + n[1] * r[1] + n[2] * r[2]
        cnn = -cn * s * speed * vn
        fa = [cnn * n[c] - ct * s * (r[c] - vn * n[c]) for c in range(3)]
        for p in (i, j, k):
            for c in range(3):
                f[p, c] += fa[c] / 3.0
    return f


def test_plate_law_is_bit_identical_to_spec():
    """The default law (and law="plate" through the interaction) is SPEC 2.2's to the bit:
    every scene that does not ask for the delta law moves exactly as before it existed."""
    x, tris, v, wind = random_sheet(7)
    f = np.zeros_like(x)
    K.triangle_forces(x, v, tris, wind, 0.7, 0.02, f, np.zeros((len(x), 3, 3)), False)
    assert np.array_equal(f, spec_plate_force(x, v, tris, wind, 0.7, 0.02))
    net = SpringNetwork.from_mesh("sheet", x, tris, 0.1, stretch=20.0)
    net.v[:] = v
    field = WindField("w", [FlowPrimitive("uniform", strength=3.0, axis=(1, 0.2, 0.1))])
    ref = Aerodynamics("a", field, net, AeroParams()).forces()[0].copy()
    plate = Aerodynamics("b", field, net, AeroParams(law="plate", potential=4.0)).forces()[0]
    assert np.array_equal(ref, plate)
    w = np.tile(field.velocity(x[:1], 0.0)[0], (len(tris), 1))
    assert np.array_equal(ref, spec_plate_force(x, v, tris, w, 0.7, 0.02))


def polhamus(deg, kp, kv, stall, cn=0.7, rho=1.2):
    """C_N of the delta law, written from Polhamus (1966) independently of the kernel: K_p sin
    cos^2 + K_v sin^2 cos up to the stall, above it the larger of its value there and the
    plate's 2 c_n / rho sin."""
    def pol(a):
        return kp * np.sin(a) * np.cos(a) ** 2 + kv * np.sin(a) ** 2 * np.cos(a)
    a, s = np.radians(deg), np.radians(stall)
    return pol(a) if a <= s else max(pol(s), 2 * cn / rho * np.sin(a))


@pytest.mark.parametrize("deg", [5.0, 10.0, 20.0, 29.0, 45.0, 80.0])
def test_delta_law_matches_polhamus(deg):
    """One triangle at rest in a uniform wind, its plane at `deg` to the wind: the force is
    q s C_N(a) along its normal plus the skin friction c_t s v along it, C_N from Polhamus's
    closed form (at 20 deg, K_p = 2.5, K_v = pi: C_N = 1.10 against the plate law's 0.41).
    The kernel and this evaluation differ only in the order of operations: rel 1e-12."""
    kp, kv, stall, rho, ct, U = 2.5, np.pi, 30.0, 1.2, 0.02, 9.0
    a = np.radians(deg)
    # a right triangle of legs 1 and 0.8 (s = 0.4 m^2) in the plane holding y, tilted by a
    x = np.array([[0.0, 0.0, 0.0], [np.cos(a), 0.0, np.sin(a)], [0.0, 0.8, 0.0]])
    tris = np.array([[0, 1, 2]])
    p = AeroParams(law="delta", potential=kp, vortex=kv, stall=stall, density=rho, friction=ct)
    net = SpringNetwork.from_mesh("tri", x, tris, 0.01, stretch=20.0)
    air = Aerodynamics("air", WindField("w", [FlowPrimitive("uniform", strength=U)]), net, p)
    F = air.forces()[2]
    n = np.array([-np.sin(a), 0.0, np.cos(a)])  # the unit normal (either sign: same force)
    w = np.array([U, 0.0, 0.0])
    q, s = 0.5 * rho * U * U, 0.4
    expect = q * s * polhamus(deg, kp, kv, stall) * np.sign(w @ n) * n \
        + ct * s * (w - (w @ n) * n)
    assert np.allclose(F, expect, rtol=1e-12, atol=1e-12)
    assert polhamus(20.0, kp, kv, stall) == pytest.approx(1.10, abs=0.005)


def test_delta_law_refuses_an_unknown_law():
    x, tris = shapes.grid(1.0, 1.0, 2, 2)
    net = SpringNetwork.from_mesh("sheet", x, tris, 0.1, stretch=20.0)
    with pytest.raises(ParameterError, match="unknown aerodynamic law 'wing'.*plate, delta"):
        Aerodynamics("air", WindField("w"), net, AeroParams(law="wing"))


def centre_along(f, x, axis):
    """The force-weighted centre (m) along ``axis`` of point forces f (n,3) at x (n,3)."""
    w = np.abs(f @ np.cross(axis, [0.0, 1.0, 0.0]))  # the part normal to a plate holding y
    return float(w @ (x @ axis) / w.sum())


@pytest.mark.parametrize("deg", [5.0, 15.0, 30.0, 60.0, 90.0])
def test_chordwise_centre_follows_a_flat_plate(deg):
    """centre="chord": a flat rectangular plate (chord 1 m, span 2 m) at rest in a uniform
    wind, pitched by `deg` with its leading edge upstream, has its centre of pressure at
    (0.2 + 0.3 sin a) of the chord from the leading edge (Joessel): 0.217 c at 5 deg, the
    middle across the flow; the per-triangle law has it in the middle at every angle. The
    total force and each triangle's direction are the law's: the change is a couple, to
    round-off. The kernel's bisection leaves 80 / 2^50 in its exponent: the centre is exact to
    far below the 1e-9 m asked."""
    a = np.radians(deg)
    x, tris = shapes.grid(1.0, 2.0, 21, 11, origin=(0.0, -1.0, 0.0))
    chord = np.array([np.cos(a), 0.0, np.sin(a)])  # from the leading edge, tilted up by a
    x = np.outer(x[:, 0], chord) + np.outer(x[:, 1], [0.0, 1.0, 0.0])
    wind = np.tile([8.0, 0.0, 0.0], (len(tris), 1))
    f0, f = np.zeros_like(x), np.zeros_like(x)
    cent = x[tris].mean(axis=1)
    plate = K.triangle_forces(x, np.zeros_like(x), tris, wind, 0.7, 0.0, f0,
                              np.zeros((len(x), 3, 3)), False)
    info = np.zeros((len(tris), 8))
    total = K.triangle_forces(x, np.zeros_like(x), tris, wind, 0.7, 0.0, f,
                              np.zeros((len(x), 3, 3)), False, 0, 0.0, 0.0, 1.0, 0.0, info)
    assert np.array_equal(f, f0)  # the info output changes nothing
    change = K.chordwise_centre(x, tris, cent, info, f)
    assert np.allclose(change, 0.0, atol=1e-12 * np.abs(plate).max())
    assert np.allclose(total + change, plate, rtol=1e-12)
    normal = np.cross(chord, [0.0, 1.0, 0.0])
    assert np.allclose(f - (f @ normal)[:, None] * normal, 0.0, atol=1e-12)
    assert centre_along(f0, x, chord) == pytest.approx(0.5, abs=1e-12)
    assert centre_along(f, x, chord) == pytest.approx(0.2 + 0.3 * np.sin(a), abs=1e-9)


def test_chordwise_centre_on_a_delta_and_through_the_interaction():
    """Any planform: the centre of pressure lies at x_le + (x_A - x_le)(0.4 + 0.6 sin a) along
    the flow, x_A the area centroid (a delta, nose upstream: x_A = 2/3 of its length). The
    interaction with AeroParams(centre="chord") gives the kernels' forces; an unknown centre is
    refused in one line naming the choices."""
    a, L = np.radians(20.0), 0.9
    corners = [((0, 0, 0), (L, 1.1, 0), (L, 0, 0)), ((0, 0, 0), (L, 0, 0), (L, -1.1, 0))]
    from interplay.geometry.kite import subdivided
    x, tris = subdivided(corners, 8)
    chord = np.array([np.cos(a), 0.0, np.sin(a)])
    x = np.outer(x[:, 0], chord) + np.outer(x[:, 1], [0.0, 1.0, 0.0])
    net = SpringNetwork.from_mesh("delta", x, tris, 0.05, stretch=20.0)
    field = WindField("w", [FlowPrimitive("uniform", strength=8.0)])
    f = Aerodynamics("air", field, net, AeroParams(centre="chord", friction=0.0)).forces()[0]
    assert centre_along(f, x, chord) == pytest.approx(2 * L / 3 * (0.4 + 0.6 * np.sin(a)),
                                                      abs=1e-9)
    with pytest.raises(ParameterError, match="unknown centre of pressure 'nose'.*triangles, "
                                             "chord"):
        Aerodynamics("air", field, net, AeroParams(centre="nose"))
