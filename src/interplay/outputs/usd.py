"""USD export (usd-core): one stage per run, metres, +z up, one time code per output frame,
laid out for an animator's DCC.

Stage layout (``/World`` is the default prim):
  /World/Looks/<material>   a UsdPreviewSurface Material per look (material kind and colour),
                            bound to every gprim that wears it
  /World/<body>             Xform, time-sampled xformOp:translate (double3) + xformOp:orient
                            (quatd), over its static mesh /World/<body>/geom
  /World/<figure>/pelvis/torso/head ...   a figure or rig (the bicyclist): one Xform per part,
                            named after it and nested under its parent, its transform relative
                            to the parent's, each over its static mesh .../<part>/geom
  /World/<surface>          Mesh with time-sampled points, normals (not for a height field:
                            they follow from its points), velocities (m/s: motion blur) and
                            extent, texture coordinates primvars:st from its rest
                            pose, doubleSided for cloth; a surface of several separate pieces
                            (the leaves) is an Xform with one such Mesh per piece
                            /World/leaves/leaves_00 ...; a height field (water) also has
                            time-sampled holeIndices: the faces that hold no water
  /World/<cords>            BasisCurves (linear), one polyline per cord (cords run on through
                            the knots), constant width (the cord's diameter), time-sampled
                            points, velocities and extent
  /World/<particles>        Points with time-sampled positions (their number may change)
  /World/<static>           Xform over its static mesh (the floor, set pieces)
Every gprim carries primvars:displayColor (constant, or per vertex where its colour varies).
Time code i is output frame i: timeCodesPerSecond = framesPerSecond = the run's fps.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..errors import InterplayError, ParameterError
from ..io.atomic import atomic_path
from .geometry import chains, local_poses, pieces, planar_uv, vertex_normals, wet_surface

FORMATS = ("usdc", "usda")


def _pxr():
    try:
        from pxr import Gf, Sdf, Usd, UsdGeom, Vt
    except ImportError:
        raise InterplayError("USD export needs usd-core: pip install 'usd-core>=24.0' "
                             "(or skip it with --no-usd)") from None
    return Gf, Sdf, Usd, UsdGeom, Vt


def prim_name(name: str) -> str:
    """A valid USD prim name for a system name (letters, digits, _; not starting with a digit)."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return s if s and not s[0].isdigit() else f"_{s}"


class _Looks:
    """The stage's UsdPreviewSurface materials, one per (material kind, colour); a gprim whose
    colour varies per vertex gets one that reads its displayColor."""

    def __init__(self, stage):
        from pxr import UsdGeom
        self.stage, self.made = stage, {}
        UsdGeom.Scope.Define(stage, "/World/Looks")

    def bind(self, gprim, shape, color=None, varying: bool = False):
        from pxr import Gf, Sdf, UsdShade
        color = tuple(round(float(c), 4) for c in (shape.color if color is None else color))
        key = (shape.material, color, varying)
        mat = self.made.get(key)
        if mat is None:
            name = f"{shape.material}_{len(self.made):02d}"
            mat = UsdShade.Material.Define(self.stage, f"/World/Looks/{name}")
            sh = UsdShade.Shader.Define(self.stage, f"/World/Looks/{name}/surface")
            sh.CreateIdAttr("UsdPreviewSurface")
            look = shape.look
            diffuse = sh.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f)
            diffuse.Set(Gf.Vec3f(*color))
            if varying:
                rd = UsdShade.Shader.Define(self.stage, f"/World/Looks/{name}/displayColor")
                rd.CreateIdAttr("UsdPrimvarReader_float3")
                rd.CreateInput("varname", Sdf.ValueTypeNames.String).Set("displayColor")
                rd.CreateInput("fallback", Sdf.ValueTypeNames.Float3).Set(Gf.Vec3f(*color))
                diffuse.ConnectToSource(rd.ConnectableAPI(), "result")
                rd.CreateOutput("result", Sdf.ValueTypeNames.Float3)
            sh.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(look.roughness)
            sh.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(look.metallic)
            sh.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(look.opacity)
            if look.glow:
                sh.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(
                    Gf.Vec3f(*(look.glow * c for c in color)))
            mat.CreateSurfaceOutput().ConnectToSource(sh.ConnectableAPI(), "surface")
            self.made[key] = mat
        UsdShade.MaterialBindingAPI.Apply(gprim.GetPrim()).Bind(mat)


