"""USD, OBJ and scene.json outputs: round trips against result.frames, Pixar's validators,
atomic writes and clear errors."""
import numpy as np
import pytest

from interplay import Scene, SpringNetwork, Springs, StaticPlane
from interplay.errors import InterplayError, ParameterError
from interplay.outputs.obj import quat_matrix, read_obj, write_obj_sequence
from interplay.outputs.rundata import from_result, load_run, write_scene_file

pxr = pytest.importorskip("pxr")


def cloth_scene(n=6, duration=0.2, fps=30):
    """A hanging n x n cloth (a SpringNetwork carrying .triangles), pinned at two corners."""
    u = np.linspace(-0.5, 0.5, n)
    X, Y = np.meshgrid(u, u, indexing="ij")
    x = np.stack([X.ravel(), Y.ravel(), np.full(n * n, 1.5)], axis=1)
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    edges = np.unique(np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]],
                                              tris[:, [2, 0]]]), axis=1), axis=0)
    cloth = SpringNetwork("cloth", x, 0.2 / (n * n), Springs.from_ratio(x, edges, 50.0),
                          dt=2e-3, integrator="implicit", mass_damping=0.5,
                          fixed=[idx[0, 0], idx[0, -1]])
    cloth.triangles = tris
    sc = Scene("cloth", duration=duration, fps=fps)
    sc.add(cloth)
    sc.add(StaticPlane("floor"))
    sc.primary = cloth
    return sc


@pytest.fixture(scope="module")
def ball_result():
    from interplay.scenes import spec
    return spec("basketball").build("two-way", duration=0.4, fps=30).simulate()


@pytest.fixture(scope="module")
def cloth_result():
    return cloth_scene().simulate()


def test_shapes_cover_every_form(ball_result, cloth_result):
    forms = {s.name: s.form for s in from_result(ball_result).shapes}
    # the ball, the net, the floor and the hoop's set pieces (rim, backboard, pole)
    assert {"ball": "body", "net": "cords", "floor": "static", "rim": "static",
            "backboard": "static", "hoop-pole": "static"}.items() <= forms.items()
    forms = {s.name: s.form for s in from_result(cloth_result).shapes}
    assert forms == {"cloth": "surface", "floor": "static"}


