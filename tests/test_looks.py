"""What the outputs show: only the floors a scene has, at their height; water only where it
stands, over its drawn bed; motion capture without its T-pose or sunk feet; a rider that
pedals; USD with materials, UVs, double-sided cloth, velocities, cords as polylines, named
figure segments; turbulence with the statistics it is given."""
import numpy as np
import pytest

from interplay.errors import InterplayError
from interplay.outputs.rundata import from_result
from interplay.systems.mocap import MocapFigure, clip_path


def _gl_renderer(run, size=(160, 90)):
    from interplay.outputs.render.gl import Renderer
    try:
        return Renderer(run, size)
    except InterplayError as e:
        pytest.skip(str(e))


@pytest.fixture(scope="module")
def pond():
    """A small pond (48 columns), two balls, 0.3 s: wet and dry columns and spray."""
    from interplay import params as P
    from interplay.scenes import spec
    s = spec("pond")
    p = P.apply(s.params(), {"basin.cells": "48", "balls.count": "2"})
    return from_result(s.build("two-way", duration=0.3, fps=20, params=p).simulate())


def test_no_floor_is_drawn_where_the_scene_has_none():
    from interplay.outputs.rundata import RunData, Shape
    from interplay.geometry.sphere import icosphere
    v, t = icosphere(1)
    run = RunData("floating", "none", 10.0, 0.2, [Shape("ball", "body", (0.8, 0.3, 0.1),
                                                        verts=0.1 * v, tris=t)],
                  {"ball": {"t": np.array([0.0, 0.1, 0.2]),
                            "position": np.array([[0, 0, 5.0], [0, 0, 4.9], [0, 0, 4.8]]),
                            "orientation": np.tile([1.0, 0, 0, 0], (3, 1))}}, "ball")
    with _gl_renderer(run) as r:
        img = r.render(run, 0.1)
        assert [s.name for s in r.shapes] == ["ball"]
        assert not any("floor" in ob for ob in r._objects)
    assert img.std() > 3  # the ball in front of the backdrop


def test_a_floor_is_drawn_at_its_physical_height():
    from interplay.systems.static import StaticPlane
    from interplay.outputs.render.gl import floor_extent
    for height in (0.0, 0.37, 40.0):
        (shape,) = StaticPlane("floor", height=height, extent=(-2, 3, -1, 4)).shapes()
        assert np.all(shape.verts[:, 2] == height)
        assert floor_extent(shape) == (-2.0, 3.0, -1.0, 4.0)
    # the bungee's only floor is the valley at z = 0, 40 m under the deck (no floor at the
    # jumper's lowest point any more); its deck, platform and arm are drawn set pieces
    from interplay.scenes import spec
    scene = spec("bungee").build("two-way", duration=0.01)
    statics = {sh.name: sh for s in scene.systems for sh in s.shapes() if sh.form == "static"}
    floors = {n: float(s.verts[:, 2].max()) for n, s in statics.items() if floor_extent(s)}
    assert floors == {"valley": 0.0}
    assert {"bridge-deck", "jump-platform", "jump-arm"} <= set(statics)
    assert statics["bridge-deck"].verts[:, 2].max() == pytest.approx(40.0)


def test_water_is_drawn_only_where_it_stands_and_its_bed_is_drawn(pond):
    from interplay.outputs.geometry import wet_surface
    from interplay.systems.shape import DRY
    water, bed = pond.shape("water"), pond.shape("water-bed")
    assert water.material == "water" and water.look.opacity < 1.0
    # the bed: the basin's floor and shore under every column (drawn at every 2nd column)
    assert bed.form == "static" and bed.verts[:, 2].max() == pytest.approx(water.base.max())
    pts = pond.frames["water"]["points"][-1]
    drawn, alpha, wet = wet_surface(water, pts)
    depth = pts[:, 2] - water.base
    dry = depth <= DRY
    assert dry.any() and (~dry).any()  # the shore is dry, the middle wet
    # a face is drawn iff one of its corners holds water; dry corners sit under the bed
    np.testing.assert_array_equal(wet, (~dry)[water.triangles].any(axis=1))
    assert np.all(drawn[dry, 2] < water.base[dry]) and np.all(drawn[~dry, 2] == pts[~dry, 2])
    assert np.all((alpha > 0) & (alpha < 1))


