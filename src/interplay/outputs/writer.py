"""Every output of a run, from the generic Result with no scene-specific code.

``write_outputs(result, out_dir)`` writes, into out_dir:
  summary.json, tracks.npz   (Result.save)
  scene.json                 shapes for redrawing (the web viewer reads it)
  run.usdc | run.usda        the USD stage
  obj/                       OBJ sequences (opt-in: OutputOptions.obj, --obj)
  preview.mp4                the preview video
  report.html + plot_*.png   the run report
``write_compare_outputs`` adds, above the per-mode folders of ``interplay compare``, the
side-by-side video compare.mp4 and the compare report.html.
"""
from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InterplayError
from .render.camera import Camera


@dataclass(frozen=True)
class OutputOptions:
    """What to write. size: video (width, height) px; video_fps: frames/s of the videos
    (sampled by time from the run's frames); camera: None frames every system."""
    usd: bool = True
    usd_format: str = "usdc"
    obj: bool = False  # OBJ sequences are opt-in (--obj): a file per frame per system
    video: bool = True
    report: bool = True
    size: tuple = (960, 540)  # px: a preview that renders beside the other outputs
    video_fps: float = 24.0  # frames/s: animation's rate
    camera: Camera | None = None
    quiet: bool = False
    timings: dict = field(default_factory=dict, compare=False)


def ensure_writable(out_dir) -> Path:
    """Create out_dir if needed and check a file can be written there, before any long work.
    Raises InterplayError naming the directory and the fix."""
    d = Path(out_dir)
    try:
        d.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test.", dir=d)
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise InterplayError(f"cannot write to output directory {d}: {e.strerror or e}; choose "
                             "another --out directory") from None
    return d


def preflight(out_dir, options: OutputOptions) -> Path:
    """Fail fast, before simulating: the output directory must be writable and every
    requested output's dependencies importable (and a headless GL context available for the
    video). Each failure is one InterplayError naming the fix."""
    d = ensure_writable(out_dir)
    worker = None
    if options.video:
        # first, before any thread or GL context: the renderer's own process checks GL
        from .render import worker as render_worker
        worker = render_worker.start()
    if options.usd:
        from .usd import _pxr
        _pxr()
    if options.video:
        if worker is not None:
            worker.ready()
        else:
            from .render.gl import gl_context
            from .render.video import _ffmpeg
            gl_context()
            _ffmpeg()
    if options.report:
        from .render.plots import _figure
        _figure(1, 1)
    return d


class StepBar:
    """progress(done, total) for rendering and export: a rich bar that appears only when the
    task has run for more than a second (short tasks stay silent)."""

    def __init__(self, label: str, quiet: bool = False, after_s: float = 1.0):
        self.label, self.quiet, self.after_s = label, quiet, after_s
        self._t0 = time.perf_counter()
        self._bar = self._task = None

    def __call__(self, done: int, total: int):
        if self.quiet:
            return
        if self._bar is None and done < total and time.perf_counter() - self._t0 > self.after_s:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn
            from rich.progress import TimeRemainingColumn
            self._bar = Progress(TextColumn(self.label), BarColumn(), MofNCompleteColumn(),
                                 TimeRemainingColumn())
            self._bar.start()
            self._task = self._bar.add_task(self.label, total=total)
        if self._bar is not None:
            self._bar.update(self._task, completed=done)
            if done >= total:
                self._bar.stop()
                self._bar = None


