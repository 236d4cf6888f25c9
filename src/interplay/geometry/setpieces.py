"""Set pieces from the paper's figures: the hoop's rim, backboard and pole, a bridge with its
jump platform and arm, a road, the ground around a basin. Each builder returns Pieces
(name, vertices (n,3) m, triangles (m,3), linear RGB colour, material of systems/shape.py);
a scene adds them as static systems (``colliders.set_pieces``): drawn and exported, and
collidable wherever the scene connects a contact to them.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Piece(NamedTuple):
    name: str
    verts: np.ndarray
    tris: np.ndarray
    color: tuple
    material: str


def _mesh(m):
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def box(lo, hi):
    """An axis-aligned box from corner lo to corner hi (m)."""
    from trimesh import creation
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    m = creation.box(extents=hi - lo)
    m.apply_translation((lo + hi) / 2)
    return _mesh(m)


def rod(a, b, radius, sections=12):
    """A cylinder of radius (m) from point a to point b (m)."""
    from trimesh import creation
    return _mesh(creation.cylinder(radius=radius, segment=np.array([a, b], dtype=float),
                                   sections=sections))


def merge(*meshes):
    """One mesh of several (vertices, triangles) pairs."""
    verts, tris, base = [], [], 0
    for v, t in meshes:
        verts.append(v)
        tris.append(t + base)
        base += len(v)
    return np.concatenate(verts), np.concatenate(tris)


def hoop(rim_centre, rim_radius: float) -> list:
    """A regulation hoop (FIBA/NBA) around a rim of radius rim_radius (m) centred at
    rim_centre (m), the backboard on its -x side: the 16 mm steel ring, its bracket, the
    1.83 x 1.07 m board 0.15 m behind the ring's inner edge with its bottom 0.15 m below the
    ring, the 0.59 x 0.45 m target square, and a padded pole 1.2 m behind with its arm."""
    from trimesh import creation
    c = np.asarray(rim_centre, float)
    ring = creation.torus(major_radius=rim_radius + 0.008, minor_radius=0.008,
                          major_sections=48, minor_sections=8)
    ring.apply_translation(c)
    face = c[0] - rim_radius - 0.152  # m: the board's front face
    bracket = box([face, c[1] - 0.08, c[2] - 0.02], [c[0] - rim_radius, c[1] + 0.08, c[2]])
    board = box([face - 0.03, c[1] - 0.915, c[2] - 0.15], [face, c[1] + 0.915, c[2] + 0.92])
    z0 = c[2] + 0.0
    square = merge(*[box([face + 0.001, c[1] + y0, z0 + za], [face + 0.004, c[1] + y1, z0 + zb])
                     for y0, y1, za, zb in ((-0.295, 0.295, 0.40, 0.45), (-0.295, -0.245, 0.0,
                                            0.45), (0.245, 0.295, 0.0, 0.45),
                                            (-0.295, 0.295, 0.0, 0.05))])
    pole_x = face - 1.2
    pole = merge(rod([pole_x, c[1], 0.0], [pole_x, c[1], c[2] + 0.5], 0.09),
                 rod([pole_x, c[1], c[2] + 0.45], [face - 0.03, c[1], c[2] + 0.45], 0.05),
                 rod([pole_x, c[1], c[2] - 0.3], [face - 0.03, c[1], c[2] + 0.1], 0.04))
    return [Piece("rim", *_mesh(ring), (0.85, 0.25, 0.04), "metal"),
            Piece("rim-bracket", *bracket, (0.85, 0.25, 0.04), "metal"),
            Piece("backboard", *board, (0.92, 0.92, 0.90), "paint"),
            Piece("backboard-square", *square, (0.08, 0.08, 0.08), "paint"),
            Piece("hoop-pole", *pole, (0.20, 0.22, 0.26), "paint")]


def bridge(deck: float, edge: float, platform, anchor, span: float = 70.0) -> list:
    """A bridge deck at height deck (m) running along y, its side at x = edge - 3 m; the jump
    platform platform = (x0, x1, y0, y1) m jutting out from it to the edge; railings; two
    piers down to the valley floor (z = 0); and the jump arm: two posts at the platform's
    front and a beam out to the cord's anchor (m)."""
    x0, x1, y0, y1 = platform
    a = np.asarray(anchor, float)
    side = x0
    deck_box = box([side - 8.0, -span / 2, deck - 1.4], [side, span / 2, deck])
    slab = box([x0, y0, deck - 0.35], [x1, y1, deck])
    piers = merge(*[box([side - 6.5, y - 1.2, 0.0], [side - 1.5, y + 1.2, deck - 1.4])
                    for y in (-0.42 * span, 0.42 * span)])
    rails = []
    for y in np.arange(-span / 2 + 1.0, span / 2, 2.0):
        if not y0 - 0.2 < y < y1 + 0.2:
            rails.append(rod([side - 0.1, y, deck], [side - 0.1, y, deck + 1.1], 0.03, 8))
    for ya, yb in ((-span / 2, y0), (y1, span / 2)):
        rails.append(rod([side - 0.1, ya, deck + 1.1], [side - 0.1, yb, deck + 1.1], 0.03, 8))
    for y in (y0, y1):
        rails.append(rod([x0, y, deck + 1.1], [x1 - 0.2, y, deck + 1.1], 0.03, 8))
        rails.append(rod([x1 - 0.2, y, deck], [x1 - 0.2, y, deck + 1.1], 0.03, 8))
    post_x, top = x1 - 0.35, deck + 1.2
    arm = merge(rod([post_x, y0 + 0.2, deck], [post_x, y0 + 0.2, top], 0.06),
                rod([post_x, y1 - 0.2, deck], [post_x, y1 - 0.2, top], 0.06),
                rod([post_x, y0 + 0.2, top], [post_x, y1 - 0.2, top], 0.06),
                rod([post_x, 0.0, top], a + [0.0, 0.0, 0.05], 0.06),
                rod([post_x, 0.0, deck + 0.3], a + [-0.3, 0.0, 0.0], 0.04))
    return [Piece("bridge-deck", *deck_box, (0.55, 0.54, 0.52), "concrete"),
            Piece("bridge-piers", *piers, (0.50, 0.49, 0.47), "concrete"),
            Piece("jump-platform", *slab, (0.45, 0.32, 0.20), "wood"),
            Piece("railings", *merge(*rails), (0.25, 0.27, 0.30), "metal"),
            Piece("jump-arm", *arm, (0.80, 0.55, 0.10), "paint")]