def test_usd_water_has_holes_where_it_is_dry(pond, tmp_path):
    pytest.importorskip("pxr")
    from pxr import Usd, UsdGeom
    from interplay.outputs.geometry import wet_surface
    from interplay.outputs.usd import validate, write_usd
    path = write_usd(pond, tmp_path / "pond.usdc")
    assert validate(path) == []
    stage = Usd.Stage.Open(str(path))
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/water"))
    last = len(pond.times) - 1
    holes = np.array(mesh.GetHoleIndicesAttr().Get(last))
    _, _, wet = wet_surface(pond.shape("water"), pond.frames["water"]["points"][last])
    np.testing.assert_array_equal(holes, np.flatnonzero(~wet))
    assert stage.GetPrimAtPath("/World/water_bed/geom").IsA(UsdGeom.Mesh)


CLIPS = {"cmu_02_03_run.bvh": True, "cmu_127_03_run.bvh": True,
         "cmu_13_32_forward_jump.bvh": True, "cmu_131_01_walk_scaled.bvh": False,
         "cmu_131_03_hop_scaled.bvh": False}


def _clip(name):
    p = clip_path(name)
    if not p.exists():
        pytest.skip(f"mocap clip {name} not present")
    return p


def _first_speeds(fig, span=0.1, step=1.0 / 240):
    out = []
    for t in np.arange(0.0, span, step):
        fig.set_time(t)
        out.append(np.linalg.norm(fig.generalized_state()[1][:51].reshape(17, 3), axis=1).max())
    return max(out)


@pytest.mark.parametrize("name", CLIPS)
def test_a_tpose_frame_0_is_skipped_and_the_clip_starts_in_motion(name):
    fig = MocapFigure("clip", _clip(name))
    assert fig.skipped_tpose == CLIPS[name]
    # without the skip the spline swings from the T-pose into the run: ~170 m/s
    assert _first_speeds(fig) < 10.0


def test_a_tpose_added_to_a_clean_clip_is_found(tmp_path):
    """The walk has no T-pose: give it one (every rotation zero, the root where it starts)."""
    lines = _clip("cmu_131_01_walk_scaled.bvh").read_text().splitlines()
    at = next(i for i, ln in enumerate(lines) if ln.startswith("Frame Time"))
    first = lines[at + 1].split()
    tpose = " ".join(first[:3] + ["0"] * (len(first) - 3))
    frames = next(i for i, ln in enumerate(lines) if ln.startswith("Frames:"))
    lines[frames] = f"Frames: {int(lines[frames].split()[1]) + 1}"
    lines.insert(at + 1, tpose)
    path = tmp_path / "walk_tpose.bvh"
    path.write_text("\n".join(lines) + "\n")
    fig = MocapFigure("clip", path)
    assert fig.skipped_tpose
    clean = MocapFigure("clip", _clip("cmu_131_01_walk_scaled.bvh"))
    fig.set_time(0.5)
    clean.set_time(0.5)
    np.testing.assert_allclose(fig.segment_positions(), clean.segment_positions(), atol=1e-9)


@pytest.mark.parametrize("name", ["cmu_02_03_run.bvh"])
def test_stance_feet_rest_on_the_ground(name):
    """The puddle's runner planted on a ground at z = 0.03 m (the pavement): in every stance
    frame (the foot slow, its sole at its lowest and still) the sole is within 1 cm of the
    ground. (A run has one foot down at a time; where a clip stands on both feet at different
    heights, one vertical offset cannot put both on the ground: docs/figures.md.)"""
    fig = MocapFigure("clip", _clip(name), ground=0.03)
    F = int(round(fig.duration / fig.motion.frame_time)) + 1
    pos, rot = [], []
    for f in range(F):
        fig.set_time(f * fig.motion.frame_time)
        p, R = fig.part_poses()
        pos.append(p.copy())
        rot.append(R.copy())
    pos, rot = np.array(pos), np.array(rot)
    sole = fig.soles(pos, rot)
    stand = fig.stances(pos, sole, fig.motion.frame_time)
    # the lowest point of a standing foot rolls heel to toe on the ground: never under it by
    # more than 1 cm, never above it by more than 1 cm
    assert np.all(np.abs(sole[stand] - 0.03) < 0.01), name
    assert stand.sum(axis=0).min() > 20  # both feet stand, for more than 20 frames each
    # unplanted, the clip's stances are off the ground by more than that
    raw = MocapFigure("clip", _clip(name))
    pos0 = pos.copy()
    pos0[:, :, 2] -= fig.plant_offsets[:, None]
    assert np.abs(raw.soles(pos0, rot)[stand] - 0.03).max() > 0.01


