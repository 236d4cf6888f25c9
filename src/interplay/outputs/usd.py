"""USD export (usd-core): one stage per run, metres, +z up, one time code per output frame.

Stage layout (``/World`` is the default prim):
  /World/<body>        Xform, time-sampled xformOp:translate (double3) + xformOp:orient (quatd)
  /World/<body>/mesh   its static body-frame Mesh (smooth vertex normals)
  /World/<figure>/seg_NN  one such Xform + mesh per segment of an articulated figure
  /World/<surface>     Mesh with time-sampled points, normals and extent
  /World/<cords>       BasisCurves (linear, one 2-point curve per cord) with time-sampled
                       points and extent and a constant width: cords have no faces to shade
  /World/<particles>   Points with time-sampled positions (their number may change per frame)
  /World/<static>      Mesh (the floor)
Every gprim carries a constant ``primvars:displayColor``. Time code i is output frame i:
timeCodesPerSecond = framesPerSecond = the run's fps.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..errors import InterplayError, ParameterError
from ..io.atomic import atomic_path

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


def vertex_normals(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals (n,3) of a triangle mesh (smooth shading)."""
    p = np.asarray(points, dtype=np.float64)
    fn = np.cross(p[tris[:, 1]] - p[tris[:, 0]], p[tris[:, 2]] - p[tris[:, 0]])
    n = np.zeros_like(p)
    for k in range(3):
        np.add.at(n, tris[:, k], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


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
    used: set = set()
    for shape in run.shapes:
        name = prim_name(shape.name)
        while name in used:
            name += "_"
        used.add(name)
        path = f"/World/{name}"
        fr = run.frames.get(shape.name, {})
        writer = {"body": _body, "parts": _parts, "surface": _surface, "cords": _cords,
                  "particles": _particles, "static": _static}[shape.form]
        writer(stage, path, shape, fr, nf)
    return stage


def _color(gprim, shape):
    from pxr import Gf, UsdGeom
    gprim.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([Gf.Vec3f(*shape.color)])


def _mesh_topology(mesh, tris):
    mesh.CreateFaceVertexCountsAttr(np.full(len(tris), 3, dtype=np.int32))
    mesh.CreateFaceVertexIndicesAttr(np.asarray(tris, dtype=np.int32).reshape(-1))
    # explicit vertex normals give smooth shading without a subdivision surface
    mesh.CreateSubdivisionSchemeAttr("none")
    mesh.SetNormalsInterpolation("vertex")


def _vec3f(a):
    from pxr import Vt
    return Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(a, dtype=np.float32))


def _extent(pts, pad=0.0):
    from pxr import Vt
    lo, hi = pts.min(0) - pad, pts.max(0) + pad
    return Vt.Vec3fArray.FromNumpy(np.stack([lo, hi]).astype(np.float32))


def _posed(stage, path, shape, verts, tris, pos, quat):
    """An Xform with time-sampled translate + orient over a static mesh."""
    from pxr import Gf, UsdGeom
    xf = UsdGeom.Xform.Define(stage, path)
    tr = xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble)
    orient = xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble)
    for i in range(len(pos)):
        tr.Set(Gf.Vec3d(*map(float, pos[i])), i)
        w, x, y, z = map(float, quat[i])
        orient.Set(Gf.Quatd(w, x, y, z), i)
    mesh = UsdGeom.Mesh.Define(stage, f"{path}/mesh")
    _mesh_topology(mesh, tris)
    mesh.CreatePointsAttr(_vec3f(verts))
    mesh.CreateNormalsAttr(_vec3f(vertex_normals(verts, tris)))
    mesh.CreateExtentAttr(_extent(verts))
    _color(mesh, shape)


def _body(stage, path, shape, fr, nf):
    _posed(stage, path, shape, shape.verts, shape.tris, fr["position"], fr["orientation"])


def _parts(stage, path, shape, fr, nf):
    from pxr import UsdGeom
    UsdGeom.Xform.Define(stage, path)
    pos, quat = fr["segment_positions"], fr["segment_orientations"]
    for k, (v, t) in enumerate(shape.parts):
        _posed(stage, f"{path}/seg_{k:02d}", shape, v, t, pos[:, k], quat[:, k])


def _surface(stage, path, shape, fr, nf):
    from pxr import UsdGeom
    mesh = UsdGeom.Mesh.Define(stage, path)
    _mesh_topology(mesh, shape.triangles)
    pa, na, ea = mesh.CreatePointsAttr(), mesh.CreateNormalsAttr(), mesh.CreateExtentAttr()
    for i, p in enumerate(fr["points"]):
        pa.Set(_vec3f(p), i)
        na.Set(_vec3f(vertex_normals(p, shape.triangles)), i)
        ea.Set(_extent(p), i)
    _color(mesh, shape)


def _cords(stage, path, shape, fr, nf):
    from pxr import UsdGeom
    curves = UsdGeom.BasisCurves.Define(stage, path)
    curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    curves.CreateCurveVertexCountsAttr(np.full(len(shape.segments), 2, dtype=np.int32))
    curves.CreateWidthsAttr([float(shape.width)])
    curves.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    pa, ea = curves.CreatePointsAttr(), curves.CreateExtentAttr()
    seg = shape.segments.reshape(-1)
    for i, p in enumerate(fr["points"]):
        pa.Set(_vec3f(p[seg]), i)
        ea.Set(_extent(p[seg], shape.width / 2), i)
    _color(curves, shape)


def _particles(stage, path, shape, fr, nf):
    from pxr import UsdGeom
    pts = UsdGeom.Points.Define(stage, path)
    pts.CreateWidthsAttr([float(shape.width or 0.01)])
    pts.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    pa, ea = pts.CreatePointsAttr(), pts.CreateExtentAttr()
    for i, p in enumerate(fr["points"]):
        p = p[np.isfinite(p).all(axis=1)]  # absent particles are NaN rows
        pa.Set(_vec3f(p), i)
        ea.Set(_extent(p, (shape.width or 0.01) / 2) if len(p) else _extent(np.zeros((1, 3))), i)
    _color(pts, shape)


def _static(stage, path, shape, fr, nf):
    from pxr import UsdGeom
    mesh = UsdGeom.Mesh.Define(stage, path)
    _mesh_topology(mesh, shape.tris)
    mesh.CreatePointsAttr(_vec3f(shape.verts))
    mesh.CreateNormalsAttr(_vec3f(vertex_normals(shape.verts, shape.tris)))
    mesh.CreateExtentAttr(_extent(shape.verts))
    _color(mesh, shape)


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