def ground_around(lo, hi, height: float, size: float, name: str = "ground",
                  color=(0.30, 0.42, 0.20), material: str = "ground") -> Piece:
    """The ground at height (m) over the square of half-size size (m) about the origin, with
    a rectangular hole [lo, hi] (x, y, m) where a basin's own bed is drawn."""
    (ax, ay), (bx, by) = lo, hi
    s = float(size)
    xs, ys = [-s, ax, bx, s], [-s, ay, by, s]
    v = np.array([[x, y, height] for y in ys for x in xs])
    tris = []
    for j in range(3):
        for i in range(3):
            if i == 1 and j == 1:
                continue  # the hole
            a, b, c, d = 4 * j + i, 4 * j + i + 1, 4 * (j + 1) + i + 1, 4 * (j + 1) + i
            tris += [(a, b, c), (a, c, d)]
    return Piece(name, v, np.array(tris, np.int64), color, material)


def trestle(deck: float, edge: float, arm, span: float = 24.0, width: float = 2.6) -> list:
    """A timber railroad bridge (the short's, after Bierce): ties on two stringers along y at
    height deck (m), the deck's side at x = edge, rails on the ties, timber bents down to the
    creek bed (z = -1) every 6 m, and the hanging frame: a post at the side, braced, with a
    cross-timber out to ``arm`` (m), the point the rope hangs from."""
    a = np.asarray(arm, float)
    x0 = edge - width
    ties = merge(*[box([x0 - 0.3, y - 0.1, deck - 0.15], [edge, y + 0.1, deck])
                   for y in np.arange(-span / 2, span / 2 + 1e-9, 0.55)])
    stringers = merge(*[box([x, -span / 2, deck - 0.55], [x + 0.35, span / 2, deck - 0.15])
                        for x in (x0 + 0.2, edge - 0.55)])
    rails = merge(*[box([x - 0.04, -span / 2, deck], [x + 0.04, span / 2, deck + 0.14])
                    for x in (x0 + 0.55, edge - 0.9)])
    bents = merge(*[rod([x, y, -1.0], [x, y, deck - 0.55], 0.15)
                    for y in np.arange(-span / 2 + 3.0, span / 2, 6.0)
                    for x in (x0 + 0.35, edge - 0.4)])
    top = a[2] + 0.12
    post = edge - 0.25
    frame = merge(rod([post, 0.0, deck], [post, 0.0, top + 0.1], 0.11),
                  box([post - 0.1, -0.1, a[2] + 0.02], [a[0] + 0.2, 0.1, a[2] + 0.22]),
                  rod([post, 0.0, top - 0.9], [post + 0.75, 0.0, a[2] + 0.05], 0.06))
    return [Piece("ties", *ties, (0.30, 0.22, 0.15), "wood"),
            Piece("stringers", *stringers, (0.26, 0.19, 0.13), "wood"),
            Piece("rails", *rails, (0.35, 0.33, 0.32), "metal"),
            Piece("bents", *bents, (0.28, 0.21, 0.14), "wood"),
            Piece("hanging-frame", *frame, (0.36, 0.27, 0.18), "wood")]