def test_usd_round_trip_matches_frames(ball_result, tmp_path):
    from pxr import Usd, UsdGeom
    from interplay.outputs.usd import write_usd
    run = from_result(ball_result)
    path = write_usd(run, tmp_path / "run.usdc")
    stage = Usd.Stage.Open(str(path))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetTimeCodesPerSecond() == run.fps
    nf = len(run.times)
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0, nf - 1)
    assert stage.GetDefaultPrim().GetPath() == "/World"
    ball = UsdGeom.Xformable(stage.GetPrimAtPath("/World/ball"))
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath("/World/net"))
    assert curves.GetTypeAttr().Get() == UsdGeom.Tokens.linear
    assert curves.GetWidthsAttr().Get()[0] > 0
    from interplay.outputs.geometry import chains
    seg = np.concatenate(chains(run.shape("net").segments, run.frames["net"]["points"][0]))
    fr = ball_result.frames
    for i in (0, nf // 2, nf - 1):
        m = np.array(ball.ComputeLocalToWorldTransform(i)).T  # USD matrices are row-vector
        q = fr["ball"]["orientation"][i]
        np.testing.assert_allclose(m[:3, 3], fr["ball"]["position"][i], atol=1e-9)
        np.testing.assert_allclose(m[:3, :3], quat_matrix(q), atol=1e-9)
        pts = np.array(curves.GetPointsAttr().Get(i))
        np.testing.assert_allclose(pts, fr["net"]["points"][i][seg], rtol=0, atol=1e-6)
    # the ball's seams: a colour per vertex
    colour = UsdGeom.Gprim(stage.GetPrimAtPath("/World/ball/geom")).GetDisplayColorAttr().Get()
    assert len(colour) == len(run.shape("ball").verts)


def test_usd_mesh_of_a_deforming_surface(cloth_result, tmp_path):
    from pxr import Usd, UsdGeom
    from interplay.outputs.usd import write_usd
    run = from_result(cloth_result)
    path = write_usd(run, tmp_path / "cloth.usda")
    assert path.read_text().startswith("#usda")
    stage = Usd.Stage.Open(str(path))  # keep the stage alive while its prims are used
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/cloth"))
    assert mesh.GetSubdivisionSchemeAttr().Get() == "none"
    assert mesh.GetNormalsInterpolation() == UsdGeom.Tokens.vertex
    for i in (0, len(run.times) - 1):
        pts = np.array(mesh.GetPointsAttr().Get(i))
        np.testing.assert_allclose(pts, cloth_result.frames["cloth"]["points"][i], atol=1e-6)
        assert len(mesh.GetNormalsAttr().Get(i)) == len(pts)


def test_usd_passes_every_registered_validator(ball_result, cloth_result, tmp_path):
    from interplay.outputs.usd import validate, write_usd
    for name, result in (("ball", ball_result), ("cloth", cloth_result)):
        path = write_usd(from_result(result), tmp_path / f"{name}.usdc")
        assert validate(path) == []


def test_usd_bad_format_is_one_clear_error(ball_result, tmp_path):
    from interplay.outputs.usd import write_usd
    with pytest.raises(ParameterError, match="usdc .*usda"):
        write_usd(from_result(ball_result), tmp_path / "run.usdc", fmt="usdz")


def test_obj_sequence_parses_back(ball_result, cloth_result, tmp_path):
    run = from_result(ball_result)
    write_obj_sequence(run, tmp_path / "obj")
    nf = len(run.times)
    net_files = sorted((tmp_path / "obj" / "net").glob("*.obj"))
    assert len(net_files) == nf and len(list((tmp_path / "obj" / "ball").glob("*.obj"))) == nf
    last = read_obj(net_files[-1])
    np.testing.assert_allclose(last["v"], ball_result.frames["net"]["points"][-1], atol=2e-6)
    np.testing.assert_array_equal(last["l"], run.shape("net").segments)
    ball = read_obj(tmp_path / "obj" / "ball" / f"ball_{nf - 1:04d}.obj")
    np.testing.assert_allclose(ball["v"].mean(0), ball_result.frames["ball"]["position"][-1],
                               atol=1e-3)
    floor = read_obj(tmp_path / "obj" / "floor.obj")
    assert floor["f"].shape == (2, 3)
    crun = from_result(cloth_result)
    write_obj_sequence(crun, tmp_path / "cobj")
    cl = read_obj(tmp_path / "cobj" / "cloth" / "cloth_0000.obj")
    np.testing.assert_array_equal(cl["f"], crun.shape("cloth").triangles)
    assert cl["vn"].shape == cl["v"].shape
    assert not list(tmp_path.glob(".*part"))


def test_obj_crash_leaves_no_sequence(ball_result, tmp_path):
    def boom(done, total):
        if done == 3:
            raise RuntimeError("disk on fire")
    with pytest.raises(RuntimeError):
        write_obj_sequence(from_result(ball_result), tmp_path / "obj", progress=boom)
    assert not (tmp_path / "obj").exists() and not list(tmp_path.iterdir())


def test_scene_file_round_trip(ball_result, tmp_path):
    run = from_result(ball_result)
    ball_result.save(tmp_path)
    write_scene_file(run, tmp_path)
    back = load_run(tmp_path)
    assert [s.name for s in back.shapes] == [s.name for s in run.shapes]
    np.testing.assert_array_equal(back.shape("net").segments, run.shape("net").segments)
    np.testing.assert_allclose(back.frames["net"]["points"], run.frames["net"]["points"])
    assert back.fps == run.fps and back.primary == "ball"
    assert back.summary["scene"] == "basketball"


def test_load_run_of_a_wrong_directory_says_what_to_pass(tmp_path):
    with pytest.raises(InterplayError, match="scene.json.*interplay run"):
        load_run(tmp_path)


def test_unwritable_output_directory_is_one_clear_error(ball_result, tmp_path):
    from interplay.outputs.writer import OutputOptions, write_outputs
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    with pytest.raises(InterplayError, match="cannot write to output directory .*--out"):
        write_outputs(ball_result, blocker / "out", OutputOptions(video=False, report=False))


def synthetic_run():
    """A two-segment figure (parts) and spray (particles that come and go, NaN rows when
    absent), written directly: the forms the figure and water systems produce."""
    from interplay.geometry.sphere import icosphere
    from interplay.outputs.rundata import RunData, Shape
    v, t = icosphere(1)
    nf = 5
    times = np.arange(nf) / 10.0
    seg_pos = np.zeros((nf, 2, 3))
    seg_pos[:, 0, 2], seg_pos[:, 1, 2] = 1.0 + times, 1.5 + times
    seg_q = np.tile([1.0, 0.0, 0.0, 0.0], (nf, 2, 1))
    spray = np.full((nf, 4, 3), np.nan)
    for i in range(nf):
        spray[i, :i] = [0.5, 0.0, 0.2 * i]  # i particles at frame i
    shapes = [Shape("figure", "parts", (0.3, 0.6, 0.8), parts=[(v * 0.1, t), (v * 0.2, t)],
                    part_names=("pelvis", "torso"), part_parents=(-1, 0)),
              Shape("spray", "particles", (0.3, 0.6, 0.9), width=0.01)]
    frames = {"figure": {"t": times, "segment_positions": seg_pos,
                         "segment_orientations": seg_q},
              "spray": {"t": times, "points": spray}}
    return RunData("synthetic", "none", 10.0, 0.4, shapes, frames, "figure")


def test_figures_and_spray_export(tmp_path):
    from pxr import Usd, UsdGeom
    from interplay.outputs.usd import validate, write_usd
    run = synthetic_run()
    path = write_usd(run, tmp_path / "s.usdc")
    assert validate(path) == []
    stage = Usd.Stage.Open(str(path))
    seg1 = UsdGeom.Xformable(stage.GetPrimAtPath("/World/figure/pelvis/torso"))
    np.testing.assert_allclose(np.array(seg1.ComputeLocalToWorldTransform(3)).T[:3, 3],
                               [0.0, 0.0, 1.8], atol=1e-12)
    pts = UsdGeom.Points(stage.GetPrimAtPath("/World/spray")).GetPointsAttr()
    assert [len(pts.Get(i)) for i in range(5)] == [0, 1, 2, 3, 4]
    write_obj_sequence(run, tmp_path / "obj")
    assert len(read_obj(tmp_path / "obj" / "spray" / "spray_0003.obj")["v"]) == 3
    fig = read_obj(tmp_path / "obj" / "figure" / "figure_0002.obj")
    assert fig["f"].shape[0] == 2 * 80 and fig["v"][:, 2].max() > 1.5
    lo, hi = run.bounds()
    assert np.all(np.isfinite(lo)) and hi[2] == pytest.approx(1.9 + 0.2)
    s = run.sample("spray", 0.25)  # between frames 2 and 3: particles are not blended
    assert np.isfinite(s["points"]).all(axis=1).sum() in (2, 3)


def test_figures_and_spray_render(tmp_path):
    from interplay.outputs.render.gl import Renderer
    try:
        r = Renderer(synthetic_run(), (160, 90))
    except InterplayError as e:
        pytest.skip(str(e))
    with r:
        img = r.render(synthetic_run(), 0.3)
    assert img.std() > 5  # figure and spray in front of the backdrop
    assert [s.name for s in r.shapes] == ["figure", "spray"]  # no floor invented
