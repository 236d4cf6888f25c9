"""Headless preview frames: moderngl on a standalone EGL context (Mesa llvmpipe on the CPU).

A ``Renderer`` is made for one run and one image size; ``render(run, t)`` returns an RGB
uint8 image (h, w, 3) of every system at time t (s): rigid bodies and static meshes with
smooth normals, deforming surfaces with per-frame normals, cord networks as instanced tubes
with a sphere at each knot, anchors as small dark hooks; a sun with soft shadows; 4x MSAA.
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import InterplayError
from . import shaders
from .camera import Camera, default_camera

SKY = np.array([0.62, 0.70, 0.80])  # linear RGB
SUN = np.array([-0.45, 0.30, 1.0]) / np.linalg.norm([-0.45, 0.30, 1.0])  # towards the sun
HOOK_COLOR = (0.12, 0.12, 0.13)
PENUMBRA = 0.02  # m, width of the soft shadow edge
GL_HINT = ("install the Mesa EGL driver (`make` does it, or apt-get install -y libegl1 "
           "libegl-mesa0 libgl1-mesa-dri) or skip the video with --no-video")

_CTX = None


def gl_context():
    """The process's headless OpenGL 3.3 context (created once: it takes ~0.4 s)."""
    global _CTX
    if _CTX is None:
        try:
            import moderngl
        except ImportError:
            raise InterplayError("preview rendering needs moderngl: pip install "
                                 "'moderngl>=5.10', or skip the video with --no-video") from None
        try:
            _CTX = moderngl.create_context(standalone=True, backend="egl", require=330)
        except Exception as e:  # moderngl raises bare Exception when EGL is missing
            raise InterplayError(f"preview rendering cannot open a headless OpenGL context "
                                 f"({str(e).splitlines()[0] if str(e) else type(e).__name__}); "
                                 f"{GL_HINT}") from None
    return _CTX


