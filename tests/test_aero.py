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


def test_kernel_matches_formula():
    rng = np.random.default_rng(1)
    x, tris = shapes.grid(1.0, 0.7, 5, 4)
    x = x + rng.normal(0, 0.05, x.shape)
    v = rng.normal(0, 2.0, x.shape)
    wind = rng.normal(0, 3.0, (len(tris), 3))
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