def test_the_rider_pedals_and_the_wheels_roll():
    from interplay.geometry.bicycle import Bicyclist
    b = Bicyclist()
    names = list(b.PART_NAMES)
    for s in np.linspace(0.0, 3.0, 13):
        pos, rot = b.pose(s)
        # the wheels turn by s / r about the axle (y), the crank by s / (r gear)
        a = s / b.r
        np.testing.assert_allclose(rot[names.index("rear_wheel")][[0, 2]][:, [0, 2]],
                                   [[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]],
                                   atol=1e-12)
        for side, pedal in zip("lr", b.pedals(s)):
            hip, knee, ankle = (pos[names.index(f"{side}_{p}")] for p in ("thigh", "shank",
                                                                          "foot"))
            # the legs keep their lengths and the foot stays on its pedal
            assert np.linalg.norm(knee - hip) == pytest.approx(b.thigh, abs=1e-9)
            assert np.linalg.norm(ankle - knee) == pytest.approx(b.shank, abs=1e-9)
            np.testing.assert_allclose(ankle - pedal, [-0.05, 0.0, 0.07], atol=1e-12)
            assert knee[0] > hip[0] - 0.05  # the knees bend forward
    # one crank turn moves the pedals round once: 2 pi r gear metres
    p0, p1 = b.pedals(0.0), b.pedals(2 * np.pi * b.r * b.gear)
    np.testing.assert_allclose(p0, p1, atol=1e-12)


def test_the_rider_rides_on_past_the_end_of_the_clip_of_the_path():
    from interplay.scenes.leaves import RiderParams, rider_path
    path = rider_path(RiderParams(), duration=6.0)
    assert path.velocity(5.9)[0] == pytest.approx(RiderParams().speed)


@pytest.fixture(scope="module")
def looks_runs():
    """Short runs of the flags, leaves and bungee scenes."""
    from interplay import params as P
    from interplay.scenes import spec
    runs = {}
    fl = P.apply(spec("flags").params(), {"cotton.nu": "8", "cotton.nv": "6", "nylon.nu": "6",
                                          "nylon.nv": "5", "canvas.nu": "8", "canvas.nv": "6"})
    runs["flags"] = from_result(spec("flags").build(duration=0.1, fps=30, params=fl).simulate())
    lv = P.apply(spec("leaves").params(), {"leaves.count": "4"})
    runs["leaves"] = from_result(spec("leaves").build(duration=0.1, fps=30,
                                                      params=lv).simulate())
    runs["bungee"] = from_result(spec("bungee").build("two-way", duration=0.1).simulate())
    return runs


