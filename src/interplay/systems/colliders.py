"""Static colliders beyond the floor: box, sphere, capsule and triangle mesh (SPEC 2.5).

Like ``StaticPlane`` they are infinitely massive, never move and record nothing. Each answers
``distance(points) -> (s, n)``: the signed distance (m, negative inside) of every point and the
outward normal there, which is all a contact needs from a static shape (its ShapeView).
``surface()`` gives the triangles drawn and exported; a static mesh is also how a scene's set
pieces (a pole, a rim, a deck) are drawn, collidable where the scene connects them.
"""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError, require_positive
from ..geometry.aabb_tree import AABBTree, check_points
from ..geometry.sphere import icosphere
from ..kernels.trimesh_contact import (box_distance, capsule_distance,
                                       signed_triangle_distance)
from .shape import Shape
from .static import Stateless
from .views import ShapeView


def box_surface(half):
    """Vertices (8,3) m and outward-wound triangles (12,3) of a box with half extents (m)."""
    h = np.asarray(half, dtype=float)
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * h
    t = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
         (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, np.array(t, dtype=np.int64)


class StaticShape(Stateless):
    """Base of immovable colliders: mass inf, no state, never stepped. color: linear RGB
    (0..1) as drawn, None for the outputs' default; material: as drawn (systems/shape.py)."""

    color = None
    material = "matte"

    def contact_view(self):
        return ShapeView(self, self.distance)

    def shapes(self):
        v, t = self.surface()
        return [Shape(self.name, "static", color=self.color, verts=np.asarray(v, float),
                      tris=np.asarray(t), palette="static", material=self.material)]

    def distance(self, points):
        """Signed distance (n,) m and outward unit normals (n,3) of points (n,3)."""
        p = check_points(self.name, points, "query points")
        s, n = np.empty(len(p)), np.empty((len(p), 3))
        self._distance(p, s, n)
        return s, n


def _vector(owner, name, value, shape=(3,)):
    a = np.asarray(value, dtype=float)
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise ParameterError(f"{owner}: {name} must be finite with shape {shape}, got {value!r}")
    return a


class StaticBox(StaticShape):
    """A box: centre (m), half extents (m), rotation (3x3, columns are the box's axes)."""

    def __init__(self, name, centre, half, rotation=np.eye(3)):
        super().__init__(name)
        self.centre = _vector(name, "centre", centre)
        self.half = _vector(name, "half extents", half)
        if not np.all(self.half > 0):
            raise ParameterError(f"{name}: half extents must be positive (m), got {half!r}")
        self.R = _vector(name, "rotation", rotation, (3, 3))
        if not np.allclose(self.R.T @ self.R, np.eye(3), atol=1e-9):
            raise ParameterError(f"{name}: rotation must be orthonormal (a rotation matrix)")

    def _distance(self, p, s, n):
        box_distance(p, self.centre, self.R, self.half, s, n)

    def surface(self):
        v, t = box_surface(self.half)
        return v @ self.R.T + self.centre, t


class StaticCapsule(StaticShape):
    """A capsule: the points within radius (m) of the segment a-b (m)."""

    def __init__(self, name, a, b, radius):
        super().__init__(name)
        self.a = _vector(name, "end a", a)
        self.b = _vector(name, "end b", b)
        self.radius = require_positive(name, "radius", radius, "m")

    def _distance(self, p, s, n):
        capsule_distance(p, self.a, self.b, self.radius, s, n)

    def surface(self):
        v, t = icosphere(2)
        axis = self.b - self.a
        # stretch the sphere's upper half to the far end: a capsule for drawing
        up = axis / (np.linalg.norm(axis) or 1.0)
        ends = np.where((v @ up)[:, None] > 0, self.b, self.a)
        return v * self.radius + ends, t


class StaticSphere(StaticCapsule):
    """A sphere of radius (m) about centre (m)."""

    def __init__(self, name, centre, radius):
        super().__init__(name, centre, centre, radius)
        self.centre = self.a


class StaticMesh(StaticShape):
    """A triangle mesh (vertices m, triangles wound outward). Points behind a face, down to
    ``depth`` (m), are inside (a closed mesh, or the solid side of a terrain). A set piece
    (a pole, a rim, a deck) is one: color and material are how it is drawn."""

    def __init__(self, name, vertices, triangles, depth=0.05, color=None, material="matte"):
        super().__init__(name)
        self.color, self.material = color, material
        self.depth = require_positive(name, "depth", depth, "m")
        self.tree = AABBTree(vertices, triangles, owner=name)
        self.vertices, self.triangles = self.tree.x, self.tree.elements

    def distance(self, points, reach=None):
        """As the other shapes, for points within reach (m; default depth) of the surface;
        farther points get s = inf."""
        p = check_points(self.name, points, "query points")
        tri, d, bary = self.tree.nearest(p, self.depth if reach is None else reach)
        s = np.full(len(p), np.inf)
        n = np.zeros((len(p), 3))
        signed_triangle_distance(p, tri, bary, d, self.vertices, self.triangles, True, s, n)
        return s, n

    def surface(self):
        return self.vertices, self.triangles


def set_pieces(pieces) -> list:
    """StaticMesh systems of geometry.setpieces Pieces (drawn and exported; collidable where
    a scene connects a contact)."""
    return [StaticMesh(p.name, p.verts, p.tris, color=p.color, material=p.material)
            for p in pieces]
