"""Built-in triangle meshes for spring-mass networks and props: a rectangular cloth grid, a
disc, a leaf outline with its centre vein, and a pole (the bicyclist is a rig of its own:
geometry/bicycle.py).

Each returns vertices (n,3) in m and triangles (m,3) (int64); the leaf also returns the
indices of its vein vertices (the stiffer midrib).
"""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError, require_positive


def _count(owner, name, value, least):
    if int(value) != value or value < least:
        raise ParameterError(f"{owner}: {name} must be an integer >= {least}, got {value!r}")
    return int(value)


def grid(width: float, height: float, nu: int, nv: int, origin=(0.0, 0.0, 0.0),
         u=(1.0, 0.0, 0.0), v=(0.0, 1.0, 0.0)):
    """A rectangular cloth: nu x nv vertices spanning width (m) along unit axis u and height (m)
    along v from origin (the corner of vertex 0). Vertex (i, j) is index j * nu + i. Quad
    diagonals alternate (criss-cross) so the cloth has no preferred shear direction."""
    width = require_positive("grid", "width", width, "m")
    height = require_positive("grid", "height", height, "m")
    nu, nv = _count("grid", "nu", nu, 2), _count("grid", "nv", nv, 2)
    s, r = np.meshgrid(np.linspace(0, width, nu), np.linspace(0, height, nv))
    x = (np.asarray(origin, float) + s.reshape(-1, 1) * np.asarray(u, float)
         + r.reshape(-1, 1) * np.asarray(v, float))
    i, j = np.meshgrid(np.arange(nu - 1), np.arange(nv - 1))
    i, j = i.ravel(), j.ravel()
    a, b, c, d = j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i
    flip = (i + j) % 2 == 1
    t1 = np.where(flip[:, None], np.stack([a, b, d], 1), np.stack([a, b, c], 1))
    t2 = np.where(flip[:, None], np.stack([b, c, d], 1), np.stack([a, c, d], 1))
    return x, np.concatenate([t1, t2]).astype(np.int64)


def disc(radius: float, rings: int, centre=(0.0, 0.0, 0.0)):
    """A flat disc in the xy plane: a centre vertex and `rings` concentric rings of 6 r
    vertices (r = 1..rings), so triangles stay close to equilateral."""
    radius = require_positive("disc", "radius", radius, "m")
    rings = _count("disc", "rings", rings, 1)
    pts, tris = [np.zeros(2)], []
    start = [0]
    for r in range(1, rings + 1):
        a = np.linspace(0, 2 * np.pi, 6 * r, endpoint=False)
        pts.extend(radius * r / rings * np.stack([np.cos(a), np.sin(a)], 1))
        start.append(start[-1] + max(1, 6 * (r - 1)))  # ring r starts after ring r-1
    tris += [(0, 1 + o, 1 + (o + 1) % 6) for o in range(6)]
    for r in range(2, rings + 1):
        inner, n_in = start[r - 1], 6 * (r - 1)
        outer, n_out = start[r], 6 * r
        # walk both rings by angle, always advancing the one whose next vertex comes first
        i = o = 0
        while i < n_in or o < n_out:
            if o < n_out and (i >= n_in or (o + 1) / n_out <= (i + 1) / n_in):
                tris.append((inner + i % n_in, outer + o, outer + (o + 1) % n_out))
                o += 1
            else:
                tris.append((inner + i, outer + o % n_out, inner + (i + 1) % n_in))
                i += 1
    x = np.zeros((len(pts), 3))
    x[:, :2] = pts
    return x + np.asarray(centre, float), np.array(tris, dtype=np.int64)


def leaf(length: float, width: float, stations: int = 8, rows: int = 2):
    """A leaf in the xy plane, tip to tip along +x from the origin: half-width
    (width/2) sin(pi s)^0.7 at s = x / length (a convex outline pointed at both ends).
    `stations` interior cross-sections of 2 rows + 1 vertices. Returns (vertices, triangles,
    vein) with vein the vertex indices on the midrib (y = 0), base and tip included."""
    length = require_positive("leaf", "length", length, "m")
    width = require_positive("leaf", "width", width, "m")
    stations = _count("leaf", "stations", stations, 1)
    rows = _count("leaf", "rows", rows, 1)
    per = 2 * rows + 1
    s = np.arange(1, stations + 1) / (stations + 1)
    half = 0.5 * width * np.sin(np.pi * s) ** 0.7
    pts = [(0.0, 0.0)]
    for si, hw in zip(s, half):
        pts.extend((si * length, hw * j / rows) for j in range(-rows, rows + 1))
    pts.append((length, 0.0))
    tip = len(pts) - 1
    row0 = lambda k: 1 + k * per  # noqa: E731 (index of station k's first vertex)
    tris = [(0, row0(0) + j + 1, row0(0) + j) for j in range(per - 1)]
    for k in range(stations - 1):
        a, b = row0(k), row0(k + 1)
        for j in range(per - 1):
            tris += [(a + j, b + j + 1, b + j), (a + j, a + j + 1, b + j + 1)]
    last = row0(stations - 1)
    tris += [(last + j, last + j + 1, tip) for j in range(per - 1)]
    x = np.zeros((len(pts), 3))
    x[:, :2] = pts
    vein = np.array([0] + [row0(k) + rows for k in range(stations)] + [tip], dtype=np.int64)
    return x, np.array(tris, dtype=np.int64), vein


def pole(height: float, radius: float = 0.025):
    """A vertical pole standing on the origin, `height` m tall (a cylinder)."""
    from trimesh import creation
    height = require_positive("pole", "height", height, "m")
    m = creation.cylinder(radius=require_positive("pole", "radius", radius, "m"),
                          segment=np.array([[0.0, 0.0, 0.0], [0.0, 0.0, height]]), sections=12)
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
