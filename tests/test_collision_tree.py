"""AABBTree against brute force: overlaps, nearest triangles, refit bounds, transformed boxes, and
triangle-triangle intersection against an exact rational reference."""
from fractions import Fraction

import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry.aabb_tree import AABBTree
from interplay.kernels.sorting import stable_argsort
from interplay.kernels.trimesh_contact import closest_on_triangle, triangles_intersect


def random_soup(rng, m, spread=1.0, size=0.1, sliver=False):
    """m independent triangles; sliver=True makes near-degenerate, near-parallel ones."""
    c = rng.uniform(-spread, spread, (m, 1, 3))
    t = c + rng.normal(0.0, size, (m, 3, 3))
    if sliver:
        # third vertex almost on the first edge, and all triangles almost in the plane z = 0
        t[:, 2] = t[:, 0] + 0.5 * (t[:, 1] - t[:, 0]) + rng.normal(0, 1e-7, (m, 3))
        t[:, :, 2] = rng.normal(0, 1e-6, (m, 3))
    return t.reshape(-1, 3), np.arange(3 * m).reshape(m, 3)


def boxes_overlap(x, ta, tb):
    lo_a, hi_a = x[ta].min(axis=1), x[ta].max(axis=1)
    lo_b, hi_b = x[tb].min(axis=1), x[tb].max(axis=1)
    return np.all((lo_a[:, None] <= hi_b[None]) & (lo_b[None] <= hi_a[:, None]), axis=2)


@pytest.mark.parametrize("sliver", [False, True])
def test_overlap_pairs_equal_brute_force(sliver):
    rng = np.random.default_rng(1 if sliver else 0)
    xa, ta = random_soup(rng, 400, sliver=sliver)
    xb, tb = random_soup(rng, 300, sliver=sliver)
    a, b = AABBTree(xa, ta), AABBTree(xb, tb)
    got = {tuple(p) for p in a.overlapping(b)}
    brute = np.argwhere(boxes_overlap(np.vstack([xa, xb]), ta, tb + len(xa)))
    assert got == {tuple(p) for p in brute}
    assert len(got) > 100  # the case is not vacuous


def test_self_overlap_each_pair_once():
    rng = np.random.default_rng(2)
    x, t = random_soup(rng, 500)
    pairs = AABBTree(x, t).overlapping()
    got = {tuple(sorted(p)) for p in pairs}
    assert len(got) == len(pairs)
    ov = boxes_overlap(x, t, t)
    brute = {(i, j) for i, j in np.argwhere(ov) if i < j}
    assert got == brute


def brute_nearest(p, x, t, radius):
    best, bt = radius * radius, -1
    for e in range(len(t)):
        d2 = closest_on_triangle(p, x[t[e, 0]], x[t[e, 1]], x[t[e, 2]])[3]
        if d2 <= best:
            best, bt = d2, e
    return bt, np.sqrt(best)


@pytest.mark.parametrize("sliver", [False, True])
def test_nearest_triangle_equals_brute_force(sliver):
    rng = np.random.default_rng(3 if sliver else 4)
    x, t = random_soup(rng, 300, sliver=sliver)
    pts = rng.uniform(-1.1, 1.1, (1500, 3))
    tri, d, bary = AABBTree(x, t).nearest(pts, 0.15)
    for i in range(len(pts)):
        bt, bd = brute_nearest(pts[i], x, t, 0.15)
        assert (tri[i] >= 0) == (bt >= 0)
        if bt >= 0:
            # ties between triangles at the same distance may pick either: compare distances
            assert d[i] == pytest.approx(bd, abs=1e-12)
            q = bary[i] @ x[t[tri[i]]]
            assert np.linalg.norm(pts[i] - q) == pytest.approx(bd, abs=1e-12)
    assert (tri >= 0).sum() > 200


@pytest.mark.parametrize("m", [500, 3000])  # below and above PARALLEL_LEAVES (2048)
def test_refit_bounds_contain_deformed_triangles(m):
    rng = np.random.default_rng(5)
    x, t = random_soup(rng, m)
    tree = AABBTree(x, t, pad=0.01)
    for _ in range(20):
        x0 = x + rng.normal(0, 0.2, x.shape)
        x1 = x0 + rng.normal(0, 0.05, x.shape)
        tree.refit(x0, x1)
        leaf = tree.prim >= 0
        for xx in (x0, x1):
            pts = xx[t[tree.prim[leaf]]]  # (leaves, 3, 3)
            assert np.all(pts >= tree.lo[leaf][:, None] + 0.01 - 1e-12)
            assert np.all(pts <= tree.hi[leaf][:, None] - 0.01 + 1e-12)
        inner = np.flatnonzero(~leaf)
        for c in (tree.left[inner], tree.right[inner]):
            assert np.all(tree.lo[inner] <= tree.lo[c]) and np.all(tree.hi[inner] >= tree.hi[c])


