"""OBJ sequences for tools without USD: one file per output frame per moving system.

Layout under the target directory (default ``obj/``):
  <system>/<system>_0000.obj ...   deforming surfaces (v, vn, f), cord networks (v, l),
                                   particles (v only), rigid bodies and figures (their
                                   meshes posed in the world: OBJ has no transforms)
  <static>.obj                     static systems, once
Coordinates are metres, +z up, as everywhere in Interplay (many tools assume +y up: rotate
on import). The whole directory is written under a temporary name and renamed when complete,
so a crash never leaves a sequence that looks finished.
"""
from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from ..errors import InterplayError
from .geometry import quat_matrix, vertex_normals
from .usd import prim_name


def _rows(prefix: str, a: np.ndarray, item: str, items: int) -> str:
    """Lines "prefix item item ..." with ``items`` items each, formatted from a's rows."""
    if len(a) == 0:
        return ""
    line = prefix + " " + " ".join([item] * items) + "\n"
    return (line * len(a)) % tuple(a.reshape(-1))


def obj_text(name: str, points, tris=None, segments=None, normals=True) -> str:
    """One OBJ file: points (n,3) m, triangles (m,3) as faces with vertex normals, segments
    (s,2) as ``l`` line elements. Indices in the file are 1-based."""
    p = np.asarray(points, dtype=float)
    out = [f"# Interplay OBJ: {name}; metres, +z up\n", f"o {name}\n", _rows("v", p, "%.6f", 3)]
    if tris is not None and len(tris):
        t = np.asarray(tris, dtype=np.int64) + 1
        if normals:
            out.append(_rows("vn", vertex_normals(p, np.asarray(tris)), "%.5f", 3))
            out.append(_rows("f", np.repeat(t, 2, axis=1), "%d//%d", 3))
        else:
            out.append(_rows("f", t, "%d", 3))
    if segments is not None and len(segments):
        out.append(_rows("l", np.asarray(segments, dtype=np.int64) + 1, "%d", 2))
    return "".join(out)


def _frame_geometry(shape, run, i):
    if shape.form == "body":
        pos, q = run.pose(shape.name, i)
        return shape.verts @ quat_matrix(q).T + pos, shape.tris, None
    if shape.form == "parts":
        fr = run.frames[shape.name]
        pos, quat = fr["segment_positions"][i], fr["segment_orientations"][i]
        verts, tris, base = [], [], 0
        for k, (v, t) in enumerate(shape.parts):
            verts.append(v @ quat_matrix(quat[k]).T + pos[k])
            tris.append(t + base)
            base += len(v)
        return np.concatenate(verts), np.concatenate(tris), None
    pts = run.points(shape.name, i)
    if shape.form == "surface":
        return pts, shape.triangles, None
    if shape.form == "cords":
        return pts, None, shape.segments
    return pts[np.isfinite(pts).all(axis=1)], None, None  # absent particles are NaN rows


def write_obj_sequence(run, out_dir, progress=None) -> list[Path]:
    """Write the run as OBJ files into ``out_dir`` (replaced whole); return the system folders
    and static files written. progress: optional callable(done, total)."""
    out_dir = Path(out_dir)
    try:
        out_dir.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".part",
                                        dir=out_dir.parent))
    except OSError as e:
        raise InterplayError(f"cannot write to {out_dir.parent}: {e.strerror}; choose another "
                             "--out directory") from None
    try:
        written = []
        nf = len(run.times)
        moving = [s for s in run.shapes if s.animated]
        total, done = nf * len(moving), 0
        for shape in run.shapes:
            name = prim_name(shape.name)
            if not shape.animated:
                (staging / f"{name}.obj").write_text(obj_text(name, shape.verts, shape.tris))
                written.append(out_dir / f"{name}.obj")
                continue
            folder = staging / name
            folder.mkdir()
            for i in range(nf):
                v, t, s = _frame_geometry(shape, run, i)
                (folder / f"{name}_{i:04d}.obj").write_text(obj_text(name, v, t, s))
                done += 1
                if progress is not None:
                    progress(done, total)
            written.append(out_dir / name)
        for p in staging.rglob("*"):
            os.chmod(p, 0o755 if p.is_dir() else 0o644)
        os.chmod(staging, 0o755)
        if out_dir.exists():
            shutil.rmtree(out_dir)
        os.replace(staging, out_dir)
    except OSError as e:
        raise InterplayError(f"cannot write OBJ files to {out_dir}: {e.strerror}; check free "
                             "space and permissions or choose another --out directory") from None
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)
    return written


def read_obj(path) -> dict:
    """Parse an OBJ written here: {"v": (n,3), "vn": (n,3), "f": (m,3), "l": (s,2)},
    indices 0-based (a check for round trips, not a general OBJ reader)."""
    v, vn, f, ln = [], [], [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            v.append([float(x) for x in parts[1:4]])
        elif parts[0] == "vn":
            vn.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f":
            f.append([int(x.split("/")[0]) - 1 for x in parts[1:]])
        elif parts[0] == "l":
            ln.append([int(x) - 1 for x in parts[1:]])
    return {"v": np.array(v).reshape(-1, 3), "vn": np.array(vn).reshape(-1, 3),
            "f": np.array(f, dtype=np.int64).reshape(-1, 3),
            "l": np.array(ln, dtype=np.int64).reshape(-1, 2)}
