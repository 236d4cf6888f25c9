"""The preview renderer in a process of its own, so the video renders while the parent writes
the USD stage, the OBJ files and the report (two cores: the outputs cost the longest of them,
not their sum).

``start()`` forks the worker before anything else has started threads or a GL context (the
command line calls it first thing, from ``writer.preflight``): the child opens its own
headless GL context at once, which is the check that video can be made, and then waits. A job
names saved run directories (the child reads them with ``load_run``: nothing large crosses
the pipe) and the video to write; the child answers with progress and the renderer's timings,
or the one-line error. Where a process cannot fork, or already holds a GL context (a fork
would inherit it), ``start()`` returns None and the writer renders in its own process.
"""
from __future__ import annotations

import multiprocessing
import os

from ...errors import InterplayError

_WORKER = None


def _serve(conn):
    import signal
    from . import gl
    from .video import _ffmpeg
    # the parent's SIGTERM handler (cli/command.py) raises in the parent; the parent ends
    # this daemon with SIGTERM when it exits, which here must just end it, without a traceback
    # under the parent's one-line error
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        gl._CTX = None  # never the parent's: it had none when this process was forked
        gl.gl_context()
        _ffmpeg()
    except InterplayError as e:
        conn.send(("error", str(e)))
        return
    conn.send(("ready", None))
    while True:
        try:
            job = conn.recv()
        except EOFError:
            return
        if job is None:
            return
        try:
            conn.send(("done", _render(job, lambda k, n: conn.send(("progress", (k, n))))))
        except InterplayError as e:
            conn.send(("error", str(e)))
        except Exception as e:  # a crash in the child must reach the parent as one line
            conn.send(("error", f"preview rendering failed: {type(e).__name__}: {e}"))


def _render(job: dict, progress) -> dict:
    from ..rundata import load_run
    from .video import render_side_by_side, render_video
    runs = {label: load_run(d) for label, d in job["dirs"].items()}
    args = (job["path"], job["size"], job["fps"], job["camera"], progress)
    if len(runs) == 1 and not job.get("panels"):
        st = render_video(next(iter(runs.values())), *args)
    else:
        st = render_side_by_side(runs, *args)
    st["path"] = str(st["path"])
    return st


class RenderWorker:
    """A forked preview renderer: ``ready()`` waits for its GL check, ``submit(job)`` hands
    it a video and ``result(progress)`` waits for it (raising its error)."""

    def __init__(self):
        ctx = multiprocessing.get_context("fork")
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_serve, args=(child,), daemon=True,
                                name="interplay-preview")
        self.proc.start()
        child.close()
        self._ready = None

    def _recv(self):
        try:
            return self.conn.recv()
        except EOFError:
            raise InterplayError("the preview renderer stopped unexpectedly; run again, or "
                                 "skip the video with --no-video") from None

    def ready(self):
        """Wait for the worker's GL context; InterplayError (one line) if it has none."""
        if self._ready is None:
            kind, msg = self._recv()
            self._ready = msg if kind == "error" else True
        if self._ready is not True:
            raise InterplayError(self._ready)

    def submit(self, dirs: dict, path, size, fps: float, camera=None, panels: bool = False):
        """Render the runs saved in dirs ({label: run directory}) to the MP4 at path: one run
        as a preview, several side by side (panels=True for one labelled panel)."""
        self.ready()
        self.conn.send({"dirs": {k: str(v) for k, v in dirs.items()}, "path": str(path),
                        "size": tuple(size), "fps": float(fps), "camera": camera,
                        "panels": panels})

    def result(self, progress=None) -> dict:
        """The submitted video's renderer statistics (render_video's dict)."""
        while True:
            kind, msg = self._recv()
            if kind == "progress":
                if progress is not None:
                    progress(*msg)
            elif kind == "error":
                raise InterplayError(msg)
            else:
                return msg

    def close(self):
        try:
            self.conn.send(None)
        except (OSError, BrokenPipeError):
            pass
        self.proc.join(timeout=5)
        if self.proc.is_alive():
            self.proc.terminate()


def start():
    """The process's worker, forked now if it has none; None where forking is not safe (no
    fork on this platform, or a GL context already open here)."""
    global _WORKER
    from . import gl
    if _WORKER is not None and _WORKER.proc.is_alive():
        return _WORKER
    if gl._CTX is not None or "fork" not in multiprocessing.get_all_start_methods() \
            or os.environ.get("INTERPLAY_RENDER_INLINE"):
        return None
    _WORKER = RenderWorker()
    return _WORKER


def current():
    """The running worker, or None."""
    return _WORKER if _WORKER is not None and _WORKER.proc.is_alive() else None