def build_stage(run):
    """An in-memory Usd.Stage of the run (see the module docstring for the layout)."""
    Gf, Sdf, Usd, UsdGeom, Vt = _pxr()
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    nf = len(run.times)
    stage.SetTimeCodesPerSecond(run.fps)
    stage.SetFramesPerSecond(run.fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(max(nf - 1, 0))
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    stage.GetRootLayer().documentation = (f"Interplay run: scene {run.scene}, coupling "
                                          f"{run.coupling}, {run.duration} s at {run.fps} fps")
    looks = _Looks(stage)
    used: set = {"Looks"}
    for shape in run.shapes:
        name = prim_name(shape.name)
        while name in used:
            name += "_"
        used.add(name)
        path = f"/World/{name}"
        fr = run.frames.get(shape.name, {})
        writer = {"body": _body, "parts": _parts, "surface": _surface, "cords": _cords,
                  "particles": _particles, "static": _static}[shape.form]
        writer(stage, path, shape, fr, looks)
    return stage


def _vec3f(a):
    from pxr import Vt
    return Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(a, dtype=np.float32))


def _extent(pts, pad=0.0):
    from pxr import Vt
    lo, hi = pts.min(0) - pad, pts.max(0) + pad
    return Vt.Vec3fArray.FromNumpy(np.stack([lo, hi]).astype(np.float32))


def _colour(gprim, looks, shape, per_vertex=None, color=None):
    """displayColor (constant, or per vertex) and the bound material."""
    from pxr import Gf, UsdGeom
    if per_vertex is not None and np.ptp(per_vertex, axis=0).max() > 1e-6:
        gprim.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(_vec3f(per_vertex))
        looks.bind(gprim, shape, per_vertex.mean(axis=0), varying=True)
        return
    c = tuple(per_vertex[0]) if per_vertex is not None else (shape.color if color is None
                                                              else color)
    gprim.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([Gf.Vec3f(*map(float, c))])
    looks.bind(gprim, shape, c)


def _mesh(stage, path, verts, tris, double_sided=False):
    """A static Mesh (points, normals, extent) with explicit vertex normals: smooth shading
    without a subdivision surface."""
    from pxr import UsdGeom
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreateFaceVertexCountsAttr(np.full(len(tris), 3, dtype=np.int32))
    mesh.CreateFaceVertexIndicesAttr(np.asarray(tris, dtype=np.int32).reshape(-1))
    mesh.CreateSubdivisionSchemeAttr("none")
    mesh.SetNormalsInterpolation("vertex")
    mesh.CreateDoubleSidedAttr(bool(double_sided))
    if verts is not None:
        mesh.CreatePointsAttr(_vec3f(verts))
        mesh.CreateNormalsAttr(_vec3f(vertex_normals(verts, tris)))
        mesh.CreateExtentAttr(_extent(verts))
    return mesh


def _xform(stage, path, pos=None, quat=None):
    """An Xform, with time-sampled translate + orient when pos (f,3) and quat (f,4) given."""
    from pxr import Gf, UsdGeom
    xf = UsdGeom.Xform.Define(stage, path)
    if pos is not None:
        tr = xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble)
        orient = xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble)
        for i in range(len(pos)):
            tr.Set(Gf.Vec3d(*map(float, pos[i])), i)
            w, x, y, z = map(float, quat[i])
            orient.Set(Gf.Quatd(w, x, y, z), i)
    return xf


def _body(stage, path, shape, fr, looks):
    _xform(stage, path, fr["position"], fr["orientation"])
    mesh = _mesh(stage, f"{path}/geom", shape.verts, shape.tris)
    _colour(mesh, looks, shape, shape.point_colors)


def _parts(stage, path, shape, fr, looks):
    """One Xform per named part, nested under its parent, relative to it."""
    _xform(stage, path)
    pos, quat = local_poses(fr["segment_positions"], fr["segment_orientations"],
                            shape.part_parents)
    paths: dict = {}
    for k, (v, t) in enumerate(shape.parts):
        par = shape.part_parents[k]
        paths[k] = f"{paths[par] if par >= 0 else path}/{prim_name(shape.part_names[k])}"
        _xform(stage, paths[k], pos[:, k], quat[:, k])
        mesh = _mesh(stage, f"{paths[k]}/geom", v, t)
        colour = shape.part_colors[k] if shape.part_colors is not None else None
        _colour(mesh, looks, shape, color=colour)


def _velocities(pts, t):
    """(f, n, 3) m/s: central differences in time (one-sided at the ends)."""
    if len(pts) < 2:
        return np.zeros_like(pts)
    return np.gradient(pts, np.asarray(t, float), axis=0)


