"""Mesh -> spring network: hand-counted springs, masses, generators, and every bad-mesh error."""
import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.geometry.bicycle import Bicyclist
from interplay.geometry import mesh as M
from interplay.geometry import shapes
from interplay.systems.springmass import SpringNetwork


def test_hand_counted_grid():
    # 3x3 vertices, 2x2 cells, 8 triangles. Edges: 6 horizontal + 6 vertical + 4 diagonals = 16.
    # Interior edges (two triangles): the 4 diagonals (-> 4 shear springs, the other diagonal)
    # and the 4 inner axis edges (-> 4 bending springs); the 8 boundary edges have none.
    x, t = shapes.grid(2.0, 2.0, 3, 3)
    ms = M.mesh_springs(x, t, total_mass=3.0)
    assert (len(t), ms.count("structural"), ms.count("shear"), ms.count("bending")) == (8, 16, 4, 4)
    assert ms.masses.sum() == pytest.approx(3.0, rel=1e-12)
    # by area: every triangle has area 1/2 m^2 and the density is 3 kg / 4 m^2, so
    # m_i = (3 kg / 4 m^2) * (incident triangles) * (1/2) / 3
    inc = np.bincount(t.ravel(), minlength=9)
    assert np.allclose(ms.masses, 3.0 / 4.0 * inc * 0.5 / 3.0)
    uni = M.mesh_springs(x, t, 3.0, masses="uniform").masses
    assert np.allclose(uni, 3.0 / 9)
    # shear springs are the other quad diagonals (length 2 sqrt(2) / 2 = sqrt 2 m)
    sh = ms.pairs[ms.kind == 1]
    assert np.allclose(np.linalg.norm(x[sh[:, 0]] - x[sh[:, 1]], axis=1), np.sqrt(2))


def test_two_triangles_and_stiffness():
    # a unit square split on its diagonal: 5 edges, one cross spring (a shear spring: the
    # shared edge is the longest of both triangles), k = ratio / l0
    x = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    t = np.array([[0, 1, 2], [0, 2, 3]])
    net = SpringNetwork.from_mesh("sq", x, t, total_mass=0.4, stretch=100.0, shear=50.0,
                                  bend=1.0, integrator="implicit")
    assert len(net.si) == 6 and net.spring_kind.tolist().count(1) == 1
    rest = np.linalg.norm(x[net.si] - x[net.sj], axis=1)
    expect = np.where(net.spring_kind == 0, 100.0, 50.0) / rest
    assert np.allclose(net.k, expect)
    assert net.triangles.shape == (2, 3) and net.mass == pytest.approx(0.4)


def test_leaf_vein_is_stiffer():
    x, t, vein = shapes.leaf(0.1, 0.05, stations=6, rows=2)
    net = SpringNetwork.from_mesh("leaf", x, t, 1e-3, stretch=10.0, stiffen=(vein, 5.0))
    on = np.isin(net.si, vein) & np.isin(net.sj, vein) & (net.spring_kind == 0)
    assert on.sum() == len(vein) - 1  # the midrib is a chain of structural edges
    l0 = net.l0
    assert np.allclose(net.k[on] * l0[on], 50.0) and np.allclose(net.k[~on & (net.spring_kind == 0)]
                                                                 * l0[~on & (net.spring_kind == 0)], 10.0)


def test_generators_are_valid_meshes():
    x, t = shapes.disc(0.5, 4)
    M.validate(x, t)
    # area converges to pi r^2 from below (inscribed polygon, 24 sides: ~1.1 % short)
    assert M.triangle_areas(x, t).sum() == pytest.approx(np.pi * 0.25, rel=0.02)
    x, t, vein = shapes.leaf(0.12, 0.06)
    assert np.all(x[vein, 1] == 0.0)
    M.validate(*Bicyclist().mesh())


def test_load_obj_ply_stl(tmp_path):
    import trimesh
    x, t = shapes.grid(1.0, 0.5, 4, 3)
    for ext in ("obj", "ply", "stl"):
        path = tmp_path / f"cloth.{ext}"
        trimesh.Trimesh(x, t, process=False).export(path)
        xl, tl = M.load(path)
        if ext != "stl":  # STL stores triangle soup: vertices come back unmerged
            assert np.allclose(xl, x) and np.array_equal(tl, t)
        assert M.triangle_areas(xl, tl).sum() == pytest.approx(0.5)


def test_load_errors(tmp_path):
    with pytest.raises(ParameterError, match="does not exist"):
        M.load(tmp_path / "none.obj")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 0 0\nf 1 2 3\n")
    with pytest.raises(ParameterError, match=r"bad.obj: triangle 0 has a zero-length edge"):
        M.load(bad)


SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)


@pytest.mark.parametrize("verts,tris,message", [
    (SQUARE * [1, 1, np.nan], [[0, 1, 2]], r"vertex 0 has a non-finite coordinate"),
    (np.where(np.arange(4)[:, None] == 2, np.inf, SQUARE), [[0, 1, 3]],
     r"vertex 2 has a non-finite coordinate"),
    (SQUARE, [[0, 1, 2], [0, 2, 4]], r"triangle 1 \[0, 2, 4\] references a vertex outside 0..3"),
    (SQUARE, [[0, 1, 2], [0, 2, 2]], r"triangle 1 \[0, 2, 2\] repeats a vertex"),
    (np.vstack([SQUARE, [[1, 1, 0]]]), [[0, 1, 2], [0, 4, 2]],
     r"triangle 1 has a zero-length edge between vertices 4 and 2"),
    (np.vstack([SQUARE, [[2, 2, 0]]]), [[0, 1, 3], [0, 2, 4]],
     r"triangle 1 \[0, 2, 4\] has zero area"),
    (SQUARE, [[0, 1, 2], [0, 2, 3], [2, 0, 1]], r"triangle 2 \[2, 0, 1\] duplicates triangle 0"),
    (SQUARE[:, :2], [[0, 1, 2]], r"vertices must be an \(n,3\) array"),
    (SQUARE, [[0, 1]], r"triangles must be an \(m,3\) array"),
    (SQUARE, [[0.0, 1.0, 2.0]], r"triangle indices must be integers"),
])
def test_bad_meshes_name_the_first_offender(verts, tris, message):
    with pytest.raises(ParameterError, match=message):
        M.validate(verts, np.asarray(tris))


def test_builder_errors():
    x, t = SQUARE, np.array([[0, 1, 2]])
    with pytest.raises(ParameterError, match=r"vertex 3 belongs to no triangle"):
        M.mesh_springs(x, t, 1.0)
    with pytest.raises(ParameterError, match=r"unknown mass distribution 'volume'"):
        M.mesh_springs(x[:3], t, 1.0, masses="volume")
    with pytest.raises(ParameterError, match=r"total_mass must be a positive"):
        M.mesh_springs(x[:3], t, 0.0)
    with pytest.raises(ParameterError, match=r"stretch must be a positive"):
        SpringNetwork.from_mesh("c", x[:3], t, 1.0, stretch=-1.0)
    with pytest.raises(ParameterError, match=r"grid: nu must be an integer >= 2"):
        shapes.grid(1.0, 1.0, 1, 3)
