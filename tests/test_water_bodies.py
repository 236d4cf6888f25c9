"""Bodies in water: Archimedes, damped bobbing, sinking, one-way, the stand-in, bad input."""
import math

import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry.basin import BasinParams, basin
from interplay.interactions.buoyancy import BodyInWater, BuoyancyParams, ResolutionWarning
from interplay.interactions.contact import ContactParams, SpherePlaneContact
from interplay.interactions.standins import ViscousDragField, ViscousDragFieldParams
from interplay.scene import Scene
from interplay.systems.kinematic import KeyframedBody, KeyframedBodyParams
from interplay.systems.rigid import Sphere, SphereParams
from interplay.systems.static import StaticPlane
from interplay.systems.water import SprayParams, Water, WaterParams

DEPTH = 0.3
R = 0.06


def pond_with_ball(density, duration, damping=0.5):
    b = basin(BasinParams(size_x=1.0, size_y=1.0, cells=48, depth=DEPTH, shore=0.0,
                          shape="rectangle"))
    water = Water("water", b.bed, b.fluid, b.depth, b.spacing, b.origin,
                  WaterParams(damping=damping, spray=SprayParams(enabled=False)))
    mass = density * 4.0 / 3.0 * math.pi * R ** 3
    ball = Sphere("ball", SphereParams(radius=R, mass=mass, shell=False, dt=1e-3),
                  position=(0.0, 0.0, DEPTH + R + 0.05))
    scene = Scene("t", duration=duration, fps=20, coupling_dt=2e-3)
    scene.add(ball)
    scene.add(water)
    floor = scene.add(StaticPlane("bed", 0.0))
    scene.connect(BodyInWater("ball-water", ball, water))
    scene.connect(SpherePlaneContact("ball-bed", ball, floor,
                                     ContactParams(stiffness=2e4, damping=250.0,
                                                   thickness=0.0)))
    return scene, ball, water


def test_a_half_density_ball_floats_at_the_archimedes_depth_and_stops_bobbing():
    scene, ball, water = pond_with_ball(500.0, 4.0)
    res = scene.simulate()
    tr = res.tracks["ball"]
    z = tr.x[:, 2]
    # Archimedes: half the ball below the water level, which the ball itself raised by its
    # displaced volume over the wet area
    level = DEPTH + ball.mass / water.rho / (water.fluid.sum() * water.area)
    depth = level - (z[-1] - R)  # submerged depth, R by Archimedes
    # the penalty head leaves water 1/(1 + kappa) of the way into the ball: the ball rests
    # 2R / (3 (1 + kappa)) = 2.2% of R deeper for kappa = 30; 5% allows for the waves left
    assert abs(depth - R) < 0.05 * R
    first = z[(tr.t > 0.2) & (tr.t < 1.2)]
    last = z[tr.t > 3.0]
    assert np.ptp(last) < 0.2 * np.ptp(first)  # bobbing damped (waves carry energy away)
    stats = res.interaction_stats()[0]
    assert stats["force_N"]["max"] > ball.mass * 9.81  # the landing: more than its weight


def test_a_dense_ball_sinks_to_the_bed():
    scene, ball, water = pond_with_ball(2000.0, 1.5)
    scene.simulate()
    # it rests on the bed contact: penetration mg(1 - rho_w/rho_b)/k = 0.2 mm
    assert ball.x[2] == pytest.approx(R, abs=2e-3)
    assert abs(ball.v[2]) < 0.05


def test_two_way_buoyancy_is_rho_g_times_the_pressure_the_water_bears():
    scene, ball, water = pond_with_ball(500.0, 0.4)
    it = scene.interactions[0]
    scene.simulate()
    water.clear_forces()
    ball.clear_forces()
    it.p = BuoyancyParams(drag=0.0)  # the exchange is pure buoyancy
    f, _, active = it.exchange(True, True)
    assert active
    water.heights()  # fills ext from the lids the exchange registered
    # equal and opposite: the external pressure head the water bears, times rho g l^2
    assert f[2] == pytest.approx(water.rho * water.g * water.ext.sum() * water.area, rel=1e-9)


def test_a_ball_too_small_for_the_columns_warns_with_the_resolution_needed():
    b = basin(BasinParams(size_x=1.0, size_y=1.0, cells=16, depth=0.2))
    water = Water("water", b.bed, b.fluid, b.depth, b.spacing, b.origin)
    ball = Sphere("pebble", SphereParams(radius=0.02, mass=0.05, shell=False))
    with pytest.warns(ResolutionWarning, match=r"pebble is 0\.04 m across but the water's "
                                               r"columns are 0\.0625 m .* at most 0\.01 m"):
        BodyInWater("pebble-water", ball, water)


def test_an_unstable_added_mass_is_refused():
    b = basin(BasinParams(size_x=1.0, size_y=1.0, cells=16, depth=0.2))
    water = Water("water", b.bed, b.fluid, b.depth, b.spacing, b.origin)
    ball = Sphere("ball", SphereParams(radius=0.1, mass=1.0, shell=False))
    with pytest.raises(ParameterError, match=r"added mass .* is not below ball's mass .* "
                                             r"use added_mass <"):
        BodyInWater("bw", ball, water, BuoyancyParams(added_mass=0.5))


def test_one_way_leaves_the_keyframed_foot_on_its_path_and_moves_the_water():
    b = basin(BasinParams(size_x=0.8, size_y=0.5, cells=64, depth=0.02, shore=0.1))
    water = Water("water", b.bed, b.fluid, b.depth, b.spacing, b.origin)
    keys = KeyframedBodyParams(times=(0.0, 0.1, 0.3), positions=(-0.2, 0, 0.2, 0, 0, 0.045,
                                                                 0, 0, 0.045))
    foot = KeyframedBody("foot", keys)
    scene = Scene("t", duration=0.3, fps=30, coupling_dt=2e-3)
    scene.add(foot)
    scene.add(water)
    scene.connect(BodyInWater("foot-water", foot, water, mode="one-way"))
    v0 = water.V.copy()
    res = scene.simulate()
    assert ["+".join(p["systems"]) for p in res.passes] == ["foot", "water"]
    np.testing.assert_allclose(res.state_at("foot", 0.3)[0], (0, 0, 0.045), atol=1e-12)
    assert np.abs(water.V - v0).max() > 1e-6  # the water was pushed from under the foot
    assert res.logs["foot-water"].active.any()


def test_keyframes_must_increase():
    with pytest.raises(ParameterError, match="key times must increase strictly"):
        KeyframedBody("foot", KeyframedBodyParams(times=(0.0, 0.0)))
    with pytest.raises(ParameterError, match="x, y, z for each of the 2 keys"):
        KeyframedBody("foot", KeyframedBodyParams(positions=(0.0, 0.0, 0.0)))


def test_viscous_drag_field_acts_on_the_submerged_part_only():
    ball = Sphere("ball", SphereParams(radius=0.1, mass=1.0, shell=False),
                  position=(0, 0, 0.5), velocity=(0, 0, -1.0))
    vol = 4.0 / 3.0 * math.pi * 0.1 ** 3
    field = ViscousDragField(ViscousDragFieldParams(surface=0.0, linear=2.0, quadratic=0.0,
                                                    density=1000.0))
    f, _, active = field.act(ball)
    assert not active and not f.any()
    ball.x[2] = 0.0  # half under: f = 1/2
    ball.clear_forces()
    f, _, active = field.act(ball)
    assert active
    assert f[2] == pytest.approx(2.0 * 0.5 * 1.0 + 1000.0 * 9.81 * vol * 0.5)
    assert ball.force[2] == pytest.approx(f[2])