def _timed(timings, key, fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    timings[key] = time.perf_counter() - t0
    return out


def write_outputs(result, out_dir, options: OutputOptions = OutputOptions(),
                  summary: dict | None = None, run_id: str | None = None,
                  request: dict | None = None, locked: bool = False) -> list[Path]:
    """Write every output of one run into out_dir as one unit (outputs/runfolder.py: staged,
    then published under a manifest with the run id); return the final paths, in order.

    summary: the dict to save as summary.json (default ``result.summary()``). Wall times of
    each output land in ``options.timings`` (s): save_s (summary, tracks, scene.json), usd_s,
    obj_s, plots_s, video_render_s and video_encode_s (inside the renderer), video_wait_s
    (how long the rest waited for a preview rendering in its own process), report_s.
    The preview renders in the process ``preflight`` started, while the USD, OBJ and plots
    are written here. run_id: the run's id (a new one by default); request: what was asked
    for, kept in the manifest; locked: the caller holds out_dir's runfolder.Lock.
    """
    from contextlib import nullcontext

    from . import runfolder
    final = ensure_writable(out_dir)
    run_id = run_id or runfolder.new_run_id()
    with nullcontext() if locked else runfolder.Lock(final):
        if not locked:
            runfolder.claim(final)
        staging = final / f".staging-{run_id}"
        staging.mkdir(exist_ok=True)
        paths = _write_all(result, staging, options, summary, run_id)
        runfolder.publish(final, staging, run_id, request)
    return [final / p.relative_to(staging) for p in paths]


def _write_all(result, out, options, summary, run_id) -> list[Path]:
    from .rundata import from_result, write_scene_file
    summary = dict(summary if summary is not None else result.summary(), run_id=run_id)
    run = from_result(result)
    tm = options.timings
    t0 = time.perf_counter()
    paths = list(result.save(out, summary, run_id))
    files = {"summary (JSON)": paths[0], "tracks (NumPy npz)": paths[1]}
    paths.append(write_scene_file(run, out, run_id))
    tm["save_s"] = time.perf_counter() - t0
    files["shapes for the viewer"] = paths[-1]
    video = st = None
    from .render import worker as render_worker
    worker = render_worker.current() if options.video else None
    if worker is not None:  # the preview renders in its own process while the rest is written
        worker.submit({run.scene: out}, out / "preview.mp4", options.size, options.video_fps,
                      options.camera)
    if options.usd:
        from .usd import write_usd
        p = _timed(tm, "usd_s", write_usd, run, out / f"run.{options.usd_format}",
                   options.usd_format)
        paths.append(p)
        files["USD stage"] = p
    if options.obj:
        from .obj import write_obj_sequence
        _timed(tm, "obj_s", write_obj_sequence, run, out / "obj",
               StepBar("OBJ sequence", options.quiet))
        paths.append(out / "obj")
        files["OBJ sequences (one file per frame)"] = out / "obj"
    plots = None
    if options.report:
        from .report import force_plots
        plots = _timed(tm, "plots_s", force_plots, result, out, summary)
    if options.video:
        bar = StepBar("rendering preview.mp4", options.quiet)
        t0 = time.perf_counter()
        if worker is not None:
            st = worker.result(bar)
            tm["video_wait_s"] = time.perf_counter() - t0
        else:
            from .render.video import render_video
            st = render_video(run, out / "preview.mp4", options.size, options.video_fps,
                              options.camera, bar)
        tm.update({"video_render_s": st["render_s"], "video_encode_s": st["encode_s"],
                   "video_frames": st["frames"]})
        video = Path(st["path"])
        paths.append(video)
        files["preview video (H.264)"] = video
    if options.report:
        from .report import write_run_report
        shown = {k: v for k, v in tm.items() if k.endswith("_s")}
        written = _timed(tm, "report_s", write_run_report, result, out, summary, files, video,
                         shown, st, plots)
        paths += written  # the plots, then report.html
    return paths


def write_compare_outputs(results: dict, out_dir, rows: dict, advice: dict,
                          options: OutputOptions = OutputOptions(),
                          mode_dirs: dict | None = None) -> list[Path]:
    """The compare level: compare.mp4 (the modes side by side) and report.html linking each
    mode's own report. results: {mode: Result}; rows: {mode: cli.text.mode_row}."""
    from .rundata import from_result
    out = ensure_writable(out_dir)
    runs = {m: from_result(r) for m, r in results.items()}
    paths = []
    video = st = None
    mode_dirs = mode_dirs or {m: out / m for m in results}
    if options.video:
        from .render import worker as render_worker
        from .render.video import render_side_by_side
        bar = StepBar("rendering compare.mp4", options.quiet)
        worker = render_worker.current()
        if worker is not None and all((d / "tracks.npz").is_file() for d in mode_dirs.values()):
            worker.submit(mode_dirs, out / "compare.mp4", options.size, options.video_fps,
                          options.camera, panels=True)
            st = worker.result(bar)
        else:
            st = render_side_by_side(runs, out / "compare.mp4", options.size, options.video_fps,
                                     options.camera, bar)
        video = Path(st["path"])
        options.timings.update({"compare_render_s": st["render_s"],
                                "compare_encode_s": st["encode_s"]})
        paths.append(video)
    if options.report:
        from .report import write_compare_report
        reports = {m: d / "report.html" for m, d in mode_dirs.items()
                   if (d / "report.html").exists()}
        files = {"compare.json": out / "compare.json"} if (out / "compare.json").exists() else {}
        it = next(iter(results.values())).main_interaction
        pair = (it["primary"], it["secondary"]) if it is not None else None
        written = write_compare_report(runs, out, rows, advice, video, reports, files, pair,
                                       st)
        paths += written
    return paths
