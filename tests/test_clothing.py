"""Clothing (issue 16): the skinned body surface, the garment builder, the skin contact."""
import copy

import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry import garment as G
from interplay.geometry.aabb_tree import AABBTree
from interplay.geometry.anthropometry import body_plan
from interplay.geometry import clearance as C
from interplay.geometry.body_surface import LIMBS, BodySurface, SurfaceParams, edge_use
from interplay.geometry.clearance import ClearanceParams
from interplay.geometry.mesh import edges
from interplay.interactions.skin_contact import SkinContactParams, _Projector
from interplay.systems.mocap import MocapFigure, clip_path
from interplay.systems.springmass import SpringNetwork


@pytest.fixture(scope="module")
def surface():
    return BodySurface(body_plan(), SurfaceParams(spacing=0.025))


@pytest.fixture(scope="module")
def run_clip():
    path = clip_path("cmu_02_03_run.bvh")
    if not path.exists():
        pytest.skip("no motion-capture data (../shared/data)")
    return MocapFigure("runner", path, ground=0.0)


def volume(x, t):
    return float(np.einsum("ij,ij->i", x[t[:, 0]], np.cross(x[t[:, 1]], x[t[:, 2]])).sum() / 6)


# --- the body surface ------------------------------------------------------------------------
def test_the_skin_is_closed_outward_and_holds_the_body(surface):
    """Every edge in exactly two triangles, one piece of genus 0 (V - E + F = 2), wound
    outward (positive volume), holding the body's tissue: its volume times the tissue density
    within 20% of the plan's mass (the head, hands and feet are not made of capsules)."""
    x, t = surface.vertices0, surface.triangles
    assert np.all(edge_use(t) == 2)
    e, _, _ = edges(t)
    assert len(x) - len(e) + len(t) == 2
    mass = sum(s.mass for s in surface.plan)
    assert abs(volume(x, t) * 1050.0 / mass - 1.0) < 0.2


def test_the_skin_bends_at_the_joints_without_cracks(surface, run_clip):
    """Posed by the run clip, the skin keeps its topology (it is one mesh moved by convex
    combinations of rigid motions) and no edge grows more than 2.5x its A-pose length at the
    shoulders, hips and knees (a crack would be a jump in length), sampled every 0.1 s."""
    skin = BodySurface(run_clip.plan, SurfaceParams(spacing=0.03))
    e, _, _ = edges(skin.triangles)
    l0 = np.linalg.norm(skin.vertices0[e[:, 0]] - skin.vertices0[e[:, 1]], axis=1)
    for t in np.arange(0.0, run_clip.duration, 0.1):
        run_clip.set_time(t)
        X = skin.pose(*run_clip.part_poses())
        ratio = np.linalg.norm(X[e[:, 0]] - X[e[:, 1]], axis=1) / l0
        assert ratio.max() < 2.5, f"t={t:.1f}: an edge {ratio.max():.2f}x its rest length"


@pytest.fixture(scope="module")
def cleared_clip():
    path = clip_path("cmu_02_03_run.bvh")
    if not path.exists():
        pytest.skip("no motion-capture data (../shared/data)")
    return MocapFigure("runner", path, ground=0.0, clearance=ClearanceParams())


@pytest.fixture(scope="module")
def runner_skin(cleared_clip):
    return BodySurface(cleared_clip.plan, SurfaceParams())


def limb_of_triangles(skin):
    """Each skin triangle's limb (index into LIMBS): the one most of its corners belong to."""
    corner = skin.vertex_limbs()[skin.triangles]
    return np.array([np.bincount(c, minlength=len(LIMBS)).argmax() for c in corner])


def test_the_cleared_clip_keeps_its_hands_off_the_hips_and_its_legs_apart(run_clip,
                                                                          cleared_clip):
    """Clearance (geometry/clearance.py) turns the arms and legs out by the least angle that
    keeps the gaps: at every frame of the clip each hand and forearm stands ``arms`` off the
    pelvis, torso and thighs, and each leg below its upper thigh ``legs`` off the other, less
    the sampling's error (checked on samples 5 mm apart, twice as fine as the search's 1 cm:
    between two of its samples on a round cone of 2 cm radius or more a surface lies less
    than (7 mm)^2 / (2 x 2 cm) = 1.2 mm nearer, held to 2.5 mm; the angle's 1 deg step is on
    the safe side), also between the clip's frames. Without it the
    clip swings a hand 7 cm into the hip. The angles never fall below what a frame needs,
    and the rest of the body is the clip's: the pelvis and torso turn and travel as in it."""
    p = ClearanceParams()
    limbs = C._Limbs(cleared_clip.plan, spacing=0.005)
    none = np.eye(3)[None]
    worst = {"arms": np.inf, "legs": np.inf, "before": np.inf}
    for t in np.arange(0.0, cleared_clip.duration, 1 / 60):
        cleared_clip.set_time(t)
        run_clip.set_time(t)
        pos, rot = cleared_clip.part_poses()
        for side in "lr":
            parts = (f"{side}_forearm", f"{side}_hand")
            worst["arms"] = min(worst["arms"], limbs.gap(parts, pos, rot, C.ARM_OBSTACLES,
                                                         (pos[0], none))[0])
            worst["before"] = min(worst["before"], limbs.gap(
                parts, *run_clip.part_poses(), C.ARM_OBSTACLES, (pos[0], none))[0])
        worst["legs"] = min(worst["legs"], limbs.gap(C.LEG["l"], pos, rot, C.LEG["r"],
                                                     (pos[0], none))[0],
                            limbs.gap(C.LEG["r"], pos, rot, C.LEG["l"], (pos[0], none))[0])
        p0, r0 = run_clip.part_poses()
        # (the height is planted again: legs turned out reach less far down)
        assert np.allclose(pos[:2, :2], p0[:2, :2], atol=1e-9) and np.allclose(rot[:2], r0[:2])
    sag = 0.0025
    assert worst["before"] < -0.05
    assert worst["arms"] >= p.arms - sag
    assert worst["legs"] >= p.legs - sag
    need = np.array([0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0])
    assert np.all(C._widen(need, 3) >= need - 1e-15)


