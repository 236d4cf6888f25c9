"""Headless preview frames: moderngl on a standalone EGL context (Mesa llvmpipe on the CPU).

A ``Renderer`` is made for one run and one image size; ``render(run, t)`` returns an RGB
uint8 image (h, w, 3) of every system at time t (s): rigid bodies, figures and static set
pieces with smooth normals; deforming surfaces with per-frame normals (water translucent over
its bed, only where the columns hold water); cord networks as instanced tubes at their real
radius with a sphere at each knot (welded joints); spray as bright droplets at their radius;
anchors as small dark hooks; a sun with soft shadows; 4x MSAA. Only what a scene has is drawn:
a floor where it has one, at its height, ending softly into the sky; otherwise a backdrop.
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import InterplayError
from ...systems.shape import MATERIALS
from ..geometry import coarser_height_field, vertex_normals, wet_surface
from . import shaders
from .camera import Camera, TrackingCamera, cameras, default_camera

ZENITH = np.array([0.30, 0.45, 0.72])   # linear RGB of the sky overhead
HORIZON = np.array([0.78, 0.82, 0.86])  # ... and at the horizon
HAZE = np.array([0.66, 0.69, 0.72])     # below the horizon: the backdrop fog fades into
SUN = np.array([0.30, -0.50, 1.0]) / np.linalg.norm([0.30, -0.50, 1.0])  # towards the sun
HOOK_COLOR = (0.12, 0.12, 0.13)
THIN = 0.45  # share of the sun a sunlit cloth or leaf shows on its shaded side
WATER_POINTS = 9000  # columns above which the preview draws a height field at every 2nd one
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


def quat_matrix4(pos, q) -> np.ndarray:
    w, x, y, z = q
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                 [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                 [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = pos
    return m


def floor_extent(shape):
    """(x0, x1, y0, y1) m of a static shape that is flat and horizontal (a floor, a road, the
    ground around a pond: drawn with a checker and a soft outer edge), else None."""
    if shape.form != "static":
        return None
    v = shape.verts
    if np.ptp(v[:, 2]) > 1e-9:
        return None
    return float(v[:, 0].min()), float(v[:, 0].max()), float(v[:, 1].min()), float(v[:, 1].max())


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


def _rgba(shape, n: int, part: int | None = None) -> np.ndarray:
    """(n,4) float32 per-vertex colour and opacity of a shape (or of its part) with n points."""
    out = np.empty((n, 4), np.float32)
    if part is not None and shape.part_colors is not None:
        out[:, :3] = shape.part_colors[part]
    elif shape.point_colors is not None:
        out[:, :3] = shape.point_colors
    else:
        out[:, :3] = shape.color
    out[:, 3] = shape.look.opacity
    return out


class Renderer:
    """Draws one run's systems at any time. size: (width, height) pixels; camera: a Camera,
    a TrackingCamera, or None for a default that frames every animated system over the whole
    run."""

    def __init__(self, run, size=(960, 540), camera=None, samples: int = 4,
                 shadow_size: int = 512):
        self.ctx = ctx = gl_context()
        self.w, self.h = int(size[0]), int(size[1])
        self.lo, self.hi = run.bounds()
        if camera is None:
            camera = default_camera(self.lo, self.hi, self.w / self.h)
        self.camera = camera
        self._path = None
        if isinstance(camera, TrackingCamera):
            # the camera's path at 60 samples/s, interpolated at any frame time
            self._path_t = np.arange(int(math.floor(run.duration * 60 + 1e-9)) + 1) / 60.0
            path = cameras(camera, run, self._path_t, self.w / self.h)
            self._path = (np.array([c.eye for c in path]), np.array([c.target for c in path]))
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
        self.sky = ctx.program(vertex_shader=shaders.SKY_VS, fragment_shader=shaders.SKY_FS)
        self.points = ctx.program(vertex_shader=shaders.POINT_VS,
                                  fragment_shader=shaders.POINT_FS)
        self.sky_vao = ctx.vertex_array(self.sky, [])
        self.shapes = list(run.shapes)  # only what the scene has: no invented floor
        self.uniforms = {"u_light_dir": tuple(SUN), "u_zenith": tuple(ZENITH),
                         "u_horizon": tuple(HORIZON), "u_haze": tuple(HAZE)}
        self._objects = []
        self._resources = [self.fbo, self.resolve, self.shadow_tex, self.shadow_fbo,
                           *self.progs.values(), *self.depth.values(), self.sky, self.sky_vao,
                           self.points]
        # cords and knots are a few pixels wide: six-sided tubes and icosahedra look round
        # there and keep the vertex work small (llvmpipe); hooks and particles get more
        cyl, self._knot_sphere, sph = _unit_cylinder(), _unit_sphere(0), _unit_sphere(1)
        for shape in self.shapes:
            self._add(shape, run, cyl, sph)
        # the floors end softly where the last of them ends (a road runs on into its verges)
        floors = np.array([ob["floor"] for ob in self._objects if "floor" in ob])
        if len(floors):
            x0, x1, y0, y1 = floors[:, 0].min(), floors[:, 1].max(), floors[:, 2].min(), \
                floors[:, 3].max()
            for ob in self._objects:
                if "floor" in ob:
                    ob.update(fade=(x0, x1, y0, y1), fade_w=0.25 * min(x1 - x0, y1 - y0) / 2)
        statics = [s.verts[:, 2].min() for s in self.shapes if s.form == "static"]
        self.ground_z = float(min(statics)) if statics else float(self.lo[2])

    # --- setup -----------------------------------------------------------------------------
    def camera_at(self, t: float) -> Camera:
        """The camera of the frame at time t (s)."""
        if self._path is None:
            return self.camera
        eye, target = (np.array([np.interp(t, self._path_t, a[:, k]) for k in range(3)])
                       for a in self._path)
        return Camera(tuple(eye), tuple(target), self.camera.fov_deg)

    def _view(self, t):
        cam = self.camera_at(t)
        centre = (self.lo + self.hi) / 2
        radius = max(float(np.linalg.norm(self.hi - self.lo)) / 2, 0.3)
        dist = float(np.linalg.norm(np.subtract(cam.eye, cam.target)))
        reach = float(np.linalg.norm(np.subtract(cam.eye, centre))) + radius
        near = max(0.02, 0.05 * dist)
        far = max(reach, dist) + 200.0
        self.vp = cam.projection(self.w / self.h, near, far) @ cam.view()
        self.px_per_m = self.h / (2.0 * math.tan(math.radians(cam.fov_deg) / 2))
        self.uniforms.update({"u_eye": tuple(map(float, cam.eye)),
                              "u_fog": (dist * 3.0 + 30.0, dist * 3.0 + 150.0)})

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
                              # ~4 mm of depth and 1.5 texels of normal offset
                              "u_bias": 0.004 / depth,
                              "u_offset": 1.5 * 2 * r / self.shadow_size})

    def _buffer(self, data, dynamic=False):
        buf = self.ctx.buffer(np.ascontiguousarray(data, dtype=np.float32).tobytes(),
                              dynamic=dynamic)
        self._resources.append(buf)
        return buf

    def _index(self, tris, dynamic=False):
        ibo = self.ctx.buffer(np.ascontiguousarray(tris, dtype=np.int32).tobytes(),
                              dynamic=dynamic)
        self._resources.append(ibo)
        return ibo

    def _vaos(self, kind, vbo, ibo, inst=None, inst_fmt=None, inst_attrs=()):
        """The vertex arrays of one object for the lit and the shadow program."""
        out = []
        if kind == "mesh":
            content = [(vbo, "3f 3f 4f", "in_pos", "in_normal", "in_color")]
        else:
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

    def _mesh(self, shape, verts, tris, rgba, **extra):
        vbo = self._buffer(np.concatenate([verts, vertex_normals(verts, tris), rgba], axis=1))
        vao, dvao = self._vaos("mesh", vbo, self._index(tris))
        ob = {"shape": shape, "kind": "mesh", "vao": vao, "dvao": dvao, "look": shape.look,
              "casts": True, **extra}
        self._objects.append(ob)
        return ob

    def _add(self, shape, run, cyl, sph):
        color = tuple(float(c) for c in shape.color)
        if shape.form == "static":
            extent = floor_extent(shape)
            ob = self._mesh(shape, shape.verts, shape.tris, _rgba(shape, len(shape.verts)),
                            casts=extent is None, centre=shape.verts.mean(axis=0))
            if extent is not None:
                ob.update(checker=shape.material != "concrete", floor=extent)
        elif shape.form == "body":
            self._mesh(shape, shape.verts, shape.tris, _rgba(shape, len(shape.verts)),
                       extent=float(np.linalg.norm(shape.verts, axis=1).max()))
        elif shape.form == "parts":
            for k, (v, t) in enumerate(shape.parts):
                self._mesh(shape, v, t, _rgba(shape, len(v), k), part=k,
                           extent=float(np.linalg.norm(v, axis=1).max()))
        elif shape.form == "surface":
            n = len(run.frames[shape.name]["points"][0])
            water, sub = shape.base is not None, None
            if water and n > WATER_POINTS:
                # a preview needs no more columns than it has pixels for: llvmpipe's cost is
                # per triangle as much as per pixel (the USD stage keeps every column)
                sub, shape = coarser_height_field(shape, 2)
                n = len(sub)
            vbo = self._buffer(np.zeros((n, 10)), dynamic=True)
            ibo = self._index(shape.triangles, dynamic=True)
            vao, dvao = self._vaos("mesh", vbo, ibo)
            self._objects.append({"shape": shape, "kind": "surface", "vao": vao, "dvao": dvao,
                                  "vbo": vbo, "ibo": ibo, "look": shape.look, "water": water,
                                  "rgba": _rgba(shape, n), "count": len(shape.triangles),
                                  "sub": sub,
                                  # a water surface lets the light through to its bed
                                  "casts": not water})
        elif shape.form == "cords":
            r = shape.width / 2
            vbo = self._buffer(np.concatenate(cyl[:2], axis=1))
            ibo = self._index(cyl[2])
            inst = self._buffer(np.zeros((len(shape.segments), 6)), dynamic=True)
            vao, dvao = self._vaos("tube", vbo, ibo, inst, "3f 3f/i", ("in_a", "in_b"))
            self._objects.append({"shape": shape, "kind": "cords", "vao": vao, "dvao": dvao,
                                  "inst": inst, "color": color, "radius": r, "casts": True,
                                  "count": len(shape.segments), "look": shape.look})
            self._knots(shape, run, self._knot_sphere, color, r)
        elif shape.form == "particles":
            n = len(run.frames[shape.name]["points"][0])
            inst = self._buffer(np.zeros((n, 3)), dynamic=True)
            vao = self.ctx.vertex_array(self.points, [(inst, "3f", "in_center")])
            self._resources.append(vao)
            self._objects.append({"shape": shape, "kind": "points", "vao": vao, "inst": inst,
                                  "color": color, "radius": max(shape.width / 2, 5e-4),
                                  "casts": False, "count": 0, "look": shape.look})
        if shape.anchors is not None:
            vbo = self._buffer(np.concatenate(sph[:2], axis=1))
            ibo = self._index(sph[2])
            inst = self._buffer(shape.anchors)
            vao, dvao = self._vaos("ball", vbo, ibo, inst, "3f/i", ("in_center",))
            r = max(shape.width, 0.004) * 1.5
            self._objects.append({"shape": None, "kind": "hooks", "vao": vao, "dvao": dvao,
                                  "color": HOOK_COLOR, "radius": r, "casts": True,
                                  "anchors": shape.anchors, "count": len(shape.anchors),
                                  "look": MATERIALS["metal"]})

    def _knots(self, shape, run, sph, color, radius):
        n = len(run.frames[shape.name]["points"][0])
        vbo = self._buffer(np.concatenate(sph[:2], axis=1))
        ibo = self._index(sph[2])
        inst = self._buffer(np.zeros((n, 3)), dynamic=True)
        vao, dvao = self._vaos("ball", vbo, ibo, inst, "3f/i", ("in_center",))
        self._objects.append({"shape": shape, "kind": "knots", "vao": vao, "dvao": dvao,
                              "inst": inst, "color": color, "radius": radius, "casts": True,
                              "count": n, "look": shape.look})

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
                p, rgba, tris = st["points"], ob["rgba"], shape.triangles
                if ob["sub"] is not None:
                    p = p[ob["sub"]]
                if ob["water"]:
                    p, alpha, wet = wet_surface(shape, p)
                    tris = tris[wet]
                    rgba = rgba.copy()
                    rgba[:, 3] = alpha
                    ob["ibo"].write(np.ascontiguousarray(tris, np.int32).tobytes())
                ob["count"] = len(tris)
                ob["vbo"].write(np.concatenate([p.astype(np.float32),
                                                vertex_normals(p, shape.triangles), rgba],
                                               1).tobytes())
            elif ob["kind"] == "cords":
                p = st["points"].astype(np.float32)
                seg = shape.segments
                ob["inst"].write(np.concatenate([p[seg[:, 0]], p[seg[:, 1]]], 1).tobytes())
            elif ob["kind"] in ("knots", "points"):
                p = st["points"]
                p = p[np.isfinite(p).all(axis=1)]  # absent particles (spray) are NaN rows
                ob["count"] = len(p)
                if len(p):
                    ob["inst"].write(p.astype(np.float32).tobytes())
            p = st.get("points")
            if p is not None and shape.base is None and np.isfinite(p).any():
                boxes += [np.nanmin(p, 0), np.nanmax(p, 0)]
        for ob in self._objects:
            if ob["kind"] == "hooks":
                boxes += [ob["anchors"].min(0), ob["anchors"].max(0)]
        if boxes:
            boxes = np.array(boxes)
            self._fit_sun(boxes.min(0), boxes.max(0))
        else:
            self._fit_sun(self.lo, self.hi)

    def _order(self):
        """The objects nearest first, floors last: llvmpipe shades a pixel only if its depth
        test passes, so what is in front should be drawn first (overdraw is its cost)."""
        eye = np.asarray(self.uniforms["u_eye"])

        def key(ob):
            if "floor" in ob:
                return np.inf
            c = ob.get("centre")
            if c is None and "model" in ob:
                c = ob["model"][:3, 3]
            return float(np.linalg.norm(c - eye)) if c is not None else 0.0
        return sorted(self._objects, key=key)

    def _draw(self, depth_pass: bool, translucent: bool = False):
        import moderngl
        vp = self.light_vp if depth_pass else self.vp
        for ob in (self._objects if depth_pass else self._order()):
            if depth_pass and not ob["casts"]:
                continue
            look = ob["look"]
            if not depth_pass and (look.opacity < 1.0) != translucent:
                continue
            vao = ob["dvao"] if depth_pass else ob["vao"]
            prog = vao.program
            _set(prog, "u_vp", vp)
            if ob["kind"] == "points":
                if ob["count"]:
                    for k, v in (("u_color", ob["color"]), ("u_glow", look.glow),
                                 ("u_radius", ob["radius"]), ("u_px", self.px_per_m),
                                 ("u_light_dir", self.uniforms["u_light_dir"])):
                        _set(prog, k, v)
                    vao.render(moderngl.POINTS, vertices=ob["count"])
                continue
            if not depth_pass:
                for k, v in self.uniforms.items():
                    _set(prog, k, v)
                if "color" in ob:
                    _set(prog, "u_color", ob["color"])
                _set(prog, "u_checker", 1 if ob.get("checker") else 0)
                _set(prog, "u_fade", ob.get("fade", (0.0, 0.0, 0.0, 0.0)))
                _set(prog, "u_fade_w", ob.get("fade_w", 0.0))
                _set(prog, "u_rough", look.roughness)
                _set(prog, "u_metal", look.metallic)
                _set(prog, "u_glow", look.glow)
                _set(prog, "u_water", 1 if ob.get("water") else 0)
                thin = ob["shape"] is not None and ob["shape"].double_sided
                _set(prog, "u_thin", THIN if thin else 0.0)
                _set(prog, "u_shadow", 0)
            if ob["kind"] == "mesh":
                _set(prog, "u_model", ob.get("model", np.eye(4)))
                vao.render()
            elif ob["kind"] == "surface":
                _set(prog, "u_model", np.eye(4))
                if ob["count"]:
                    vao.render(vertices=3 * ob["count"])
            elif ob["count"]:
                _set(prog, "u_radius", ob["radius"])
                vao.render(instances=ob["count"])

    def render(self, run, t: float) -> np.ndarray:
        """RGB image (h, w, 3) uint8 of the run at time t (s)."""
        import moderngl
        ctx = self.ctx
        self._view(t)
        self._update(run, t)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        self.shadow_fbo.use()
        self.shadow_fbo.clear(depth=1.0)
        # front faces would shadow themselves; offsetting depth keeps surfaces clean
        ctx.polygon_offset = (2.0, 4.0)
        self._draw(depth_pass=True)
        ctx.polygon_offset = (0.0, 0.0)
        self.fbo.use()
        self.fbo.clear(depth=1.0)
        self.shadow_tex.use(location=0)
        self._draw(depth_pass=False)
        # the sky on the far plane after the opaque things: shaded only where none is
        ctx.depth_func = "<="
        _set(self.sky, "u_inv_vp", np.linalg.inv(self.vp))
        for k in ("u_eye", "u_zenith", "u_horizon", "u_haze"):
            _set(self.sky, k, self.uniforms[k])
        self.sky_vao.render(moderngl.TRIANGLES, vertices=3)
        ctx.depth_func = "<"
        # translucent surfaces (water) last, blended over what they cover
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self._draw(depth_pass=False, translucent=True)
        ctx.disable(moderngl.BLEND)
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
