"""Rigid impact zones (kernels/impact_zones.py) and the garments' guard against crossings
(systems/garment_layers.Layers.guard)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from interplay.geometry import garment as G
from interplay.geometry.aabb_tree import AABBTree
from interplay.geometry.anthropometry import body_plan
from interplay.geometry.body_surface import BodySurface, SurfaceParams
from interplay.kernels import impact_zones as IZ


def _zones(label):
    return {IZ._root(label, i) for i in np.flatnonzero(label >= 0)}


def test_zones_merge_the_corners_of_crossing_pairs():
    """Two pairs sharing triangle 1 make one zone of their corners; a third, apart, its own."""
    tris = np.array([[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11], [12, 13, 14]])
    label = np.full(15, -1, np.int64)
    IZ.merge(tris, np.array([[0, 1], [1, 2], [3, 4]]), label)
    roots = np.array([IZ._root(label, i) for i in range(15)])
    assert len(set(roots[:9])) == 1
    assert len(set(roots[9:])) == 1 and roots[9] != roots[0]


def test_a_zone_moves_by_its_best_rigid_fit_and_fixed_points_stay():
    """A zone whose points moved rigidly keeps that motion exactly; one whose points moved
    anyhow ends a rigid motion of where they started (every distance between its points as
    at the start, to round-off) through the mass-weighted centre they moved to; a fixed
    point keeps its place."""
    rng = np.random.default_rng(3)
    x0 = rng.normal(size=(12, 3))
    m = rng.uniform(0.5, 2.0, 12)
    R = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    label = np.full(12, -1, np.int64)
    IZ.merge(np.arange(12).reshape(4, 3), np.array([[0, 1], [2, 3]]), label)
    assert len(_zones(label)) == 2
    fixed = np.zeros(12, bool)
    x = x0 @ R.T + [0.1, 0.2, -0.3]
    want = x.copy()
    assert IZ.move_rigidly(x0, x, m, fixed, label) == 2
    np.testing.assert_allclose(x, want, atol=1e-12)

    x = x0 + rng.normal(scale=0.2, size=x0.shape)
    fixed[7] = True
    before = x.copy()
    centre = [np.average(x[z], axis=0, weights=m[z]) for z in (slice(0, 6), slice(6, 12))]
    IZ.move_rigidly(x0, x, m, fixed, label)
    for z, c in zip((slice(0, 6), slice(6, 12)), centre):
        d0 = np.linalg.norm(x0[z, None] - x0[None, z], axis=2)
        d = np.linalg.norm(x[z, None] - x[None, z], axis=2)
        if z.start == 0:
            np.testing.assert_allclose(d, d0, atol=1e-12)
            np.testing.assert_allclose(np.average(x[z], axis=0, weights=m[z]), c, atol=1e-12)
    assert np.array_equal(x[7], before[7])


@pytest.fixture(scope="module")
def layered():
    surface = BodySurface(body_plan(), SurfaceParams(spacing=0.025))
    from interplay.scenes import runner as RN
    from interplay.systems.garment_layers import Layers
    pants = G.sweatpants(surface, G.Fit(spacing=0.03, ease=0.025, shortest=0.3))
    shirt = G.tee(surface, G.Fit(spacing=0.03, ease=0.02), over=pants)
    net = G.network(G.join("clothes", pants, shirt), dt=1 / 240)
    net.layers = Layers(net, surface, covers=RN.COVERS)
    return net


def test_a_look_at_what_moved_finds_what_a_full_look_finds(layered):
    """The guard looks again only at the triangles with a moved point (Layers._look): 60
    points kicked 2 cm, under FULL_LOOK of the triangles, give the same crossing pairs as a
    full look, whether it finds the moved points itself or is told them."""
    from interplay.systems.garment_layers import FULL_LOOK
    net, L = layered, layered.layers
    x0 = net.x.copy()
    start = {tuple(p) for p in L._look()}
    rng = np.random.default_rng(5)
    pick = rng.choice(len(x0), 60, replace=False)
    net.x[pick] += rng.normal(scale=0.02, size=(60, 3))
    assert np.isin(net.triangles, pick).any(axis=1).mean() < FULL_LOOK
    full = {tuple(p) for p in np.sort(AABBTree(net.x, net.triangles).intersections(), axis=1)}
    looked = {tuple(p) for p in L._look()}
    # told which points moved (as the guard's rounds tell it their zones' points)
    net.x[pick] += rng.normal(scale=0.02, size=(60, 3))
    again = {tuple(p) for p in np.sort(AABBTree(net.x, net.triangles).intersections(), axis=1)}
    told = {tuple(p) for p in L._look(pick)}
    net.x[:] = x0
    assert looked == full and len(full - start) > 0
    assert told == again and again != full


@pytest.mark.parametrize("follow", [False, True])
def test_the_guard_lets_no_new_crossing_through(layered, follow):
    """The tee and pants as cut (their own few crossings at the crotch let stand), then every
    free point (the waistband's ride the skin) kicked 2 cm at random: hundreds of new
    crossing triangle pairs. After the guard none is left that was not there at the start;
    the points outside the zones are where the kick put them, those in them have the
    velocity of their move over the step. With ``follow`` the zones' points first move by a given displacement
    (as the skin carries them) and become rigid only where that still crosses."""
    net = layered
    L = net.layers
    x0 = net.x.copy()
    L.remember()
    allowed = set(map(tuple, np.sort(L.tree.intersections(), axis=1)))
    rng = np.random.default_rng(11)
    kicked = x0 + rng.normal(scale=0.02, size=x0.shape) * ~net.fixed[:, None]
    net.x[:] = kicked
    crossing = {tuple(p) for p in np.sort(AABBTree(net.x, net.triangles).intersections(), axis=1)}
    assert len(crossing - allowed) > 100
    h = 1 / 240
    carry = np.full_like(x0, np.nan)
    if follow:
        carry[::2] = [0.0, 0.0, 0.001]  # half the points near a skin that moved 1 mm up
    L.guard(x0, h, carry if follow else None)
    after = {tuple(p) for p in np.sort(AABBTree(net.x, net.triangles).intersections(), axis=1)}
    assert after <= allowed
    moved = ~np.all(net.x == kicked, axis=1)
    assert moved.any() and not moved.all()
    np.testing.assert_allclose(net.v[moved], (net.x[moved] - x0[moved]) / h)
    net.x[:], net.v[:] = x0, 0.0


def test_a_move_that_crosses_is_undone_where_it_crosses(layered):
    """From the tee and pants as cut (a state with no new crossing), every free point kicked
    1 cm at random (a last stretch limit moves them less): many new crossings. Undone
    where they cross, none is left that was not there at the start, the points of the
    crossing triangles are back where they were (position and velocity), and the others keep
    their move."""
    net = layered
    L = net.layers
    x0, v0 = net.x.copy(), np.zeros_like(net.x)
    L.remember()
    allowed = set(map(tuple, np.sort(L.tree.intersections(), axis=1)))
    rng = np.random.default_rng(12)
    kicked = x0 + rng.normal(scale=0.01, size=x0.shape) * ~net.fixed[:, None]
    net.x[:], net.v[:] = kicked, 1.0
    crossing = {tuple(p) for p in np.sort(AABBTree(net.x, net.triangles).intersections(), axis=1)}
    assert len(crossing - allowed) > 20
    sent = L.undo_new_crossings(x0, v0)
    after = {tuple(p) for p in np.sort(AABBTree(net.x, net.triangles).intersections(), axis=1)}
    assert after <= allowed
    back = np.all(net.x == x0, axis=1) & ~net.fixed
    kept = np.all(net.x == kicked, axis=1) & ~net.fixed
    assert np.all(back | kept | net.fixed)  # each point either back or where the kick put it
    assert back.sum() > 0 and kept.sum() > back.sum()  # most of the move stands
    assert np.all(net.v[back] == 0.0) and np.all(net.v[kept] == 1.0)
    assert np.array_equal(sent, back)  # it names the points it sent back (held by a next limit)
    net.x[:], net.v[:] = x0, 0.0