def test_limbs_cross_each_other_only_at_the_crotch_seam_over_the_run_clip(cleared_clip,
                                                                           runner_skin):
    """The skin posed by the cleared clip (the runner's 1.8 cm mesh), sampled every 0.05 s:
    the hands pass the hips and the arms come down against the trunk without their skins
    passing through each other, and the thighs pass each other (LIMBS: the push where limbs
    meet). What is left, measured: at most 4 triangle pairs between limbs over the clip, all
    at the crotch's front seam (within 3 cm of the pelvis's mid-plane), where the midline
    vertices are carried half by each thigh. Without the push: 18 pairs in 7 samples."""
    skin = runner_skin
    plain = copy.copy(skin)  # the same mesh and weights, posed by linear blending alone
    plain.contacts = []
    limb = limb_of_triangles(skin)
    tree = AABBTree(skin.vertices0, skin.triangles)
    between = {"pushed": 0, "plain": 0}
    for t in np.arange(0.0, cleared_clip.duration, 0.05):
        cleared_clip.set_time(t)
        pos, rot = cleared_clip.part_poses()
        for name, surface in (("pushed", skin), ("plain", plain)):
            X = surface.pose(pos, rot)
            tree.refit(X)
            pairs = tree.intersections()
            across = pairs[limb[pairs[:, 0]] != limb[pairs[:, 1]]] if len(pairs) else pairs
            between[name] += len(across)
            if name == "pushed":
                for a, b in across:
                    side = (X[skin.triangles[[a, b]]].reshape(-1, 3) - pos[0]) @ rot[0][:, 1]
                    assert np.abs(side).max() < 0.03, f"t={t:.2f}: limbs cross off the crotch"
    assert between["pushed"] <= 4
    assert between["plain"] >= 10


@pytest.mark.xfail(strict=True, reason="the crotch's front seam and the right groin at its "
                   "deepest flexion: 1-3 triangle pairs in 2 of 29 samples (docs/clothing.md)")
def test_the_skin_never_crosses_itself_over_the_run_clip(cleared_clip, runner_skin):
    tree = AABBTree(runner_skin.vertices0, runner_skin.triangles)
    for t in np.arange(0.0, cleared_clip.duration, 0.05):
        cleared_clip.set_time(t)
        tree.refit(runner_skin.pose(*cleared_clip.part_poses()))
        assert len(tree.intersections()) == 0, f"t={t:.1f}"


def test_the_skins_signed_distance_tells_the_side_exactly_off_thin_parts(runner_skin):
    """The side of a point off the skin mesh is told by the pseudonormal of the feature its
    closest point lies on (face, edge or corner: exact for a closed mesh, Baerentzen &
    Aanaes 2005). Points about 3 cm from the hands, toes, shoulders and a hip: every one
    more than 1 cm off the implicit body gets its side (the runner's 2 cm triangles stand
    off the implicit body by at most a chord's sag, (3 cm)^2 / (8 x 1.2 cm) < 1 cm on the
    toes' rounded edges), and the mesh has no face turned inside out (at 2 cm the toes,
    thinner than two cells, had 5). Normals interpolated
    over the closest triangle told points 4 cm off a hand's tip 4 cm inside."""
    surface = runner_skin
    X, T = surface.vertices0, surface.triangles
    normal = np.cross(X[T[:, 1]] - X[T[:, 0]], X[T[:, 2]] - X[T[:, 0]])
    assert np.all(np.einsum("ij,ij->i", normal, surface.gradient(X[T].mean(axis=1))) > 0)
    rng = np.random.default_rng(3)
    names = [s.name for s in surface.plan]
    ends = [surface.pos0[names.index(n)] + surface.rot0[names.index(n)]
            @ surface.plan[names.index(n)].bone for n in ("l_hand", "r_hand", "l_toes",
                                                          "r_toes")]
    ends += [surface.pos0[names.index(n)] for n in ("l_upper_arm", "r_upper_arm", "l_thigh")]
    pts = np.concatenate([c + rng.normal(0.0, 0.03, (3000, 3)) for c in ends])
    truth = surface.sdf(pts)
    s, _ = surface.mesh_distance(pts, reach=0.05)
    keep = (np.abs(truth) > 0.01) & np.isfinite(s)
    assert keep.sum() > 10000
    assert np.array_equal(np.sign(s[keep]), np.sign(truth[keep]))