def test_transformed_boxes_contain_moved_rigid_mesh():
    from interplay.geometry.sphere import icosphere
    rng = np.random.default_rng(6)
    v, t = icosphere(2)
    tree = AABBTree(v * 0.3, t)
    for _ in range(20):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        w, a, b, c = q
        R = np.array([[1 - 2 * (b * b + c * c), 2 * (a * b - w * c), 2 * (a * c + w * b)],
                      [2 * (a * b + w * c), 1 - 2 * (a * a + c * c), 2 * (b * c - w * a)],
                      [2 * (a * c - w * b), 2 * (b * c + w * a), 1 - 2 * (a * a + b * b)]])
        tr = rng.normal(size=3)
        tree.transform(R, tr)
        leaf = tree.prim >= 0
        pts = tree.x[t[tree.prim[leaf]]]
        assert np.allclose(tree.x, (v * 0.3) @ R.T + tr)
        assert np.all(pts >= tree.lo[leaf][:, None] - 1e-12)
        assert np.all(pts <= tree.hi[leaf][:, None] + 1e-12)


def exact_intersect(A, B):
    """Slow exact reference: rational arithmetic; an edge of one triangle crossing the plane of
    the other at a point inside it (barycentric coordinates all >= 0)."""
    A = [[Fraction(float(c)) for c in p] for p in A]
    B = [[Fraction(float(c)) for c in p] for p in B]

    def sub(p, q):
        return [p[i] - q[i] for i in range(3)]

    def dot(p, q):
        return sum(p[i] * q[i] for i in range(3))

    def cross(p, q):
        return [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]

    def edge_hits(p, q, T):
        n = cross(sub(T[1], T[0]), sub(T[2], T[0]))
        dp, dq = dot(n, sub(p, T[0])), dot(n, sub(q, T[0]))
        if dp == dq:
            return False  # parallel to the plane (coplanar pairs are not reported)
        s = dp / (dp - dq)
        if not 0 <= s <= 1:
            return False
        x = [p[i] + s * (q[i] - p[i]) for i in range(3)]
        nn = dot(n, n)
        # barycentric coordinates by signed sub-areas
        for i in range(3):
            a, b = T[(i + 1) % 3], T[(i + 2) % 3]
            if dot(cross(sub(b, a), sub(x, a)), n) / nn < 0:
                return False
        return True

    return any(edge_hits(P[i], P[(i + 1) % 3], Q) for P, Q in ((A, B), (B, A)) for i in range(3))


def test_triangle_intersection_matches_exact_reference():
    rng = np.random.default_rng(7)
    agree = hits = 0
    for k in range(3000):
        A = rng.normal(size=(3, 3))
        B = rng.normal(size=(3, 3)) * (0.05 if k % 3 == 0 else 1.0) + (k % 5) * 0.3
        got = triangles_intersect(A[0], A[1], A[2], B[0], B[1], B[2])
        ref = exact_intersect(A, B)
        agree += got == ref
        hits += ref
    assert agree == 3000
    assert 200 < hits < 2800


def test_mesh_intersections_found_by_tree():
    from interplay.geometry.sphere import icosphere
    v, t = icosphere(2)
    a = AABBTree(v * 0.1, t)
    b = AABBTree(v * 0.1 + [0.15, 0, 0], t)
    c = AABBTree(v * 0.1 + [0.25, 0, 0], t)
    assert len(a.intersections(b)) > 0
    assert len(a.intersections(c)) == 0
    assert len(a.intersections()) == 0  # a closed sphere never crosses itself


def test_bad_meshes_are_refused_with_the_fix():
    with pytest.raises(ParameterError, match=r"cloth: a collision mesh needs at least one"):
        AABBTree(np.zeros((3, 3)), np.zeros((0, 3), np.int64), owner="cloth")
    x = np.eye(3)
    x[1, 2] = np.nan
    with pytest.raises(ParameterError, match=r"cloth: vertices of point 1 is not finite.*fix"):
        AABBTree(x, [[0, 1, 2]], owner="cloth")
    with pytest.raises(ParameterError, match=r"cloth: contact thickness must be zero or "
                                             r"positive \(m\), got -0.1"):
        AABBTree(np.eye(3), [[0, 1, 2]], owner="cloth", pad=-0.1)