def fast_normals(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals (n,3), float32 (bincount: no Python loop)."""
    p = np.asarray(points, dtype=np.float64)
    fn = np.cross(p[tris[:, 1]] - p[tris[:, 0]], p[tris[:, 2]] - p[tris[:, 0]])
    idx = tris.reshape(-1)
    n = np.stack([np.bincount(idx, np.repeat(fn[:, k], 3), minlength=len(p))
                  for k in range(3)], axis=1)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return (n / np.where(length > 0, length, 1.0)).astype(np.float32)


def quat_matrix4(pos, q) -> np.ndarray:
    w, x, y, z = q
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                 [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                 [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = pos
    return m


def ground_shape(lo, hi):
    """A floor quad (a static Shape) just under the box [lo, hi], 20 m or 10 box sizes wide."""
    from ...systems.shape import Shape
    c = (np.asarray(lo) + np.asarray(hi)) / 2
    s = max(10.0, 5 * float(np.max(np.asarray(hi) - np.asarray(lo))))
    z = float(lo[2]) - 1e-3
    v = np.array([[c[0] - s, c[1] - s, z], [c[0] + s, c[1] - s, z], [c[0] + s, c[1] + s, z],
                  [c[0] - s, c[1] + s, z]])
    return Shape("ground", "static", (0.55, 0.55, 0.57), verts=v, tris=np.array([[0, 1, 2],
                                                                               [0, 2, 3]]))


def _unit_cylinder(sides=6):
    a = 2 * np.pi * np.arange(sides) / sides
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(sides)], axis=1)
    pos = np.concatenate([ring, ring + [0, 0, 1]])
    nrm = np.concatenate([ring, ring])
    i = np.arange(sides)
    j = (i + 1) % sides
    tris = np.concatenate([np.stack([i, j, j + sides], 1), np.stack([i, j + sides, i + sides], 1)])
    return pos, nrm, tris


def _unit_sphere(sub=1):
    from ...geometry.sphere import icosphere
    v, t = icosphere(sub)
    return v, v, t


def _gl_matrix(m: np.ndarray) -> bytes:
    return np.ascontiguousarray(m.T, dtype=np.float32).tobytes()  # GL wants column-major


class Renderer:
    """Draws one run's systems at any time. size: (width, height) pixels; camera: a Camera or
    None for a default that frames every animated system over the whole run."""

    def __init__(self, run, size=(1280, 720), camera: Camera | None = None, samples: int = 4,
                 shadow_size: int = 512):
        self.ctx = ctx = gl_context()
        self.w, self.h = int(size[0]), int(size[1])
        lo, hi = run.bounds()
        self.camera = camera or default_camera(lo, hi, self.w / self.h)
        self._released = False
        samples = min(samples, ctx.max_samples)
        self.fbo = ctx.framebuffer(ctx.renderbuffer((self.w, self.h), 4, samples=samples),
                                   ctx.depth_renderbuffer((self.w, self.h), samples=samples))
        self.resolve = ctx.framebuffer(ctx.renderbuffer((self.w, self.h), 4))
        self.shadow_size = int(shadow_size)
        self.shadow_tex = ctx.depth_texture((shadow_size, shadow_size))
        self.shadow_tex.compare_func = "<="
        self.shadow_tex.repeat_x = self.shadow_tex.repeat_y = False
        self.shadow_fbo = ctx.framebuffer(depth_attachment=self.shadow_tex)
        self.progs = {k: ctx.program(vertex_shader=vs, fragment_shader=shaders.LIT_FS)
                      for k, vs in (("mesh", shaders.MESH_VS), ("tube", shaders.TUBE_VS),
                                    ("ball", shaders.BALL_VS))}
        self.depth = {k: ctx.program(vertex_shader=vs, fragment_shader=shaders.DEPTH_FS)
                      for k, vs in (("mesh", shaders.MESH_VS), ("tube", shaders.TUBE_VS),
                                    ("ball", shaders.BALL_VS))}
        # a scene without a floor still gets one under its lowest point, for scale and shadows
        self.shapes = list(run.shapes)
        if not any(s.form == "static" for s in self.shapes):
            self.shapes.append(ground_shape(lo, hi))
        self._setup_matrices(run, lo, hi)
        self._objects = []
        self._resources = [self.fbo, self.resolve, self.shadow_tex, self.shadow_fbo,
                           *self.progs.values(), *self.depth.values()]
        # cords and knots are a few pixels wide: six-sided tubes and icosahedra look round
        # there and keep the vertex work small (llvmpipe); hooks and particles get more
        cyl, self._knot_sphere, sph = _unit_cylinder(), _unit_sphere(0), _unit_sphere(1)
        for shape in self.shapes:
            self._add(shape, run, cyl, sph)

    # --- setup -----------------------------------------------------------------------------
    def _setup_matrices(self, run, lo, hi):
        cam = self.camera
        centre = (lo + hi) / 2
        radius = max(float(np.linalg.norm(hi - lo)) / 2, 0.3)
        dist = float(np.linalg.norm(np.subtract(cam.eye, centre)))
        near = max(0.02, (dist - radius) * 0.2)
        far = dist + radius + 60.0
        self.vp = cam.projection(self.w / self.h, near, far) @ cam.view()
        static = [s.verts[:, 2].min() for s in self.shapes if s.form == "static"]
        self.ground_z = float(min(static)) if static else float(lo[2])
        self.uniforms = {"u_eye": tuple(map(float, cam.eye)), "u_light_dir": tuple(SUN),
                         "u_sky": tuple(SKY),
                         "u_fog": (dist + radius * 2, dist + radius * 2 + 25.0)}

    def _fit_sun(self, lo, hi):
        """The sun's orthographic view for this frame, fitted to the casters' box [lo, hi]
        (m) and deep enough to reach the ground: the shadow map's texels go where shadows
        fall, and only the pixels near a shadow pay for the soft filter."""
        centre = (lo + hi) / 2
        r = max(float(np.linalg.norm(hi - lo)) / 2, 0.05) * 1.05
        eye = centre + SUN * 2 * r
        depth = 3 * r + max(centre[2] - self.ground_z, 0.0) / SUN[2]
        ortho = np.diag([1 / r, 1 / r, -2.0 / depth, 1.0])
        ortho[2, 3] = -1.0  # view depth 0..depth -> -1..1
        self.light_vp = ortho @ Camera(tuple(eye), tuple(centre)).view()
        self.uniforms.update({"u_light_vp": self.light_vp,
                              # a penumbra of ~2.5 cm, in shadow-map uv units
                              "u_spread": PENUMBRA / (2 * r),
                              # ~4 mm of depth and 1.5 texels of normal offset
                              "u_bias": 0.004 / depth,
                              "u_offset": 1.5 * 2 * r / self.shadow_size})

    def _buffer(self, data, dynamic=False):
        buf = self.ctx.buffer(np.ascontiguousarray(data, dtype=np.float32).tobytes(),
                              dynamic=dynamic)
        self._resources.append(buf)
        return buf

    def _vaos(self, kind, vbo, ibo, inst=None, inst_fmt=None, inst_attrs=()):
        """The vertex arrays of one object for the lit and the shadow program."""
        out = []
        content = [(vbo, "3f 3f", "in_pos", "in_normal")]
        if inst is not None:
            content.append((inst, inst_fmt, *inst_attrs))
        for prog in (self.progs[kind], self.depth[kind]):
            # skip_errors: the shadow programs have no in_normal (the compiler drops it)
            vao = self.ctx.vertex_array(prog, content, index_buffer=ibo, index_element_size=4,
                                        skip_errors=True)
            self._resources.append(vao)
            out.append(vao)
        return out

    def _static_geometry(self, pos, nrm, tris):
        vbo = self._buffer(np.concatenate([pos, nrm], axis=1))
        ibo = self.ctx.buffer(np.ascontiguousarray(tris, dtype=np.int32).tobytes())
        self._resources.append(ibo)
        return vbo, ibo

    def _add(self, shape, run, cyl, sph):
        color = tuple(float(c) for c in shape.color)
        if shape.form in ("body", "static"):
            vbo, ibo = self._static_geometry(shape.verts, fast_normals(shape.verts, shape.tris),
                                             shape.tris)
            vao, dvao = self._vaos("mesh", vbo, ibo)
            self._objects.append({"shape": shape, "kind": "mesh", "vao": vao, "dvao": dvao,
                                  "color": color, "checker": shape.form == "static",
                                  "casts": shape.form == "body",
                                  "extent": float(np.linalg.norm(shape.verts, axis=1).max())})
        elif shape.form == "parts":
            for k, (v, t) in enumerate(shape.parts):
                vbo, ibo = self._static_geometry(v, fast_normals(v, t), t)
                vao, dvao = self._vaos("mesh", vbo, ibo)
                self._objects.append({"shape": shape, "kind": "mesh", "part": k, "vao": vao,
                                      "dvao": dvao, "color": color, "casts": True,
                                      "extent": float(np.linalg.norm(v, axis=1).max())})
        elif shape.form == "surface":
            n = len(run.frames[shape.name]["points"][0])
            vbo = self._buffer(np.zeros((n, 6)), dynamic=True)
            ibo = self.ctx.buffer(np.ascontiguousarray(shape.triangles, np.int32).tobytes())
            self._resources.append(ibo)
            vao, dvao = self._vaos("mesh", vbo, ibo)
            # a water surface (a height field) lets the light through to its bed
            self._objects.append({"shape": shape, "kind": "surface", "vao": vao, "dvao": dvao,
                                  "vbo": vbo, "color": color, "casts": shape.grid_xy is None})
        elif shape.form == "cords":
            r = shape.width / 2
            vbo, ibo = self._static_geometry(*cyl)
            inst = self._buffer(np.zeros((len(shape.segments), 6)), dynamic=True)
            vao, dvao = self._vaos("tube", vbo, ibo, inst, "3f 3f/i", ("in_a", "in_b"))
            self._objects.append({"shape": shape, "kind": "cords", "vao": vao, "dvao": dvao,
                                  "inst": inst, "color": color, "radius": r, "casts": True,
                                  "count": len(shape.segments)})
            self._knots(shape, run, self._knot_sphere, color, r)
        elif shape.form == "particles":
            self._knots(shape, run, sph, color, max(shape.width / 2, 1e-3))
        if shape.anchors is not None:
            vbo, ibo = self._static_geometry(*sph)
            inst = self._buffer(shape.anchors)
            vao, dvao = self._vaos("ball", vbo, ibo, inst, "3f/i", ("in_center",))
            r = max(shape.width, 0.004) * 1.5
            self._objects.append({"shape": None, "kind": "hooks", "vao": vao, "dvao": dvao,
                                  "color": HOOK_COLOR, "radius": r, "casts": True,
                                  "anchors": shape.anchors,
                                  "count": len(shape.anchors)})

    def _knots(self, shape, run, sph, color, radius):
        n = len(run.frames[shape.name]["points"][0])
        vbo, ibo = self._static_geometry(*sph)
        inst = self._buffer(np.zeros((n, 3)), dynamic=True)
        vao, dvao = self._vaos("ball", vbo, ibo, inst, "3f/i", ("in_center",))
        self._objects.append({"shape": shape, "kind": "knots", "vao": vao, "dvao": dvao,
                              "inst": inst, "color": color, "radius": radius, "casts": True,
                              "count": n})

    # --- per frame -------------------------------------------------------------------------
    def _update(self, run, t):
        """Write this frame's states into the GL buffers; fit the sun to the casters."""
        states, boxes = {}, []
        for ob in self._objects:
            shape = ob["shape"]
            if shape is None or not shape.animated:
                continue
            if shape.name not in states:
                states[shape.name] = run.sample(shape.name, t)
            st = states[shape.name]
            if ob["kind"] == "mesh":
                k = ob.get("part")
                pos = st["position"] if k is None else st["segment_positions"][k]
                ob["model"] = quat_matrix4(pos, st["orientation"] if k is None
                                           else st["segment_orientations"][k])
                r = ob["extent"]
                boxes += [pos - r, pos + r]
            elif ob["kind"] == "surface":
                p = st["points"]
                ob["vbo"].write(np.concatenate([p.astype(np.float32),
                                                fast_normals(p, shape.triangles)], 1).tobytes())
            elif ob["kind"] == "cords":
                p = st["points"].astype(np.float32)
                seg = shape.segments
                ob["inst"].write(np.concatenate([p[seg[:, 0]], p[seg[:, 1]]], 1).tobytes())
            elif ob["kind"] == "knots":
                p = st["points"]
                p = p[np.isfinite(p).all(axis=1)]  # absent particles (spray) are NaN rows
                ob["count"] = len(p)
                if len(p):
                    ob["inst"].write(p.astype(np.float32).tobytes())
            p = st.get("points")
            if p is not None and np.isfinite(p).any():
                boxes += [np.nanmin(p, 0), np.nanmax(p, 0)]
        for ob in self._objects:
            if ob["kind"] == "hooks":
                boxes += [ob["anchors"].min(0), ob["anchors"].max(0)]
        if boxes:
            boxes = np.array(boxes)
            self._fit_sun(boxes.min(0), boxes.max(0))
        else:
            self._fit_sun(*run.bounds())

    def _draw(self, depth_pass: bool):
        vp = self.light_vp if depth_pass else self.vp
        for ob in self._objects:
            if depth_pass and not ob["casts"]:
                continue
            vao = ob["dvao"] if depth_pass else ob["vao"]
            prog = vao.program
            _set(prog, "u_vp", vp)
            if not depth_pass:
                for k, v in self.uniforms.items():
                    _set(prog, k, v)
                _set(prog, "u_color", ob["color"])
                _set(prog, "u_checker", 1 if ob.get("checker") else 0)
                _set(prog, "u_shadow", 0)
            if ob["kind"] in ("mesh", "surface"):
                _set(prog, "u_model", ob.get("model", np.eye(4)))
                vao.render()
            elif ob["count"]:
                _set(prog, "u_radius", ob["radius"])
                vao.render(instances=ob["count"])

    def render(self, run, t: float) -> np.ndarray:
        """RGB image (h, w, 3) uint8 of the run at time t (s)."""
        import moderngl
        ctx = self.ctx
        self._update(run, t)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE)
        self.shadow_fbo.use()
        self.shadow_fbo.clear(depth=1.0)
        # front faces would shadow themselves; offsetting depth keeps surfaces clean
        ctx.polygon_offset = (2.0, 4.0)
        self._draw(depth_pass=True)
        ctx.polygon_offset = (0.0, 0.0)
        self.fbo.use()
        sky = np.power(SKY, 1 / 2.2)
        self.fbo.clear(*sky, 1.0, depth=1.0)
        self.shadow_tex.use(location=0)
        self._draw(depth_pass=False)
        ctx.copy_framebuffer(self.resolve, self.fbo)
        img = np.frombuffer(self.resolve.read(components=3, alignment=1), dtype=np.uint8)
        return img.reshape(self.h, self.w, 3)[::-1].copy()  # GL rows run bottom-up

    def release(self):
        """Free the GL objects (the context stays for the next renderer)."""
        if not self._released:
            for r in reversed(self._resources):
                r.release()
            self._released = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()


def _set(prog, name, value):
    if name not in prog:
        return
    if isinstance(value, np.ndarray) and value.shape == (4, 4):
        prog[name].write(_gl_matrix(value))
    else:
        prog[name].value = value


def frame_times(duration: float, fps: float) -> np.ndarray:
    """Sample times (s) of a video at fps covering 0..duration."""
    n = int(math.floor(duration * fps + 1e-9)) + 1
    return np.arange(n) / fps