# --- garments --------------------------------------------------------------------------------
def test_the_panels_sew_into_closed_garments_of_the_stated_size(surface):
    """Welded seams leave only the openings: a tee has its hem, neck and two sleeve ends, a
    vest its hem, neck and two armholes, pants a waist and two cuffs, a skirt a waist and a
    hem; every edge belongs to one or two triangles. The skirt is cut in gores: its waist has
    fewer columns than its hem, its edges are within the spacings the sewing evens them to
    (Fit.shortest, Fit.split), and no triangle of it crosses another (the exact test: cut
    with its hem's columns up to the waist, the swing's cut crossed itself in 1,619 pairs on
    this body, 563 on the child's). (The tee's
    shoulder tips and the pants' cuffs still cross in a few pairs at some spacings; the
    layers' untangling undoes them in the dressing.) The tee's chest grows by 2 pi times the
    ease (a ring ``ease`` farther out all round) within 15% of that growth (the ring is the
    convex hull of the body's section, which the ease rounds); the pants reach the ankle."""
    fit = G.Fit(spacing=0.02)
    cases = {"tee": (G.tee, 4), "vest": (G.vest, 4), "pants": (G.sweatpants, 3),
             "skirt": (G.skirt, 2)}
    made = {}
    for name, (make, openings) in cases.items():
        g = make(surface, fit)
        e, counts, _ = edges(g.triangles)
        assert counts.max() <= 2, name
        assert len(G.boundary_loops(g.triangles)) == openings, name
        made[name] = g
    sk = G.skirt(surface, G.Fit(spacing=0.02, length=0.6, ease=0.05))  # the swing's cut
    assert len(AABBTree(sk.vertices, sk.triangles).intersections()) == 0
    assert sk.sizes["waist_columns"] < sk.sizes["columns"]
    e, _, _ = edges(sk.triangles)
    length = np.linalg.norm(np.diff(sk.vertices[e], axis=1)[:, 0], axis=1)
    # the evening's bounds, less a hair: the push out of the body after it moves a few points
    assert fit.shortest * fit.spacing * 0.95 < length.min()
    assert length.max() < fit.split * fit.spacing * 1.05
    loose = G.tee(surface, G.Fit(spacing=0.02, ease=0.03)).sizes["chest_girth"]
    chest = made["tee"].sizes["chest_girth"]
    growth = 2 * np.pi * (0.03 - fit.ease)
    assert abs(loose - chest - growth) < 0.15 * growth
    P = {s.name: k for k, s in enumerate(surface.plan)}
    ankle = surface.pos0[P["l_foot"], 2]
    pants = made["pants"]
    low = pants.vertices[pants.groups["cuff_l"], 2].mean()
    assert abs(low - (ankle + 0.035)) < 0.02
    # the mass is the cut area at the fabric's areal density
    net = G.network(pants)
    assert net.m.sum() == pytest.approx(pants.area * G.FABRICS["fleece"].density, rel=1e-9)


def test_the_stretch_certificate_counts_the_overstretched_share(surface):
    """The pants dilated about their centre by 1 + e strain every structural spring by e
    exactly (l = (1 + e) |x_i - x_j| against rest lengths cut at the same points, the
    bands' shorter ones apart): at e = 3% the largest strain is 3% and no spring is past
    OVERSTRETCH (5%), though the bands, cut short to grip, are; at e = 8% all are. The share
    survives a checkpoint's capture and restore."""
    from interplay.systems.garments import OVERSTRETCH
    net = G.network(G.sweatpants(surface, G.Fit(spacing=0.03)))
    x0 = net.x.copy()
    c = x0.mean(axis=0)
    for e, share in ((0.03, 0.0), (0.08, 1.0)):
        net.x[:] = c + (1.0 + e) * (x0 - c)
        largest, over = net.stretch()
        assert largest["pants"] == pytest.approx(e, rel=1e-9)  # round-off of a length
        assert largest["pants bands"] > OVERSTRETCH  # the bands are not in the share
        assert over == {"pants": share}
    net.certificates = [{"t": 0.0, "cloth_body_intersections": 0, "penetration_m": 0.0,
                         "self_intersections": 0, "stretch": largest, "overstretched": over}]
    snap = net.capture()
    net.certificates = []
    net.restore(snap)
    assert net.certificates[0]["overstretched"] == {"pants": 1.0}
    assert net.certificates[0]["stretch"] == largest


def strip_network(rows, cols=11, spacing=0.01, limit=0.05, pinned=None):
    """A cotton jersey strip (cols x rows points, ``spacing`` m apart, in the x-z plane, top
    row at z = 0) as a Garments network at 1/240 s, stretch limit ``limit``; pinned: the
    points that ride (default the top row)."""
    import dataclasses
    X, Z = np.meshgrid(np.arange(cols) * spacing, -np.arange(rows) * spacing)
    x = np.stack([X.ravel(), np.zeros(X.size), Z.ravel()], 1)
    a = (np.arange(rows - 1)[:, None] * cols + np.arange(cols - 1)).ravel()
    t = np.concatenate([np.stack([a, a + 1, a + cols], 1),
                        np.stack([a + 1, a + cols + 1, a + cols], 1)])
    fabric = dataclasses.replace(G.FABRICS["cotton_jersey"], stretch_limit=limit)
    groups = {} if pinned is False else {
        "pinned": np.arange(cols) if pinned is None else np.asarray(pinned)}
    return G.network(G.Garment("strip", x, t, fabric, groups), dt=1.0 / 240.0)


