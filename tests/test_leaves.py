"""The leaves scene: the passing rider's wake lifts leaves, they fall back and come to rest on
the ground, none below it."""
import numpy as np
import pytest

from interplay import params as P
from interplay.errors import SceneError
from interplay.interactions.ground import GroundContact, GroundParams
from interplay.scenes import leaves
from interplay.systems.springmass import SpringNetwork
from interplay.systems.static import StaticPlane
from interplay.geometry import shapes


def test_leaves_lift_fall_and_rest():
    # 12 coarse leaves, the rider passing x = 0 at 0.5 s; 2.5 s leaves ~1.5 s to settle
    p = P.apply(leaves.LeavesParams(), {"leaves.count": "12", "leaves.stations": "3",
                                  "leaves.rows": "1", "rider.pass_time": "0.5",
                                  "rider.start": "-3"})
    scene = leaves.build(duration=2.5, fps=30, params=p)
    net = next(s for s in scene.systems if s.name == "leaves")
    result = scene.simulate()
    assert not result.warnings
    z = result.frames["leaves"]["points"][:, :, 2]
    assert z.max() > 0.1  # the wake lifted some leaves at least 10 cm
    # at rest: the slowest settling point moves < 1 mm/s, and every point is on the contact
    # surface (1 mm thickness) give or take the penalty's sag g / stiffness = 0.01 mm
    assert np.abs(net.v).max() < 1e-3
    assert net.x[:, 2].min() > 0.0
    assert np.allclose(net.x[:, 2], p.ground.thickness, atol=2e-4)
    assert net.strain() < 0.05
    assert {"bicyclist", "leaves"} <= set(result.frames)
    assert result.primary == "bicyclist"


@pytest.mark.parametrize("integrator,dt", [("implicit", 1 / 240), ("explicit", 2e-4)])
def test_a_dropped_cloth_rests_on_the_ground_with_friction(integrator, dt):
    x, t = shapes.grid(0.2, 0.2, 4, 4, origin=(0, 0, 0.05))
    cloth = SpringNetwork.from_mesh("cloth", x, t, 0.01, 5.0, dt=dt, integrator=integrator,
                                    mass_damping=0.5)
    cloth.v[:] = [1.0, 0.0, 0.0]  # sliding along x as it lands
    ground = StaticPlane()
    contact = GroundContact("g", ground, cloth, GroundParams(friction=0.5, thickness=0.0))
    # a held penalty force is only stable over a step the explicit network resolves: exchange
    # every network step there; the implicit one carries the contact's Jacobian and takes 1/240
    h = dt
    for _ in range(int(round(1.0 / h))):
        cloth.clear_forces()
        contact.exchange(False, True)
        cloth.advance(h)
    # friction 0.5 g = 4.9 m/s^2 stops 1 m/s of sliding within ~0.2 s, ~0.1 m
    assert np.abs(cloth.v).max() < 1e-3
    assert 0.0 < cloth.x[:, 0].min() - x[:, 0].min() < 0.2
    # resting sag g / stiffness = 0.1 mm
    assert np.allclose(cloth.x[:, 2], -9.81 / 1e5, atol=2e-5)


def test_hybrid_is_refused():
    with pytest.raises(SceneError, match="leaves supports one-way coupling, not hybrid"):
        leaves.SPEC.check_coupling("hybrid")


def _land(look_ahead: bool):
    """A cloth falling at 2 m/s onto the leaves' ground (implicit, 1/240 s, exchanged once a
    step); its lowest point (m) and its highest after it has landed."""
    x, t = shapes.grid(0.2, 0.2, 5, 5, origin=(0, 0, 0.02))
    cloth = SpringNetwork.from_mesh("cloth", x, t, 0.01, 5.0, dt=1 / 240, integrator="implicit",
                                    mass_damping=0.5)
    cloth.v[:] = [0.0, 0.0, -2.0]
    contact = GroundContact("g", StaticPlane(), cloth,
                            GroundParams(friction=0.5, thickness=0.0, stiffness=3e7,
                                         damping=1e4))
    h = 1 / 240
    contact.prepare(h if look_ahead else 0.0)
    lowest, highest_after = 0.0, -1.0
    for step in range(int(round(0.5 / h))):
        cloth.clear_forces()
        contact.exchange(False, True)
        cloth.advance(h)
        lowest = min(lowest, float(cloth.x[:, 2].min()))
        if step > 10:
            highest_after = max(highest_after, float(cloth.x[:, 2].max()))
    return lowest, highest_after


def test_a_fast_cloth_lands_on_the_ground_not_below_it():
    """Without looking ahead the penalty first sees a point once it is below the ground, up
    to v h = 8 mm down; the speculative contact stops it on the ground: no point more than 2 mm
    below (the bound every ground contact must keep), and no bounce back up."""
    blind, _ = _land(False)
    assert blind < -5e-3
    lowest, highest_after = _land(True)
    assert lowest > -2e-3
    assert highest_after < 2e-3
