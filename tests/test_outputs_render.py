"""Preview rendering and MP4 videos: frames decode with the expected count and size; camera
specs; missing dependencies and crashes give one clear error and no file."""
import sys

import numpy as np
import pytest

from interplay.errors import InterplayError, ParameterError
from interplay.outputs.rundata import from_result
from interplay.outputs.render.camera import Camera, default_camera, parse_camera

SIZE = (320, 180)  # small frames keep the default suite fast


def _has_gl():
    try:
        from interplay.outputs.render.gl import gl_context
        gl_context()
        return True
    except InterplayError:
        return False


needs_gl = pytest.mark.skipif(not _has_gl(), reason="no headless OpenGL (EGL) context")


@pytest.fixture(scope="module")
def run():
    from interplay.scenes import spec
    return from_result(spec("basketball").build("two-way", duration=0.4, fps=30).simulate())


def _read_mp4(path):
    import imageio_ffmpeg
    gen = imageio_ffmpeg.read_frames(str(path))
    meta = next(gen)
    w, h = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(h, w, 3) for f in gen]
    return meta, frames


@pytest.mark.parametrize("spec, expect", [
    ("1,2,3:0,0,1", Camera((1.0, 2.0, 3.0), (0.0, 0.0, 1.0), 35.0)),
    ("1,2,3:0,0,1:50", Camera((1.0, 2.0, 3.0), (0.0, 0.0, 1.0), 50.0)),
])
def test_camera_spec_parses(spec, expect):
    assert parse_camera(spec) == expect
    assert parse_camera(expect.spec()) == expect


@pytest.mark.parametrize("spec, words", [
    ("1,2,3", "eye_x,eye_y,eye_z:target"),
    ("1,2:0,0,1", "3 coordinates"),
    ("a,b,c:0,0,1", "not numbers"),
    ("1,2,3:0,0,1:500", "field of view"),
    ("1,1,1:1,1,1", "same point"),
])
def test_bad_camera_spec_is_one_clear_error(spec, words):
    with pytest.raises(ParameterError, match=words) as e:
        parse_camera(spec)
    assert "\n" not in str(e.value) and spec in str(e.value)


def test_default_camera_sees_every_corner():
    lo, hi = np.array([-0.3, -0.2, 0.0]), np.array([0.4, 0.3, 3.8])
    cam = default_camera(lo, hi, 16 / 9)
    vp = cam.projection(16 / 9, 0.05, 100.0) @ cam.view()
    for x in (lo[0], hi[0]):
        for y in (lo[1], hi[1]):
            for z in (lo[2], hi[2]):
                p = vp @ np.array([x, y, z, 1.0])
                assert np.all(np.abs(p[:2] / p[3]) <= 1.0)


@needs_gl
def test_frame_is_lit_and_not_blank(run):
    from interplay.outputs.render.gl import Renderer
    with Renderer(run, SIZE) as r:
        img = r.render(run, 0.3)
    assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
    assert img.std() > 10  # sky, floor, ball and net: not one flat colour
    orange = (img[..., 0] > 150) & (img[..., 2] < 110)  # the ball
    assert orange.sum() > 20


@needs_gl
def test_mp4_decodes_with_expected_frames_and_size(run, tmp_path):
    from interplay.outputs.render.video import render_video
    st = render_video(run, tmp_path / "preview.mp4", SIZE, fps=20)
    meta, frames = _read_mp4(tmp_path / "preview.mp4")
    expected = int(np.floor(run.duration * 20 + 1e-9)) + 1
    assert st["frames"] == expected == len(frames)
    assert tuple(meta["size"]) == SIZE and meta["fps"] == pytest.approx(20)
    assert frames[0].std() > 10
    assert parse_camera(st["camera"])  # the camera it used can be passed back in


@needs_gl
def test_side_by_side_video(run, tmp_path):
    from interplay.outputs.render.video import render_side_by_side
    st = render_side_by_side({"two-way": run, "one-way": run, "hybrid": run},
                             tmp_path / "compare.mp4", (480, 180), fps=10)
    meta, frames = _read_mp4(tmp_path / "compare.mp4")
    assert tuple(meta["size"]) == (480, 180) and len(frames) == st["frames"] == 5
    assert st["panels"] == ["two-way", "one-way", "hybrid"]


@needs_gl
def test_crash_while_rendering_leaves_no_video(run, tmp_path):
    from interplay.outputs.render.video import render_video

    def boom(done, total):
        if done == 2:
            raise RuntimeError("interrupted")
    with pytest.raises(RuntimeError):
        render_video(run, tmp_path / "preview.mp4", SIZE, progress=boom)
    assert list(tmp_path.iterdir()) == []


def test_odd_video_size_is_refused(run, tmp_path):
    from interplay.outputs.render.video import render_video
    with pytest.raises(ParameterError, match="even"):
        render_video(run, tmp_path / "p.mp4", (321, 180))


def test_missing_renderer_dependency_is_one_clear_error(run, tmp_path, monkeypatch):
    from interplay.outputs.render import gl
    monkeypatch.setattr(gl, "_CTX", None)
    monkeypatch.setitem(sys.modules, "moderngl", None)  # import moderngl -> ImportError
    with pytest.raises(InterplayError, match="needs moderngl.*--no-video"):
        gl.Renderer(run, SIZE)


def test_missing_encoder_is_one_clear_error(run, tmp_path, monkeypatch):
    from interplay.outputs.render.video import video_writer
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    with pytest.raises(InterplayError, match="needs imageio-ffmpeg"):
        with video_writer(tmp_path / "x.mp4", SIZE, 30):
            pass
    assert not (tmp_path / "x.mp4").exists()