def structural_strain(net):
    """The largest strain (l / l0 - 1) of the network's structural springs, bands (those
    between two pinned points) apart."""
    d = np.linalg.norm(net.x[net.si] - net.x[net.sj], axis=1) / net.l0 - 1.0
    return float(d[(net.spring_kind == 0) & ~net.band].max())


def test_a_loaded_strip_stretches_no_more_than_its_limit():
    """A cotton jersey strip 0.1 m wide and 0.2 m long, pinned along its top, pulled down by
    5 N on its bottom row (a 0.5 kg weight's pull) for 2 s. Its tension, 5 N / 0.1 m =
    50 N/m, against the jersey's 400 N/m would strain it 12.5% at rest: without a limit the
    strain passes 10%. With the 5% limit it never passes 5%: the passes end only when no
    structural spring is over its cap (l0 x 1.05), so the bound is exact up to the
    round-off of a length (1e-12), as long as no step ran out of passes (checked). The
    weight's pull is a force on light points, not the weight's own mass: 1,000 times a
    cloth point's mass at the corner makes the passes converge slowly (docs/clothing.md)."""
    for limit in (np.inf, 0.05):
        net = strip_network(21, limit=limit)
        bottom = np.arange(len(net.x) - 11, len(net.x))
        worst = 0.0
        for _ in range(480):
            net.clear_forces()
            net.add_point_forces(bottom, np.tile([0.0, 0.0, -5.0 / 11], (11, 1)))
            net.advance(1.0 / 240.0)
            worst = max(worst, structural_strain(net))
        if limit == np.inf:
            assert worst > 0.10
        else:
            assert worst <= 0.05 + 1e-12
            assert net.limit_stats[1] == 0  # no step left springs over their caps


def test_the_strain_limit_keeps_momentum_and_pinned_points():
    """A cotton strip stretched 20% with random jitter and random velocities: the limit
    brings every structural spring to its cap or under, and each correction moves a
    spring's two ends by opposite impulses (shares of 1/m), so the strip's linear momentum
    is unchanged to round-off (1e-12 of sum m |v|) when no point is pinned. Pinned points
    (the top row) do not move at all, and their velocities are not touched."""
    rng = np.random.default_rng(3)
    for pinned in (False, None):
        net = strip_network(8, limit=0.05, pinned=pinned)
        # stretched down from the top row (which stays where it is cut, so the pins leave
        # room for the limit), with jitter on the free points
        net.x[:, 2] *= 1.2
        net.x[~net.fixed] += rng.normal(0.0, 0.001, (int((~net.fixed).sum()), 3))
        net.v[:] = rng.normal(0.0, 0.5, net.v.shape)
        p0, x0, v0 = net.momentum(), net.x.copy(), net.v.copy()
        net.limit_strain(1.0 / 240.0)
        assert structural_strain(net) <= 0.05 + 1e-12
        pins = net.fixed
        if pinned is False:
            scale = float(np.sum(net.m[:, None] * np.abs(v0)))
            assert np.abs(net.momentum() - p0).max() <= 1e-12 * scale
        else:
            assert pins.sum() == 11
            assert np.array_equal(net.x[pins], x0[pins])
            assert np.array_equal(net.v[pins], v0[pins])
        moved = ~pins
        # the velocity changes by the move over the step: x - x_n = h v still holds
        assert np.allclose((net.v - v0)[moved] / 240.0, (net.x - x0)[moved], atol=1e-15)


def test_garments_worn_together_are_limited_each_on_its_own():
    """Two strips joined into one network (as the runner's tee and pants), stretched with
    jitter: the limit runs each garment's passes on its own, the two in parallel
    (kernels/strain_limit.limit_strain). They share no point, so each must end bit for bit
    where it ends limited alone, both within their caps (the one stretched 20% is done in
    about half the passes of the one stretched 60%: a garment that stops early must not
    change the other's passes)."""
    from interplay.geometry.garment import join
    rng = np.random.default_rng(5)
    a, b = strip_network(8, limit=0.05), strip_network(12, limit=0.03)
    a.x[:, 2] *= 1.2
    b.x[:, 2] *= 1.6
    for net in (a, b):
        net.x[~net.fixed] += rng.normal(0.0, 0.001, (int((~net.fixed).sum()), 3))
        net.v[:] = rng.normal(0.0, 0.5, net.v.shape)
    gb = b.garment  # renamed: the joined garment's groups are named after its garments
    gb = G.Garment("other", gb.vertices, gb.triangles, gb.fabric, gb.groups)
    both = G.network(join("both", a.garment, gb), dt=1.0 / 240.0)
    both.x[:] = np.r_[a.x, b.x]  # on each other: the limit looks only along springs
    both.v[:] = np.r_[a.v, b.v]
    assert len(both.parts) == 2
    for net in (a, b, both):
        net.limit_strain(1.0 / 240.0)
    n = len(a.x)
    assert np.array_equal(both.x[:n], a.x) and np.array_equal(both.v[:n], a.v)
    assert np.array_equal(both.x[n:], b.x) and np.array_equal(both.v[n:], b.v)
    assert structural_strain(a) <= 0.05 + 1e-12
    assert structural_strain(b) <= 0.03 + 1e-12
    # a is done in fewer passes than b: its passes stop while b's go on
    assert a.limit_stats[0] < b.limit_stats[0] == both.limit_stats[0]