def _surface(stage, path, shape, fr, looks):
    from pxr import Vt
    pts = np.asarray(fr["points"], float)
    water = shape.base is not None
    if water:
        drawn = [wet_surface(shape, p) for p in pts]
        pts = np.array([d[0] for d in drawn])
    vel = _velocities(pts, fr["t"])
    parts = pieces(shape.triangles, pts.shape[1])
    if len(parts) > 1:
        _xform(stage, path)
    for k, (idx, tris) in enumerate(parts):
        p_path = path if len(parts) == 1 else f"{path}/{prim_name(shape.name)}_{k:02d}"
        mesh = _mesh(stage, p_path, None, tris, shape.double_sided)
        pa, va, ea = mesh.CreatePointsAttr(), mesh.CreateVelocitiesAttr(), mesh.CreateExtentAttr()
        # a height field's normals follow from its points (a DCC computes them); authoring
        # them per frame would double the water's share of the stage
        na = None if water else mesh.CreateNormalsAttr()
        for i in range(len(pts)):
            p = pts[i][idx]
            pa.Set(_vec3f(p), i)
            if na is not None:
                na.Set(_vec3f(vertex_normals(p, tris)), i)
            va.Set(_vec3f(vel[i][idx]), i)
            ea.Set(_extent(p), i)
        if water:
            ha = mesh.CreateHoleIndicesAttr()
            for i, (_, _, wet) in enumerate(drawn):
                ha.Set(Vt.IntArray.FromNumpy(np.flatnonzero(~wet).astype(np.int32)), i)
        from pxr import Sdf, UsdGeom
        st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                     UsdGeom.Tokens.vertex)
        uv = planar_uv(pts[0][idx] if not water else np.c_[shape.grid_xy, np.zeros(len(idx))])
        st.Set(Vt.Vec2fArray.FromNumpy(uv.astype(np.float32)))
        colors = shape.point_colors[idx] if shape.point_colors is not None else None
        _colour(mesh, looks, shape, colors)


def _cords(stage, path, shape, fr, looks):
    from pxr import UsdGeom
    pts = np.asarray(fr["points"], float)
    lines = chains(shape.segments, pts[0])
    order = np.concatenate(lines)
    curves = UsdGeom.BasisCurves.Define(stage, path)
    curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    curves.CreateCurveVertexCountsAttr(np.array([len(c) for c in lines], dtype=np.int32))
    curves.CreateWidthsAttr([float(shape.width)])
    curves.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    vel = _velocities(pts, fr["t"])
    pa, va, ea = curves.CreatePointsAttr(), curves.CreateVelocitiesAttr(), \
        curves.CreateExtentAttr()
    for i, p in enumerate(pts):
        pa.Set(_vec3f(p[order]), i)
        va.Set(_vec3f(vel[i][order]), i)
        ea.Set(_extent(p[order], shape.width / 2), i)
    _colour(curves, looks, shape)


def _particles(stage, path, shape, fr, looks):
    from pxr import UsdGeom
    pts = UsdGeom.Points.Define(stage, path)
    pts.CreateWidthsAttr([float(shape.width or 0.01)])
    pts.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    pa, ea = pts.CreatePointsAttr(), pts.CreateExtentAttr()
    for i, p in enumerate(fr["points"]):
        p = p[np.isfinite(p).all(axis=1)]  # absent particles are NaN rows
        pa.Set(_vec3f(p), i)
        ea.Set(_extent(p, (shape.width or 0.01) / 2) if len(p) else _extent(np.zeros((1, 3))), i)
    _colour(pts, looks, shape)


def _static(stage, path, shape, fr, looks):
    _xform(stage, path)
    mesh = _mesh(stage, f"{path}/geom", shape.verts, shape.tris)
    _colour(mesh, looks, shape, shape.point_colors)


def write_usd(run, path, fmt: str | None = None) -> Path:
    """Write the run's stage to ``path`` (.usdc binary by default, .usda text on request).

    fmt: "usdc" or "usda"; default from the extension of ``path``. Written atomically: a
    failure leaves no file at ``path``.
    """
    path = Path(path)
    fmt = fmt or (path.suffix[1:] if path.suffix in (".usdc", ".usda") else "usdc")
    if fmt not in FORMATS:
        raise ParameterError(f"USD format {fmt!r}: choose usdc (binary) or usda (text)")
    if path.suffix not in (".usd", f".{fmt}"):
        raise ParameterError(f"{path}: a {fmt} stage needs the extension .{fmt} or .usd")
    stage = build_stage(run)
    with atomic_path(path) as tmp:
        # USD picks the file format from the extension, so write beside the temp name with
        # the real one, then move it onto the temp name that atomic_path renames.
        staging = tmp.with_name(tmp.name + f".{fmt}")
        try:
            if not stage.GetRootLayer().Export(str(staging), args={"format": fmt}):
                raise InterplayError(f"USD could not write {path}")
            os.replace(staging, tmp)
        finally:
            if staging.exists():
                staging.unlink()
    return path


def validate(path) -> list[str]:
    """Run every validator registered with pxr.UsdValidation on a stage file; return the
    errors as "Validator: message" lines (warnings are not errors)."""
    _pxr()
    from pxr import Usd, UsdValidation
    stage = Usd.Stage.Open(str(path))
    reg = UsdValidation.ValidationRegistry()
    ctx = UsdValidation.ValidationContext(reg.GetOrLoadAllValidators())
    out = []
    for e in ctx.Validate(stage):
        if e.GetType() == UsdValidation.ValidationErrorType.Error:
            out.append(f"{e.GetName()}: {e.GetMessage()}")
    return out
