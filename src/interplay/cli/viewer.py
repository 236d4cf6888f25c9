"""`interplay view DIR`: a saved run in a web viewer on localhost (viser), with a time slider
and play/pause.

It reads scene.json (shapes) and tracks.npz (frames) from DIR, so any saved run redraws with
no scene-specific code: bodies as meshes moved per frame, cord networks as line segments,
deforming surfaces as meshes whose vertices change, particles as point clouds, static
systems as a grid.
"""
from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np

from ..errors import InterplayError


def _viser():
    try:
        import viser
    except ImportError:
        raise InterplayError("the web viewer needs viser: pip install 'interplay[viewer]' "
                             "(or pip install viser)") from None
    return viser


def _rgb(color, scale: float = 1.0) -> tuple:
    """RGB 0..1 -> bytes; viser lights the scene itself, so no gamma here."""
    return tuple(int(round(255 * min(max(c * scale, 0.0), 1.0))) for c in color)


def _finite(p) -> np.ndarray:
    """The present particles (absent ones are NaN rows); one far below if none, since an
    empty point cloud cannot be sent."""
    p = np.asarray(p, dtype=np.float32)
    p = p[np.isfinite(p).all(axis=1)]
    return p if len(p) else np.array([[0.0, 0.0, -1e3]], dtype=np.float32)


class Viewer:
    """A viser server showing one RunData; ``set_frame(i)`` moves everything to frame i."""

    def __init__(self, run, host: str = "127.0.0.1", port: int = 8080, log=print):
        viser = _viser()
        from ..outputs.render.camera import default_camera
        self.run, self.log = run, log
        self.times = run.times
        try:
            self.server = viser.ViserServer(host=host, port=port, verbose=False)
        except OSError as e:
            raise InterplayError(f"viewer: cannot listen on {host}:{port} ({e.strerror}); pass "
                                 "another --port") from None
        sc = self.server.scene
        sc.set_up_direction("+z")
        lo, hi = run.bounds()
        cam = default_camera(lo, hi, 16 / 9, fov_deg=50.0)
        self.server.initial_camera.position = tuple(float(x) for x in cam.eye)
        self.server.initial_camera.look_at = tuple(float(x) for x in cam.target)
        self.handles = []
        for shape in run.shapes:
            self._add(shape)
        self._gui()
        self.server.on_client_connect(self._connected)
        self.set_frame(0)

    @property
    def url(self) -> str:
        host = self.server.get_host()
        host = "localhost" if host in ("0.0.0.0", "::") else host  # listening everywhere
        return f"http://{host}:{self.server.get_port()}"

    def _connected(self, client):
        self.log(f"viewer: a browser connected (client {client.client_id})")

    def _add(self, shape):
        sc, name, color = self.server.scene, f"/{shape.name}", _rgb(shape.color)
        fr = self.run.frames.get(shape.name, {})
        if shape.form == "body":
            h = sc.add_mesh_simple(name, shape.verts.astype(np.float32),
                                   shape.tris.astype(np.uint32), color=color)
            self.handles.append(("pose", shape.name, h))
        elif shape.form == "parts":
            for k, (v, t) in enumerate(shape.parts):
                part = color if shape.part_colors is None else _rgb(shape.part_colors[k])
                h = sc.add_mesh_simple(f"{name}/{shape.part_names[k]}", v.astype(np.float32),
                                       t.astype(np.uint32), color=part)
                self.handles.append(("part", (shape.name, k), h))
        elif shape.form == "surface":
            h = sc.add_mesh_simple(name, fr["points"][0].astype(np.float32),
                                   shape.triangles.astype(np.uint32), color=color, side="double")
            self.handles.append(("vertices", shape.name, h))
        elif shape.form == "cords":
            # thin light cords vanish on viser's white background: draw them darker
            h = sc.add_line_segments(name, self._segments(shape, 0), _rgb(shape.color, 0.55),
                                     thickness=2.0, thickness_units="screen")
            self.handles.append(("segments", shape, h))
        elif shape.form == "particles":
            h = sc.add_point_cloud(name, _finite(fr["points"][0]), color,
                                   point_size=max(shape.width, 0.005), point_shape="circle")
            self.handles.append(("points", shape.name, h))
        elif shape.form == "static":
            lo, hi = shape.verts.min(0), shape.verts.max(0)
            if hi[2] - lo[2] < 1e-9:  # a horizontal plane: a grid reads better than a quad
                sc.add_grid(name, width=float(hi[0] - lo[0]), height=float(hi[1] - lo[1]),
                            plane="xy", position=((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2,
                                                  float(lo[2])))
            else:
                sc.add_mesh_simple(name, shape.verts.astype(np.float32),
                                   shape.tris.astype(np.uint32), color=color)
        if shape.anchors is not None:
            sc.add_point_cloud(f"{name}_anchors", shape.anchors.astype(np.float32), (30, 30, 30),
                               point_size=max(3 * shape.width, 0.01), point_shape="circle")

    def _segments(self, shape, i):
        p = self.run.frames[shape.name]["points"][i].astype(np.float32)
        return p[shape.segments]

    def _gui(self):
        gui, run = self.server.gui, self.run
        nf = len(self.times)
        gui.add_markdown(f"**{run.scene}** - {run.coupling}  \n{run.duration:g} s, "
                         f"{nf} frames at {run.fps:g} fps")
        self.slider = gui.add_slider("frame", min=0, max=max(nf - 1, 1), step=1, initial_value=0)
        self.clock = gui.add_number("time (s)", 0.0, step=0.001, disabled=True)
        self.playing = gui.add_checkbox("playing", True)
        self.speed = gui.add_slider("speed", min=0.05, max=2.0, step=0.05, initial_value=1.0)
        self.slider.on_update(lambda _: self.set_frame(int(self.slider.value)))

    def set_frame(self, i: int):
        i = int(np.clip(i, 0, len(self.times) - 1))
        frames = self.run.frames
        with self.server.atomic():
            for kind, key, h in self.handles:
                if kind == "pose":
                    pos, q = self.run.pose(key, i)
                    h.position, h.wxyz = tuple(map(float, pos)), tuple(map(float, q))
                elif kind == "part":
                    fr = frames[key[0]]
                    h.position = tuple(map(float, fr["segment_positions"][i, key[1]]))
                    h.wxyz = tuple(map(float, fr["segment_orientations"][i, key[1]]))
                elif kind == "vertices":
                    h.vertices = frames[key]["points"][i].astype(np.float32)
                elif kind == "segments":
                    h.points = self._segments(key, i)
                elif kind == "points":
                    h.points = _finite(frames[key]["points"][i])
            self.clock.value = round(float(self.times[i]), 4)

    def play(self, stop: threading.Event | None = None):
        """Advance the slider in real time (scaled by the speed slider) while playing."""
        stop = stop or threading.Event()
        nf = len(self.times)
        dt = 1.0 / self.run.fps
        while not stop.is_set():
            if self.playing.value and nf > 1:
                self.slider.value = (int(self.slider.value) + 1) % nf
            time.sleep(dt / max(float(self.speed.value), 1e-3))

    def stop(self):
        self.server.stop()


def serve(run_dir, host: str = "127.0.0.1", port: int = 8080, log=print):
    """Serve a saved run until interrupted (Ctrl-C); print its URL first."""
    from ..outputs.rundata import load_run
    run = load_run(Path(run_dir))
    viewer = Viewer(run, host, port, log=log)
    log(f"viewer: {run.scene} ({run.coupling}) at {viewer.url}  (Ctrl-C to stop)")
    try:
        viewer.play()
    except KeyboardInterrupt:
        pass
    finally:
        viewer.stop()