def test_the_strain_limit_moves_no_held_point_and_shortens_from_the_other_end():
    """A strip stretched 20% with its bottom row held (as a last limit holds the points
    sent back where they crossed): the held points stay exactly where they are, and every
    structural spring still comes within its cap, its free end doing all the moving. Pinned
    along the top, a held point beyond its long range attachment's reach is not pulled in
    by it either."""
    for pinned, limited in ((False, True), (None, False)):
        net = strip_network(8, limit=0.05, pinned=pinned)
        net.x[:, 2] *= 1.2
        held = np.zeros(len(net.x), bool)
        held[-11:] = limited
        held[-6] = True
        x0 = net.x.copy()
        net.limit_strain(1.0 / 240.0, None, held)
        assert np.array_equal(net.x[held], x0[held])
        if limited:
            assert structural_strain(net) <= 0.05 + 1e-12
            assert net.limit_stats[1] == 0


def test_the_final_limits_may_bring_cloth_to_the_final_gap_and_no_nearer():
    """The skin contact's half-spaces for a limit after its projection (skin_contact.kept_off):
    a strip pinned along both side edges, stretched 20%, its middle column 8 mm off a skin at
    y = 0.012 m (outward +y), one point of it 0.5 mm off. Pulled towards the pins' plane the
    column comes to rest exactly at the gap (5 mm, the contact's thickness; 2 mm, a final
    gap), less stretched the nearer it may come; the point already within the gap comes no
    nearer."""
    from interplay.interactions.skin_contact import kept_off
    strain = {}
    for gap in (0.005, 0.002):
        net = strip_network(11, cols=11, limit=0.05, pinned=np.r_[0:121:11, 10:121:11])
        net.x[:, 0] *= 1.2
        mid = np.flatnonzero(np.isclose(net.x[:, 0], 0.06))
        net.x[mid, 1] = 0.02
        net.x[mid[0], 1] = 0.0125
        s = net.x[mid, 1] - 0.012
        net.limit_strain(1.0 / 240.0, kept_off(mid, np.tile([0.0, 1.0, 0.0], (len(mid), 1)),
                                               net.x[mid], s, gap))
        y = net.x[mid, 1]
        np.testing.assert_allclose(y[1:], 0.012 + gap, atol=1e-12)  # round-off of a plane
        assert y[0] >= 0.0125 - 1e-12
        strain[gap] = structural_strain(net)
    assert strain[0.002] < strain[0.005]


def test_cloth_the_projection_moved_out_may_come_to_the_final_gap(surface):
    """The final limits start from where the skin's projection left each point: a jersey
    strip 10 x 4 cm on the chest, pinned 3 mm off the skin along its side edges and cut 1/1.2
    of that size (more stretch than the limit can take back: it pulls the middle towards the
    pins as far as the skin lets it), its middle column found 1 mm inside the skin. The
    projection moves that column out to the thickness (5 mm) and the first limit holds it
    there; the final limit brings it to the final gap (2 mm). Taking the distance found
    before the projection, it stayed at 5 mm: the final gap never reached cloth lying on the
    skin (the runner's tee pleats)."""
    from interplay.systems.garment_layers import Layers
    X = surface.vertices0
    trunk = np.flatnonzero(surface.vertex_limbs() == list(LIMBS).index("trunk"))
    chest = trunk[np.abs(X[trunk, 2] - 1.3) < 0.03]
    p = X[chest[np.argmax(X[chest, 0])]]  # the chest's front (+x) at 1.3 m
    n = surface.mesh_distance(p[None])[1][0]
    across = np.cross(n, [0.0, 0.0, 1.0])
    across /= np.linalg.norm(across)
    a, b = np.meshgrid((np.arange(11) - 5) * 0.01, (np.arange(5) - 2) * 0.01)
    a, b = a.ravel(), b.ravel()
    x = p + a[:, None] * across + b[:, None] * np.cross(n, across)
    for _ in range(5):  # draped 3 mm off the skin
        s, nrm = surface.mesh_distance(x)
        x += (0.003 - s)[:, None] * nrm
    mid = np.flatnonzero(a == 0.0)
    x[mid] -= 0.004 * nrm[mid]
    q = (np.arange(4)[:, None] * 11 + np.arange(10)).ravel()
    tris = np.concatenate([np.stack([q, q + 1, q + 11], 1), np.stack([q + 1, q + 12, q + 11], 1)])
    rest = x.mean(0) + (x - x.mean(0)) / 1.2
    pins = np.flatnonzero(np.abs(a) > 0.045)
    for gap in (0.005, 0.002):
        net = G.network(G.Garment("strip", rest, tris, G.FABRICS["cotton_jersey"],
                                  {"pinned": pins}), dt=1.0 / 240.0)
        net.x[:], net.v[:] = x, 0.0
        assert surface.mesh_distance(net.x[mid])[0].max() < -0.0009
        net.layers = Layers(net, surface)
        law = SkinContactParams(final_limits=1, final_gap=gap)
        proj = _Projector(net, surface.triangles, law, X, surface.vertex_limbs())
        proj.start()
        proj.resolve(X, np.zeros_like(X), 1.0 / 240.0)
        # to round-off of the tangent planes over the skin's facets (0.01 mm)
        assert surface.mesh_distance(net.x[mid])[0] == pytest.approx(gap, abs=1e-5)


