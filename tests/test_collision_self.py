"""Self-collision of a cloth: a folded sheet's upper layer falls onto its lower layer and stays
above it."""
import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry.shapes import grid
from interplay.interactions.mesh_contact import MeshContact, MeshContactParams, SelfContact
from interplay.systems.springmass import SpringNetwork, Springs
from interplay.systems.static import StaticPlane

H = 1e-3  # s


def folded(n=16, size=0.4, gap=0.03):
    """A sheet folded over the line x = 0: the half x > 0 mirrored onto x < 0, gap (m) higher,
    the fold rounded off near the line. Returns the network, the upper half's mask and each
    point's mirror partner in the other layer."""
    v, t = grid(size, size, n, n, origin=(-size / 2, -size / 2, 0.01))
    x = v.copy()
    up = x[:, 0] > 1e-9
    x[up, 0] = -x[up, 0]
    x[up, 2] += gap * (1 - np.exp(-v[up, 0] / 0.02))
    cloth = SpringNetwork.from_mesh("cloth", x, t, 0.05, stretch=100.0, dt=H,
                                    integrator="implicit", mass_damping=0.5)
    mirror = np.arange(n * n).reshape(n, n)[:, ::-1].reshape(-1)
    return cloth, up, mirror


@pytest.mark.parametrize("with_self", [True, False])
def test_folded_cloth_layers_do_not_pass_through(with_self):
    cloth, up, mirror = folded()
    p = MeshContactParams(thickness=0.003, skin=0.001)
    floor = MeshContact("floor", cloth, StaticPlane("floor"), p)
    fold = SelfContact("self", cloth, p)
    for c in (floor, fold):
        c.prepare(H)
    worst = np.inf
    for _ in range(300):
        cloth.clear_forces()
        floor.exchange(True, True)
        if with_self:
            fold.exchange(True, True)
        cloth.advance(H)
        worst = min(worst, (cloth.x[up, 2] - cloth.x[mirror[up], 2]).min())
    if with_self:
        # the layers stay apart by the thickness, less what the approach (~0.5 m/s at
        # impact) presses into it while the contact resolves over its 3 steps: 1.5 mm
        assert worst > p.thickness - 3 * H * 0.5
        assert fold.n_contacts > 0
    else:
        assert worst < 1e-3  # without self-collision the layers meet (on the floor)


def test_self_contact_needs_triangles():
    net = SpringNetwork("rope", np.eye(3), 0.1, Springs.from_ratio(np.eye(3), [[0, 1], [1, 2]],
                                                                     10.0), dt=H)
    with pytest.raises(ParameterError, match=r"self: self-collision needs a network with "
                                             r"triangles; rope has none"):
        SelfContact("self", net)