def test_usd_an_animator_can_use(looks_runs, tmp_path):
    pytest.importorskip("pxr")
    from pxr import Usd, UsdGeom, UsdShade
    from interplay.outputs.usd import validate, write_usd
    stages = {}
    for name, run in looks_runs.items():
        path = write_usd(run, tmp_path / f"{name}.usdc")
        assert validate(path) == [], name
        stages[name] = Usd.Stage.Open(str(path))
    for name, stage in stages.items():
        # every gprim wears a UsdPreviewSurface material
        for prim in stage.Traverse():
            if prim.IsA(UsdGeom.Gprim):
                mat, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
                assert mat, f"{name}: {prim.GetPath()} has no material"
                shader = UsdShade.Shader(mat.GetSurfaceOutput().GetConnectedSources()[0][0]
                                         .source.GetPrim())
                assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
    flag = UsdGeom.Mesh(stages["flags"].GetPrimAtPath("/World/cotton"))
    # cloth: double-sided, texture coordinates 0..1, velocities for motion blur
    assert flag.GetDoubleSidedAttr().Get() is True
    st = np.array(UsdGeom.PrimvarsAPI(flag).GetPrimvar("st").Get())
    assert st.shape == (48, 2) and st.min() == pytest.approx(0.0) and st.max() == 1.0
    run = looks_runs["flags"]
    vel = np.array(flag.GetVelocitiesAttr().Get(1))
    fr = run.frames["cotton"]
    expect = (fr["points"][2] - fr["points"][0]) / (fr["t"][2] - fr["t"][0])
    np.testing.assert_allclose(vel, expect, rtol=1e-5, atol=1e-5)
    # each leaf its own prim, double-sided, with its own autumn colour
    leaves = stages["leaves"].GetPrimAtPath("/World/leaves")
    kids = [UsdGeom.Mesh(c) for c in leaves.GetChildren()]
    assert len(kids) == 4 and all(k.GetDoubleSidedAttr().Get() for k in kids)
    assert all(UsdGeom.PrimvarsAPI(k).GetPrimvar("st") for k in kids)
    # the rider: a transform per part over a static mesh, nested (frame / rider / head)
    head = stages["leaves"].GetPrimAtPath("/World/bicyclist/frame/rider/head")
    assert head.IsA(UsdGeom.Xform) and not UsdGeom.Mesh(head.GetChild("geom")).GetPointsAttr() \
        .GetNumTimeSamples()
    # the figure: anatomically named segments nested under the figure's prim
    jumper = stages["bungee"]
    for path in ("/World/jumper/pelvis", "/World/jumper/pelvis/torso/head",
                 "/World/jumper/pelvis/r_thigh/r_shank/r_foot/r_toes"):
        assert jumper.GetPrimAtPath(path).IsA(UsdGeom.Xform), path
    # the world pose of a nested segment is the run's
    foot = UsdGeom.Xformable(jumper.GetPrimAtPath("/World/jumper/pelvis/r_thigh/r_shank/r_foot"))
    k = looks_runs["bungee"].shape("jumper").part_names.index("r_foot")
    np.testing.assert_allclose(np.array(foot.ComputeLocalToWorldTransform(2)).T[:3, 3],
                               looks_runs["bungee"].frames["jumper"]["segment_positions"][2, k],
                               atol=1e-9)
    # the cord: one polyline per cord (the cord with one strap, and the other strap), at its
    # real width
    cord = UsdGeom.BasisCurves(jumper.GetPrimAtPath("/World/cord"))
    counts = list(cord.GetCurveVertexCountsAttr().Get())
    assert sorted(counts) == [2, 22] and cord.GetWidthsAttr().Get()[0] == pytest.approx(0.032)


def test_turbulence_has_its_rms_and_no_divergence():
    from interplay.systems.wind import FlowPrimitive, WindField
    w = WindField("w", [FlowPrimitive("turbulence", strength=1.2, core=2.0, phase=0.7,
                                      velocity=(6.0, 0.0, 0.0))])
    p = np.random.default_rng(1).uniform(-30.0, 30.0, (40000, 3))
    v = w.velocity(p, 0.0)
    # 12 modes in random directions: the total is exact on average, the split between the
    # components is not (each within 35% here)
    assert np.sqrt(np.mean(np.sum(v * v, axis=1)) / 3) == pytest.approx(1.2, rel=0.03)
    assert np.abs(v.mean(axis=0)).max() < 0.02
    # carried by the mean wind: the field at x + U t at time t is the field at x at 0
    np.testing.assert_allclose(w.velocity(p[:50] + [6.0 * 0.4, 0, 0], 0.4), v[:50], atol=1e-9)
    h = 1e-4  # central differences: divergence O(h^2 k^3) ~ 1e-7 1/s
    x = p[:20]
    div = sum((w.velocity(x + h * e, 0.0) - w.velocity(x - h * e, 0.0))[:, i] / (2 * h)
              for i, e in enumerate(np.eye(3)))
    assert np.abs(div).max() < 1e-5