def test_the_strain_limit_leaves_a_contact_plane_on_its_outer_side():
    """A strip (in the x-z plane) pinned along both side edges, stretched 20% between them,
    its middle column pushed 2 cm out of the plane by a post: the half-space y >= 0.02 m.
    Shortening its springs pulls the middle back towards the pins' plane (y = 0: without
    the post it ends below 0.02 m); the post's projection follows every pass, so the middle
    stays on it (to round-off)."""
    from interplay.kernels.strain_limit import Planes
    for post in (False, True):
        net = strip_network(11, cols=11, limit=0.05, pinned=np.r_[0:121:11, 10:121:11])
        net.x[:, 0] *= 1.2
        mid = np.flatnonzero(np.isclose(net.x[:, 0], 0.06))
        net.x[mid, 1] = 0.02
        planes = Planes(mid, np.tile([0.0, 1.0, 0.0], (len(mid), 1)), np.full(len(mid), 0.02))
        before = structural_strain(net)
        net.limit_strain(1.0 / 240.0, planes if post else None)
        assert structural_strain(net) < before
        if post:
            assert net.x[mid, 1].min() >= 0.02 - 1e-12
        else:
            assert net.x[mid, 1].min() < 0.02 - 1e-3


def test_bad_garment_meshes_are_refused_naming_the_element(surface, tmp_path):
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, -1, 0]], float) * 0.01
    t = np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]])
    with pytest.raises(ParameterError, match=r"edge \(0, 1\) is shared by 3 triangles"):
        G.check_garment(G.Garment("bad", x, t, G.FABRICS["cotton_jersey"]))
    big = x * 20.0
    with pytest.raises(ParameterError, match=r"edge \(\d+, \d+\) is .* too coarse"):
        G.check_garment(G.Garment("coarse", big, t[:2], G.FABRICS["cotton_jersey"]),
                        max_edge=0.05)
    # a patch through the torso: deeper inside than dressing can fix
    import trimesh
    P = {s.name: k for k, s in enumerate(surface.plan)}
    c = surface.pos0[P["torso"]] + [0.0, 0.0, 0.15]
    sq = np.array([[-0.01, -0.01, 0], [0.01, -0.01, 0], [0.01, 0.01, 0], [-0.01, 0.01, 0]]) + c
    path = tmp_path / "through.obj"
    trimesh.Trimesh(sq, [[0, 1, 2], [0, 2, 3]], process=False).export(path)
    with pytest.raises(ParameterError, match=r"vertex \d starts .* cm inside the body"):
        G.load_garment(path, surface=surface)


# --- the skin contact --------------------------------------------------------------------------
def _square(centre, size, n, normal_axis=2):
    from interplay.geometry.shapes import grid
    x, t = grid(size, size, n, n)
    x = x - x.mean(axis=0) + centre
    return x, t


def test_a_cloth_square_at_5_m_per_s_onto_the_thigh_does_not_tunnel(surface):
    """A 20 cm cotton square falls at 5 m/s onto the front of the A-pose thigh at the runner's
    step (1/240 s: 2.1 cm a step, less than the reach and the thigh's radius): after 0.1 s no
    point is inside the skin and no cloth triangle crosses a skin triangle."""
    P = {s.name: k for k, s in enumerate(surface.plan)}
    hip = surface.pos0[P["l_thigh"]]
    top = surface.mesh_distance(hip[None] + [0.3, 0.0, -0.12], reach=1.0)[0][0]
    # start 5 cm in front of the thigh's front surface, moving back onto it
    x, t = _square(hip + [0.3 - top + 0.05, 0.0, -0.12], 0.2, 12)
    x = x[:, [2, 1, 0]] - x[:, [2, 1, 0]].mean(axis=0) + (hip + [0.3 - top + 0.05, 0, -0.12])
    net = SpringNetwork.from_mesh("square", x, t, 0.2 * 0.2 * 0.16, 300.0, dt=1 / 240,
                                  integrator="localglobal", mass_damping=0.1)
    net.v[:] = [-5.0, 0.0, 0.0]
    h = 1 / 240
    X, V = surface.vertices0, np.zeros_like(surface.vertices0)
    proj = _Projector(net, surface.triangles, SkinContactParams(), X)
    touched = 0
    for _ in range(24):
        net.clear_forces()
        proj.start()
        net.advance(h)
        proj.resolve(X, V, h)
        touched = max(touched, proj.count)
    s, _ = surface.mesh_distance(net.x)
    assert s.min() > 0.0
    assert len(AABBTree(X, surface.triangles).intersections(AABBTree(net.x, net.triangles))) == 0
    assert touched > 20  # it did land


def _slope_skin(theta):
    """A closed box 1 x 1 x 0.2 m whose top face is tilted by theta about y."""
    import trimesh
    box = trimesh.creation.box((1.0, 1.0, 0.2))
    c, s = np.cos(theta), np.sin(theta)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.asarray(box.vertices) @ R.T, np.asarray(box.faces, np.int64), R


