"""BVH reading, unit and axis detection, retargeting onto the figure, bad files."""
import numpy as np
import pytest

from interplay.io.motion_file import BVHError, read_bvh
from interplay.systems.mocap import MocapFigure, clip_path

MOCAP = clip_path("x.bvh").parent  # ../shared/data/mocap beside the repository (or a worktree's)
CLIPS = ["cmu_02_03_run.bvh", "cmu_127_03_run.bvh", "cmu_13_32_forward_jump.bvh",
         "cmu_131_01_walk_scaled.bvh", "cmu_131_03_hop_scaled.bvh"]


def _clip(name):
    p = MOCAP / name
    if not p.exists():
        pytest.skip(f"mocap clip {name} not present in {MOCAP}")
    return p


@pytest.mark.parametrize("name", CLIPS)
def test_real_clips_read_with_their_frame_counts(name):
    m = read_bvh(_clip(name))
    assert len(m.joints) == 31 and m.frames.shape[1] == 96
    assert len(m.frames) == {"cmu_02_03_run.bvh": 174, "cmu_127_03_run.bvh": 333,
                             "cmu_13_32_forward_jump.bvh": 337,
                             "cmu_131_01_walk_scaled.bvh": 995,
                             "cmu_131_03_hop_scaled.bvh": 1248}[name]


@pytest.mark.parametrize("name, units, hips", [
    ("cmu_02_03_run.bvh", "cmu", (9.2872, 16.9500, -34.2762)),
    ("cmu_131_01_walk_scaled.bvh", "m", (0.2952, 0.9539, -1.9134)),
])
def test_units_and_up_axis_are_detected(name, units, hips):
    fig = MocapFigure("clip", _clip(name))
    assert fig.units == units
    s = 0.0254 / 0.45 if units == "cmu" else 1.0
    # BVH (x, y, z) with +Y up and facing +Z -> world (z, x, y): +x forward, +y left, +z up
    x, y, z = (v * s for v in hips)
    assert np.allclose(fig.segment_positions()[0], (z, x, y), atol=1e-4)  # README rounds


@pytest.mark.parametrize("name", CLIPS)
def test_retargeted_clip_keeps_root_path_and_foot_heights(name):
    fig = MocapFigure("clip", _clip(name))
    jp = fig.joint_positions
    hips, lf, rf = (fig.joint_index[s] for s in ("pelvis", "l_foot", "r_foot"))
    for f in range(len(jp)):
        fig.time = 0.0
        fig.advance(f * fig.dt)  # spline knots: the frames themselves
        sp = fig.segment_positions()
        assert np.linalg.norm(sp[0] - jp[f, hips]) < 1e-6
        # ankles within 3 cm of the clip's (the figure has the clip's leg lengths; what is left
        # is the hip joint's placement under a constant clavicle-like LHipJoint)
        assert abs(sp[11, 2] - jp[f, lf, 2]) < 0.03 and abs(sp[15, 2] - jp[f, rf, 2]) < 0.03


def test_playback_velocity_is_smooth_and_forces_are_ignored():
    fig = MocapFigure("clip", _clip("cmu_02_03_run.bvh"))
    fig.add_wrench([1e6, 0, 0])
    v = []
    for _ in range(100):
        fig.advance(1.0 / 240)  # between frames too
        v.append(fig.generalized_state()[1][:3].copy())
    v = np.array(v[12:])  # past the spline's free end (the first 50 ms)
    assert 2.0 < np.median(v[:, 0]) < 3.2  # the jog's ~2.6 m/s along +x
    assert np.abs(np.diff(v, axis=0)).max() < 0.5  # no jumps between samples (m/s per 4 ms)


GOOD = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT LeftUpLeg
  {
    OFFSET 1 -1 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0 -5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0083333
0 10 0 0 0 0 0 0 0
0 10 1 0 0 0 10 0 0
"""


def _write(tmp_path, text):
    p = tmp_path / "clip.bvh"
    p.write_text(text)
    return p


def test_small_file_reads_and_composes_rotations(tmp_path):
    m = read_bvh(_write(tmp_path, GOOD))
    pos, rot = m.global_transforms()
    assert np.allclose(pos[1, 1], [0.0 + 1.0, 10 - 1, 1.0])
    assert np.allclose(rot[1, 1], [[np.cos(0.1745329), -np.sin(0.1745329), 0],
                                   [np.sin(0.1745329), np.cos(0.1745329), 0], [0, 0, 1]],
                       atol=1e-6)


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.rsplit("\n", 2)[0] + "\n", r"Frames: says 2 but only 1 motion lines follow"),
    (lambda t: t.replace("0 10 1 0 0 0 10 0 0", "0 10 1 0 0 0 10 0"),
     r"clip.bvh:20: expected 9 numbers, got 8"),
    (lambda t: t.replace("0 10 1 0 0 0 10 0 0", "0 10 1 0 0 0 ten 0 0"),
     r"clip.bvh:20: expected a number, got 'ten'"),
    (lambda t: t.replace("CHANNELS 3 Zrotation", "CHANNELS 3 Wrotation"),
     r"clip.bvh:9: CHANNELS says 3 but lists"),
    (lambda t: "\n".join(t.splitlines()[:9]), r"ends inside the HIERARCHY section"),
])
def test_bad_bvh_files_name_the_line(tmp_path, edit, message):
    with pytest.raises(BVHError, match=message):
        read_bvh(_write(tmp_path, edit(GOOD)))


def test_unknown_joints_are_refused_with_the_names_expected(tmp_path):
    with pytest.raises(BVHError, match=r"no joint for segment\(s\) torso, head"):
        MocapFigure("clip", _write(tmp_path, GOOD))
