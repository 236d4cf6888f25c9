"""Segments in water: the solids' chords against brute force, their volume below a flat
surface in closed form, buoyancy from the columns equal to rho g V_sub and to the pressure the
water bears, the stand-in's drag law, several solids over one column."""
import math

import numpy as np
import pytest

from interplay.geometry.basin import BasinParams, basin
from interplay.geometry.primitive import Primitive
from interplay.interactions.buoyancy import BodyInWater, BuoyancyParams
from interplay.interactions.standins import ViscousDragField, ViscousDragFieldParams
from interplay.kernels import lids as L
from interplay.systems.rigid import RigidBody
from interplay.systems.water import SprayParams, Water, WaterParams

RHO, G = 1000.0, 9.81


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _solids(kind, centre, rot, size, volume=1.0):
    return L.Solids(np.array([kind]), np.array([centre], float), np.array([rot], float),
                    np.array([size], float), np.array([volume]), np.zeros(1))


def _inside(kind, c, R, s, p):
    """Brute-force membership of points p (n,3)."""
    q = (p - c) @ R  # in the solid's frame
    if kind == L.CAPSULE:
        t = np.clip(q[:, 2], -s[1], s[1])
        return q[:, 0] ** 2 + q[:, 1] ** 2 + (q[:, 2] - t) ** 2 <= s[0] ** 2
    if kind == L.BOX:
        return np.all(np.abs(q) <= s, axis=1)
    return ((q / s) ** 2).sum(axis=1) <= 1.0


@pytest.mark.parametrize("kind, size", [(L.CAPSULE, (0.05, 0.15, 0.0)),
                                        (L.BOX, (0.05, 0.09, 0.18)),
                                        (L.ELLIPSOID, (0.13, 0.05, 0.045))])
def test_vertical_chords_match_brute_force(kind, size):
    rng = np.random.default_rng(1)
    z = np.linspace(-0.5, 0.5, 100001)  # 10 um spacing
    for _ in range(20):
        R = _rotation(rng)
        c = rng.normal(scale=0.05, size=3)
        s = _solids(kind, c, R, size)
        for x, y in rng.normal(scale=0.08, size=(10, 2)) + c[:2]:
            lo, hi = L.chord(s, 0, x, y)
            inside = _inside(kind, c, R, np.asarray(size),
                             np.stack([np.full_like(z, x), np.full_like(z, y), z], 1))
            if not inside.any():
                assert hi <= lo
                continue
            # the sampled line brackets the chord's ends to the spacing
            assert lo == pytest.approx(z[inside][0], abs=2e-5)
            assert hi == pytest.approx(z[inside][-1], abs=2e-5)


def test_volume_below_a_flat_surface_in_closed_form():
    r, h = 0.05, 0.15  # a forearm-sized capsule: radius, half the axis segment
    vol = math.pi * r * r * (2 * h + 4.0 / 3.0 * r)
    out = np.zeros((1, 4))
    rng = np.random.default_rng(2)
    # any capsule, box or ellipsoid with its centre on the surface: half under (symmetry)
    for kind, size, v in ((L.CAPSULE, (r, h, 0), vol), (L.BOX, (0.05, 0.09, 0.18), 0.0065),
                          (L.ELLIPSOID, (0.13, 0.05, 0.045), 1e-3)):
        for _ in range(5):
            L.submerged(_solids(kind, (0.3, -0.2, 0.0), _rotation(rng), size, v), 0.0, 16, out)
            assert out[0, 0] == pytest.approx(0.5 * v, rel=1e-12)
    # an upright capsule: its lower cap and the cylinder up to the surface
    for level in (-0.1, 0.0, 0.07):
        L.submerged(_solids(L.CAPSULE, (0, 0, 0), np.eye(3), (r, h, 0), vol), level, 16, out)
        exact = 2.0 / 3.0 * math.pi * r ** 3 + math.pi * r * r * (level + h)
        # 16 x 16 chords over the shadow; the cap's chords are scaled with the rest: within 1%
        assert out[0, 0] == pytest.approx(exact, rel=1e-2)
        assert out[0, 3] < level
    # a box tilted about one axis, level through its middle third: a prism's cross-section
    a = 0.4
    Ry = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    box = (0.05, 0.09, 0.18)
    L.submerged(_solids(L.BOX, (0, 0, 0), Ry, box, 8 * np.prod(box)), 0.02, 16, out)
    # the x-z section is a rectangle 0.1 x 0.36 turned by a; the plane z = 0.02 cuts it along
    # both long sides, so the area below is the half plus a strip of width 0.02 / cos(a)
    area = 0.5 * 0.1 * 0.36 + 0.1 * 0.02 / math.cos(a)
    assert out[0, 0] == pytest.approx(area * 0.18, rel=1e-2)