def test_a_point_riding_the_skin_is_kept_just_outside_it():
    """Points that ride the skin (a pinned waistband) are placed by its weights, which where
    the skin folds carry a few just inside it: the contact moves those out to RIDE_OFF along
    the normal and leaves the others, pinned or free, where their own rules put them."""
    from interplay.interactions import skin_contact as SCm
    from interplay.systems.springmass import Springs
    X, T, R = _slope_skin(0.0)  # the top face at z = 0.1
    x = np.array([[0.0, 0.0, 0.0995], [0.1, 0.0, 0.103], [0.2, 0.0, 0.0995]])
    net = SpringNetwork("band", x.copy(), [1e-3] * 3,
                        Springs(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0),
                                np.zeros(0), np.zeros(0, bool)), dt=1e-3, integrator="explicit")
    net.fixed[:2] = True  # 0: pinned, 0.5 mm inside; 1: pinned, 3 mm out; 2: free, inside
    proj = _Projector(net, T, SkinContactParams(thickness=0.004, friction=0.0), X)
    proj.start()
    proj.resolve(X, np.zeros_like(X), 1e-3)
    assert net.x[0] == pytest.approx([0.0, 0.0, 0.1 + SCm.RIDE_OFF], abs=1e-12)
    assert net.x[1] == pytest.approx(x[1], abs=1e-15)  # outside: its place is the skin's
    assert net.x[2, 2] == pytest.approx(0.104, abs=1e-12)  # free: out to the thickness


def test_a_skin_ridge_between_two_cloth_points_is_held_off_by_the_edge_contact():
    """A tent of skin (a ridge along y at z = 0, its faces sloping at 45 deg) under one cloth
    square 2 cm across, its points 4 mm below the ridge's height on either side: each point
    is 4.2 mm off its face (outside the 4 mm thickness: no point contact), yet the ridge
    passes through both triangles. The point contact alone leaves them crossed; the
    edge-edge contact moves each edge over the ridge out along the ridge's pseudonormal (up)
    to the thickness, and no triangle crosses the skin (the certificate's exact test)."""
    import trimesh

    from interplay.kernels.trimesh_contact import closest_segments
    ridge = [[0.0, y, 0.0] for y in (-0.05, 0.05)]
    feet = [[sx * 0.05, y, -0.05] for sx in (-1, 1) for y in (-0.05, 0.05)]
    tent = trimesh.convex.convex_hull(np.array(ridge + feet))
    X, T = np.asarray(tent.vertices), np.asarray(tent.faces, np.int64)
    x = np.array([[-0.01, -0.01, -0.004], [0.01, -0.01, -0.004], [-0.01, 0.01, -0.004],
                  [0.01, 0.01, -0.004]])

    def crossings(edges: bool) -> tuple[int, np.ndarray]:
        net = strip_network(2, cols=2, spacing=0.02, pinned=False)
        net.x[:], net.v[:] = x, 0.0
        law = SkinContactParams(thickness=0.004, friction=0.5, edges=edges)
        proj = _Projector(net, T, law, X)
        proj.start()
        proj.resolve(X, np.zeros_like(X), 1.0 / 240.0)
        return len(AABBTree(net.x, net.triangles).intersections(AABBTree(X, T))), net.x

    crossed, after = crossings(False)
    assert crossed > 0 and np.array_equal(after, x)
    crossed, after = crossings(True)
    assert crossed == 0
    assert after[:, :2] == pytest.approx(x[:, :2], abs=1e-12)  # moved along the ridge's normal
    assert np.all(after[:, 2] > x[:, 2])
    # each edge over the ridge keeps most of the thickness off it: one pass, and an edge that
    # its own push turns ends a little nearer than that (3.8 mm of 4)
    ends = np.array([[0.0, -0.05, 0.0], [0.0, 0.05, 0.0]])
    for a, b in ((0, 1), (1, 2), (2, 3)):
        gap = np.sqrt(closest_segments(after[a], after[b], ends[0], ends[1])[2])
        assert 0.9 * 0.004 < gap < 2.5 * 0.004


@pytest.mark.parametrize("theta_deg,mu,sticks", [(20.0, 0.5, True), (35.0, 0.5, False)])
def test_friction_holds_below_the_cone_and_slides_by_coulomb_above(theta_deg, mu, sticks):
    """A point resting on a slope of the skin under gravity (symplectic Euler steps of 1 ms,
    projected after each): at tan(theta) = 0.36 < mu = 0.5 it stays (moves < 0.1 mm in
    0.5 s); at tan(theta) = 0.70 it slides with g (sin - mu cos) within 3% (the sliding
    friction uses the normal correction of each step, g cos h)."""
    theta = np.radians(theta_deg)
    X, T, R = _slope_skin(theta)
    top = R @ np.array([0.0, 0.0, 0.1])
    n = R @ np.array([0.0, 0.0, 1.0])
    net = SpringNetwork("pt", (top + 0.004 * n)[None], [1e-3],
                        __import__("interplay.systems.springmass",
                                   fromlist=["Springs"]).Springs(
                            np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0),
                            np.zeros(0), np.zeros(0, bool)), dt=1e-3, integrator="explicit")
    proj = _Projector(net, T, SkinContactParams(thickness=0.004, friction=mu), X)
    h, steps = 1e-3, 500
    x_start = net.x[0].copy()
    for _ in range(steps):
        net.clear_forces()
        proj.start()
        net.advance(h)
        proj.resolve(X, np.zeros_like(X), h)
    moved = np.linalg.norm(net.x[0] - x_start)
    if sticks:
        assert moved < 1e-4
    else:
        g = 9.81
        want = 0.5 * g * (np.sin(theta) - mu * np.cos(theta)) * (steps * h) ** 2
        assert moved == pytest.approx(want, rel=0.03)


