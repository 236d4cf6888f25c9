"""Preview videos: H.264 MP4 through imageio-ffmpeg's bundled ffmpeg.

Video frames are sampled by time (default 24 frames/s, whatever the run's output rate):
between the run's frames, states are interpolated (``RunData.sample``).
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ...errors import InterplayError, ParameterError
from ...io.atomic import atomic_path
from .camera import default_camera
from .gl import Renderer, frame_times
from .overlay import draw_label


def _ffmpeg():
    try:
        import imageio_ffmpeg
    except ImportError:
        raise InterplayError("preview video needs imageio-ffmpeg: pip install "
                             "'imageio-ffmpeg>=0.5', or skip the video with --no-video") from None
    return imageio_ffmpeg


def check_size(size) -> tuple[int, int]:
    """(width, height) in pixels, both even (H.264 with 4:2:0 chroma needs even sides)."""
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ParameterError(f"video size {size!r}: expected (width, height) in pixels") from None
    if w < 16 or h < 16 or w > 7680 or h > 4320 or w % 2 or h % 2:
        raise ParameterError(f"video size {w}x{h}: width and height must be even, from 16 to "
                             "7680x4320 pixels, e.g. 1280x720")
    return w, h


@contextmanager
def video_writer(path, size, fps: float, timer: dict | None = None):
    """Yield ``write(frame)`` for RGB uint8 frames (h, w, 3); the MP4 appears at ``path``
    only when the block completes (a crash leaves no file). timer["encode_s"] accumulates
    the wall time spent handing frames to ffmpeg and finishing the file."""
    ff = _ffmpeg()
    w, h = check_size(size)
    timer = timer if timer is not None else {}
    timer.setdefault("encode_s", 0.0)
    with atomic_path(path) as tmp:
        gen = ff.write_frames(str(tmp), (w, h), fps=fps, codec="libx264", quality=None,
                              pix_fmt_out="yuv420p", macro_block_size=1,
                              ffmpeg_log_level="error",
                              # the temp name has no .mp4: name the container; faststart puts
                              # the index first so browsers play while loading
                              output_params=["-f", "mp4", "-movflags", "+faststart",
                                             "-crf", "20", "-preset", "fast"])
        gen.send(None)
        done = False

        def write(frame):
            t0 = time.perf_counter()
            gen.send(np.ascontiguousarray(frame, dtype=np.uint8))
            timer["encode_s"] += time.perf_counter() - t0

        try:
            yield write
            done = True
        finally:
            t0 = time.perf_counter()
            try:
                gen.close()
            except Exception:
                if done:
                    raise InterplayError(f"ffmpeg failed to finish {path}") from None
            timer["encode_s"] += time.perf_counter() - t0


def _label(run, t, title=None):
    return [title or f"{run.scene} - {run.coupling}", f"t = {t:.3f} s"]


def render_video(run, path, size=(960, 540), fps: float = 24.0, camera=None,
                 progress=None) -> dict:
    """Render the run to an MP4 at ``path``. Returns {"path", "frames", "size", "fps",
    "camera", "render_s", "encode_s"} (wall times in s). progress: callable(done, total)."""
    w, h = check_size(size)
    times = frame_times(run.duration, fps)
    timer = {"render_s": 0.0, "encode_s": 0.0}
    with Renderer(run, (w, h), camera) as r, video_writer(path, (w, h), fps, timer) as write:
        for k, t in enumerate(times):
            t0 = time.perf_counter()
            img = draw_label(r.render(run, t), _label(run, t))
            timer["render_s"] += time.perf_counter() - t0
            write(img)
            if progress is not None:
                progress(k + 1, len(times))
        cam = r.camera
    return {"path": Path(path), "frames": len(times), "size": [w, h], "fps": fps,
            "camera": cam.spec(), **timer}


def render_side_by_side(runs: dict, path, size=(960, 540), fps: float = 24.0, camera=None,
                        progress=None) -> dict:
    """One MP4 with a panel per run, left to right (the paper's Figure 2 as a movie).

    runs: {label: RunData}, e.g. the three coupling modes; every panel uses the same camera
    (the default frames all runs together) and shows its label and the time.
    """
    w, h = check_size(size)
    labels = list(runs)
    if not labels:
        raise ParameterError("side-by-side video: no runs given")
    n = len(labels)
    widths = [w // n + (1 if i < w % n else 0) for i in range(n)]
    duration = max(r.duration for r in runs.values())
    if camera is None:
        boxes = np.array([b for r in runs.values() for b in r.bounds()])
        camera = default_camera(boxes.min(0), boxes.max(0), min(widths) / h)
    times = frame_times(duration, fps)
    timer = {"render_s": 0.0, "encode_s": 0.0}
    renderers = []
    try:
        for lab, pw in zip(labels, widths):
            renderers.append(Renderer(runs[lab], (pw, h), camera))
        with video_writer(path, (w, h), fps, timer) as write:
            for k, t in enumerate(times):
                t0 = time.perf_counter()
                panels = []
                for lab, r in zip(labels, renderers):
                    run = runs[lab]
                    img = r.render(run, min(t, run.duration))
                    panels.append(draw_label(img, [lab, f"t = {t:.3f} s"], scale=1.2))
                frame = np.concatenate(panels, axis=1)
                frame[:, np.cumsum(widths)[:-1]] = 40  # a thin dark line between panels
                timer["render_s"] += time.perf_counter() - t0
                write(frame)
                if progress is not None:
                    progress(k + 1, len(times))
    finally:
        for r in renderers:
            r.release()
    return {"path": Path(path), "frames": len(times), "size": [w, h], "fps": fps,
            "camera": camera.spec(), "panels": labels, **timer}