def _tank(kappa=30.0, cells=64, size=0.8, depth=0.5, samples=4):
    b = basin(BasinParams(size_x=size, size_y=size, cells=cells, depth=depth, shore=0.0,
                          shape="rectangle"))
    return Water("water", b.bed, b.fluid, b.depth, b.spacing, b.origin,
                 WaterParams(body_stiffness=kappa, damping=20.0, body_samples=samples,
                             spray=SprayParams(enabled=False)))


def _capsule(name="forearm", r=0.05, h=0.15, position=(0, 0, 0.5), velocity=(0, 0, 0),
             axis=(0, 0, 1)):
    """A segment-sized rigid capsule (tissue density 1050 kg/m^3), no gravity."""
    axis = np.asarray(axis, float)
    vol = math.pi * r * r * (2 * h + 4.0 / 3.0 * r)
    return RigidBody(name, 1050.0 * vol, (0.01, 0.01, 0.01), 1e-3, position, velocity,
                     gravity=(0, 0, 0),
                     primitive=Primitive("capsule", radius=r, a=tuple(-h * axis),
                                         b=tuple(h * axis))), vol


def test_a_capsule_held_half_under_water_feels_rho_g_times_its_submerged_volume():
    water = _tank(kappa=1000.0)
    level = 0.5
    r, h = 0.05, 0.15
    body, vol = _capsule(position=(0.0, 0.0, level))  # upright, its middle at the surface
    it = BodyInWater("forearm-water", body, water, BuoyancyParams(drag=0.0, normal_drag=0.0,
                                                                  axial_drag=0.0))
    it.prepare(2e-3)
    for _ in range(800):  # 1.6 s: the water it pushed aside settles
        water.clear_forces()
        body.clear_forces()
        it.exchange(True, True)
        water.advance(2e-3)
    water.clear_forces()
    f, _, active = it.exchange(True, True)
    assert active
    # the water it displaced raised the tank's level; the surface far from it is the level
    H = water.heights()
    far = H[water.fluid].max() - H[water.fluid].min()
    assert far < 1e-4  # settled: the surface is flat to 0.1 mm
    s = H[water.fluid].mean()
    v_sub = 2.0 / 3.0 * math.pi * r ** 3 + math.pi * r * r * (s - level + h)
    # buoyancy short of rho g V_sub by the water rising 1/(1 + kappa) into the body (0.1%
    # at kappa 1000) and by the sampled cap (4 x 4 samples per 1.25 cm column: 0.5%)
    assert f[2] == pytest.approx(RHO * G * v_sub, rel=1e-2)
    assert abs(f[0]) + abs(f[1]) < 1e-6 * f[2]
    # and it is what the water bears: rho g times the external pressure head over its area
    assert f[2] == pytest.approx(RHO * G * water.ext.sum() * water.area, rel=1e-9)


def test_solids_over_one_column_share_exactly_what_the_water_bears():
    """Two capsules stacked over the same columns (a forearm under an upper arm), held while
    the water settles, are packed bottom up: their buoyancies add to the pressure the water
    bears, the lower one fully under, the upper one only with what is under the surface."""
    water = _tank(samples=8)
    level = 0.5
    lower, v1 = _capsule("lower", position=(0, 0, level - 0.25))
    upper, v2 = _capsule("upper", position=(0, 0, level + 0.1))
    its = [BodyInWater(n, b, water, BuoyancyParams(drag=0.0, normal_drag=0.0, axial_drag=0.0))
           for n, b in (("lower-water", lower), ("upper-water", upper))]
    for _ in range(500):  # 1 s
        water.clear_forces()
        for it in its:
            it.exchange(True, True)
        water.advance(2e-3)
    water.clear_forces()
    its[0].exchange(True, True)
    f2, _, _ = its[1].exchange(True, True)
    # the lower one registered first and saw only itself; together, from the columns:
    out = water.solid_loads((0, 2), np.zeros((2, 7)))
    water.heights()
    total = RHO * G * water.ext.sum() * water.area
    assert RHO * G * out[:, 0].sum() == pytest.approx(total, rel=1e-12)
    assert out[0, 0] == pytest.approx(v1, rel=1e-9)  # the lower one: all of it
    # the upper one: at a sample rho from the axis (w = sqrt(r^2 - rho^2)) the lower's chord
    # 0.3 + 2w starts at 0.1 - w; the column's head keeps kappa / (1 + kappa) (s - bottom) out
    # of it, and the upper gets what the lower's chord leaves; integrated over the disc
    s = water.heights()[water.fluid].mean()
    r, k = 0.05, 30.0 / 31.0
    packed = (k * ((s - 0.1) * math.pi * r * r + 2.0 / 3.0 * math.pi * r ** 3)
              - (0.3 * math.pi * r * r + 4.0 / 3.0 * math.pi * r ** 3))
    # the upper's share is a difference of larger volumes, so the lower's sampled chords
    # (8 x 8 samples per 1.25 cm column, scaled to its exact volume) show in it 5-fold: 3 %
    assert out[1, 0] == pytest.approx(packed, rel=0.03)
    assert f2[2] == pytest.approx(RHO * G * out[1, 0], rel=1e-12)