def test_the_keyframed_run_is_a_clip_the_figure_plays(tmp_path):
    """Without motion capture the runner plays a keyframed run: a BVH the reader and the
    retargeting take (metres from centimetres), moving forward at its speed (3.2 m/s within
    5%: the root's forward channel is speed x t) with its feet near the ground."""
    from interplay.scenes.runner import keyframed_run
    path = tmp_path / "run.bvh"
    keyframed_run(path, duration=1.0)
    fig = MocapFigure("runner", path, units="cm", skip_tpose=False, ground=0.0)
    fig.set_time(0.0)
    x0 = fig.segment_positions()[0].copy()
    fig.set_time(0.9)
    moved = np.linalg.norm(fig.segment_positions()[0][:2] - x0[:2])
    assert moved == pytest.approx(3.2 * 0.9, rel=0.05)
    assert 0.7 < fig.body.height < 2.5


@pytest.mark.slow
def test_the_runners_garments_never_cross_or_enter_the_body():
    """The issue's per-frame certificates on the default runner (43 frames of the CMU jog):
    no cloth triangle crosses a skin triangle or another cloth triangle (the exact
    triangle-triangle test) and no cloth point is more than 2 mm inside the skin, in any
    frame. Zero crossings needs the arms'
    room for the hem (scenes/runner.ARM_ROOM: with 2 cm the hands crossed the tee's hem in 7
    frames)."""
    if not clip_path("cmu_02_03_run.bvh").exists():
        pytest.skip("no motion-capture data (../shared/data)")
    from interplay.scenes import runner as RN
    res = RN.build().simulate()
    frames = res.diagnostics["clothes"]["certificates"]["per_frame"]
    assert len(frames) == 43
    crossing = [f["cloth_body_intersections"] for f in frames]
    assert max(crossing) == 0, crossing
    assert max(f["penetration_m"] for f in frames) <= 0.002
    # nor any garment triangle another (the layers' untangling and guard)
    selfx = [f["self_intersections"] for f in frames]
    assert max(selfx) == 0, selfx
    # the guard's zones stretch their rims; the later guards' are rigid, and the two final
    # limits are undone only where they cross and may bring the cloth to 2 mm off the skin:
    # the tee within its 5% in every frame (at most 4.99999%; 8.7% with one relimit and one
    # final limit held at the thickness, 5.1% in one frame with one relimit, 31% when the
    # second guard's zones were carried by the skin). No tolerance: the limit leaves every
    # spring at its cap or under (it shortens one over it to 0.1% under)
    tee = [f["stretch"]["tee"] for f in frames]
    assert max(tee) <= 0.05, max(tee)


def _layered(surface, layers: bool, seconds: float = 0.25):
    """Sweat pants and a tee cut on the A-pose body with no regard for each other (the tee
    not cut ``over`` the pants: its hem crosses the pants' seat), joined into one network
    (pants first, the tee over them), run for ``seconds`` on the still body with the skin
    contact and, if ``layers``, the layers held apart; returns (tee-pants crossing pairs at
    the start, at the end, the deepest point inside the skin (m), the largest tee strain)."""
    from interplay.scenes import runner as RN
    from interplay.systems.garment_layers import Layers
    pants = G.sweatpants(surface, G.Fit(spacing=0.03, ease=0.025, shortest=0.3))
    shirt = G.tee(surface, G.Fit(spacing=0.03, ease=0.02))
    net = G.network(G.join("clothes", pants, shirt), dt=1 / 240)
    if layers:
        net.layers = Layers(net, surface, covers=RN.COVERS)
    tee = np.zeros(len(net.x), bool)
    tee[net.parts["tee"]] = True

    def between():
        p = AABBTree(net.x, net.triangles).intersections()
        return int(np.sum(tee[net.triangles[p[:, 0], 0]] != tee[net.triangles[p[:, 1], 0]]))

    X, V = surface.vertices0, np.zeros_like(surface.vertices0)
    proj = _Projector(net, surface.triangles, SkinContactParams(), X, surface.vertex_limbs())
    start = between()
    h = 1 / 240
    for _ in range(int(round(seconds / h))):
        net.clear_forces()
        proj.start()
        net.advance(h)
        proj.resolve(X, V, h)
    s, _ = surface.mesh_distance(net.x)
    d = np.linalg.norm(net.x[net.si] - net.x[net.sj], axis=1) / net.l0 - 1.0
    on = tee[net.si] & (net.spring_kind == 0)
    return start, between(), float(max(0.0, -s.min())), float(d[on].max())


def test_a_tee_worn_over_pants_is_moved_out_of_them_and_stays_out(surface):
    """Layers (systems/garment_layers.py): a tee and pants cut at the runner's eases (2 and
    2.5 cm), the tee not cut over the pants, cross where its hem meets the pants' seat (263
    triangle pairs). Worn as layers, pants first, after 0.25 s (60 steps of 1/240 s) on the
    still body no tee triangle crosses a pants triangle, no point is more than 2 mm inside
    the skin and the tee's springs are within 20% (nothing torn to get it out). Without the
    layers the crossings stay (336: the control, so the test can fail)."""
    start, end, depth, strain = _layered(surface, True)
    assert start > 50
    assert end == 0
    assert depth <= 0.002
    assert strain < 0.2
    assert _layered(surface, False)[1] > 0.5 * start