def test_edge_edge_proximity_equals_brute_force():
    from interplay.kernels.trimesh_contact import closest_segments
    rng = np.random.default_rng(8)
    reach = 0.05

    def segments(m):
        a = rng.uniform(-1, 1, (m, 3))
        b = a + rng.normal(0, 0.1, (m, 3))
        b[::7] = a[::7] + 1e-9 * rng.normal(size=3)  # near-degenerate: almost points
        return np.vstack([a, b]), np.column_stack([np.arange(m), np.arange(m) + m])

    xa, ea = segments(400)
    xb, eb = segments(300)
    # each tree grows its boxes by half the reach: boxes of segments closer than reach overlap
    ta, tb = AABBTree(xa, ea, pad=reach / 2), AABBTree(xb, eb, pad=reach / 2)
    pairs, st, d = ta.edge_contacts(tb, reach)
    got = {tuple(p): dd for p, dd in zip(pairs, d)}
    brute = {}
    for i in range(len(ea)):
        for j in range(len(eb)):
            d2 = closest_segments(xa[ea[i, 0]], xa[ea[i, 1]], xb[eb[j, 0]], xb[eb[j, 1]])[2]
            if d2 <= reach * reach:
                brute[(i, j)] = np.sqrt(d2)
    assert set(got) == set(brute) and len(brute) > 20
    assert all(abs(got[k] - brute[k]) < 1e-12 for k in brute)
    # the closest points' parameters reproduce the distances
    p = xa[ea[pairs[:, 0], 0]] + st[:, :1] * (xa[ea[pairs[:, 0], 1]] - xa[ea[pairs[:, 0], 0]])
    q = xb[eb[pairs[:, 1], 0]] + st[:, 1:] * (xb[eb[pairs[:, 1], 1]] - xb[eb[pairs[:, 1], 0]])
    assert np.allclose(np.linalg.norm(p - q, axis=1), d, atol=1e-12)


@pytest.mark.parametrize("n", [0, 1, 2, 3, 63, 64, 65, 1000])
def test_the_builds_sort_is_numpys_stable_argsort(n):
    # the tree's median split orders centroids with it; the same permutation as NumPy's
    # stable sort (ties in their given order) keeps every tree, and every contact sum over
    # it, the same to the bit as before it replaced np.argsort(kind="mergesort")
    rng = np.random.default_rng(n)
    for keys in (rng.random(n), rng.integers(0, 4, n).astype(float), np.zeros(n),
                 rng.integers(0, 9, n)):  # int keys: the water's lids by column
        assert np.array_equal(stable_argsort(keys), np.argsort(keys, kind="stable"))


def test_serial_and_parallel_refits_fit_the_same_boxes():
    # the tree refits in one thread below PARALLEL_LEAVES elements: the same boxes, to the bit
    from interplay.kernels import aabb_tree as K
    rng = np.random.default_rng(6)
    x, t = random_soup(rng, 300)
    x1 = x + rng.normal(0, 0.05, x.shape)
    a, b = AABBTree(x, t, pad=0.01), AABBTree(x, t, pad=0.01)
    K.refit(a.tree, a.elements, x, x1, 0.01)
    K.refit_serial(b.tree, b.elements, x, x1, 0.01)
    assert np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi)


def test_a_hint_changes_nothing_but_the_search():
    # any hint, right, wrong, out of reach or none, gives the same nearest triangle bit for
    # bit: the hint only bounds the descent (kernels/aabb_tree.nearest_triangles)
    rng = np.random.default_rng(6)
    x, t = random_soup(rng, 400)
    pts = rng.uniform(-1.1, 1.1, (2000, 3))
    tree = AABBTree(x, t)
    tri, d, bary = tree.nearest(pts, 0.15)
    moved = pts + rng.normal(0, 0.01, pts.shape)
    want = tree.nearest(moved, 0.15)
    for hint in (tri, rng.integers(-1, len(t), len(pts)), np.full(len(pts), -1)):
        got = tree.nearest(moved, 0.15, hint=hint)
        for a, b in zip(got, want):
            assert np.array_equal(a, b)
    with pytest.raises(ParameterError, match="hint"):
        tree.nearest(pts, 0.15, hint=np.full(len(pts), len(t)))


@pytest.mark.parametrize("m", [500, 3000])
def test_refitting_the_moved_elements_alone_equals_a_full_refit(m):
    rng = np.random.default_rng(7)
    x, t = random_soup(rng, m)
    tree, full = AABBTree(x, t, pad=0.01), AABBTree(x, t, pad=0.01)
    for _ in range(5):
        some = rng.choice(m, m // 20, replace=False)
        x = x.copy()
        x[t[some].ravel()] += rng.normal(0, 0.1, (3 * len(some), 3))
        moved = np.flatnonzero(np.isin(t, t[some]).any(axis=1))  # sharing a moved vertex
        tree.refit_some(x, moved)
        full.refit(x)
        assert np.array_equal(tree.lo, full.lo) and np.array_equal(tree.hi, full.hi)