@pytest.mark.parametrize("axis, speed", [((1, 0, 0), 2.0), ((0, 0, 1), 3.0),
                                         ((0.6, 0, 0.8), 1.5)])
def test_a_capsule_moving_steadily_through_the_drag_field_feels_its_law(axis, speed):
    """Fully under, moving at constant velocity along -z: the field's form drag splits the
    velocity into the part along the capsule's axis (end-on, C_a pi r^2) and the part across
    it (broadside, C_n (4 r h + pi r^2)), plus its linear and quadratic terms and buoyancy."""
    r, h = 0.05, 0.15
    v = np.array([0.0, 0.0, -speed])
    body, vol = _capsule(position=(0, 0, -1.0), velocity=v, axis=axis)
    form = BuoyancyParams(normal_drag=1.1, axial_drag=0.3)
    p = ViscousDragFieldParams(surface=0.0, linear=2.0, quadratic=5.0, density=RHO)
    field = ViscousDragField(p, form)
    f, torque, active = field.act(body)
    assert active
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    va = (v @ u) * u
    vn = v - va
    expect = -(2.0 + 5.0 * speed) * v - 0.5 * RHO * (
        1.1 * (4 * r * h + math.pi * r * r) * np.linalg.norm(vn) * vn
        + 0.3 * math.pi * r * r * np.linalg.norm(va) * va)
    expect[2] += RHO * G * vol
    np.testing.assert_allclose(f, expect, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(body.force, f, rtol=1e-12)
    assert np.abs(torque).max() < 1e-9  # a symmetric part moving without spin
    # the same over the whole run: constant velocity, so the law is the same at every step
    body.clear_forces()
    body.v[:] = 2 * v
    f2, _, _ = field.act(body)
    drag, drag2 = f - [0, 0, RHO * G * vol], f2 - [0, 0, RHO * G * vol]
    quad = drag - (-(2.0 + 5.0 * speed) * v)
    quad2 = drag2 - (-(2.0 + 5.0 * 2 * speed) * 2 * v)
    np.testing.assert_allclose(quad2, 4.0 * quad, rtol=1e-12)  # form drag ~ v^2


def test_a_box_feels_the_drag_of_each_face_along_its_axes():
    """Turned about z, moving obliquely: each velocity component along a box axis meets the
    face across it, -1/2 rho C_n 4 h_i h_j |v_k| v_k."""
    half = np.array([0.05, 0.09, 0.18])
    a = 0.3
    body = RigidBody("torso", 20.0, (0.1, 0.1, 0.1), 1e-3, (0, 0, -2.0), (1.0, 0.5, -2.0),
                     gravity=(0, 0, 0), primitive=Primitive("box", axes=tuple(half)))
    body.q[:] = (math.cos(a / 2), 0.0, 0.0, math.sin(a / 2))
    R = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
    field = ViscousDragField(ViscousDragFieldParams(linear=0.0, quadratic=0.0, density=0.0),
                             BuoyancyParams(normal_drag=1.05))
    f, _, _ = field.act(body)
    vb = R.T @ body.v
    faces = 4 * np.array([half[1] * half[2], half[0] * half[2], half[0] * half[1]])
    np.testing.assert_allclose(f, R @ (-0.5 * RHO * 1.05 * faces * np.abs(vb) * vb),
                               rtol=1e-12)
