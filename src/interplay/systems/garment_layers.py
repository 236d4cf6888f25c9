"""Garments kept apart from themselves and from each other (issue 16: zero garment
self-intersections), at the position level, in the same projection that keeps them off the
skin (interactions/skin_contact._Projector): kernels/cloth_layers.py.

At each step's start every point has its nearest triangles of the garments (those of its
own neighbourhood apart; found anew every REFRESH steps) and the side it must stay on: for
two garments worn one over the other, the outer one's point outside the inner one's triangle
along the skin's normal (the tee over the pants: a hem that has slipped inside the waist is
moved out); for one garment's cloth over two limbs (one pants leg against the other, a
sleeve against the side), its own limb's cloth nearer that limb; within a fold over one limb
the side it is on. At the step's end, before the skin contact, each point is held on that
side, ``thickness`` off the triangle: the skin contact and the stretch limit (held off the
skin by its half-spaces) come after, so where the body leaves no room for two layers (the
inner thighs) they touch or cross; no layer is pushed into the skin (pushed after the skin
contact, the pants crossed the thighs' skin in 4 of 43 frames, 39 pairs at worst).

The thickness (8 mm on the runner) is far more than the fabrics' (0.6-2 mm): the projection
is point-triangle only, and with edges 1.4-1.6 cm long two layers' edges slip through each
other between points kept a few millimetres apart; half a spacing keeps most of them apart
(docs/clothing.md: the runner's self-crossings at 1.5, 3, 5, 8 and 12 mm).
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix, identity
from scipy.spatial import cKDTree

from ..errors import ParameterError
from ..geometry.aabb_tree import AABBTree
from ..geometry.body_surface import LIMBS
from ..kernels import cloth_layers as CL

#: candidate triangles kept per point: a point between two folds of one garment and the
#: other garment meets three
CANDIDATES = 4
#: the candidates are gathered every REFRESH steps (the tree query is most of the layers'
#: cost), their sides every step: within the radius's reach over two steps of 1/240 s
REFRESH = 2


class Layers:
    """The layers of a Garments network (systems/garments.py) worn on ``surface`` (a
    geometry.body_surface.BodySurface; its garments cut in its A-pose): ``thickness`` (m)
    the gap kept between a point and a triangle of the garments; ``reach`` (m) how much
    farther than that a point's triangles are looked for (more than the layers close in on
    each other between two gatherings); ``passes`` Gauss-Seidel passes a step; ``step`` (m)
    the largest move of one correction (a crossing deeper than that is undone over several
    passes); covers: garment name -> the limbs it is worn over
    (geometry.body_surface.LIMBS; all if absent)."""

    def __init__(self, net, surface, thickness: float = 0.008, reach: float = 0.002,
                 passes: int = 4, step: float = 0.001, covers: dict | None = None):
        if not (thickness > 0.0 and reach > 0.0):
            raise ParameterError(f"{net.name}: layers need a thickness and a reach > 0, got "
                                 f"thickness {thickness} m, reach {reach} m")
        radius = thickness + reach
        self.net = net
        self.thickness, self.radius, self.passes, self.step = thickness, radius, passes, step
        tris = np.ascontiguousarray(net.triangles, np.int64)
        n = len(net.x)
        # each point's neighbourhood: the points within two edges of it (itself included).
        # Not one: where the cut folds a sliver onto itself two points across an edge lie a
        # fraction of a millimetre apart, and held apart they strain that edge's bending
        # spring 20-fold
        e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
        rows, cols = np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]]
        adj = (coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)).tocsr()
               + identity(n, format="csr"))
        ring = (adj @ adj).tocsr()
        ring.sort_indices()
        layer = np.zeros(n, np.int64)
        for k, idx in enumerate(net.parts.values()):  # the garments in the order put on
            layer[idx] = k
        # each point's limb: its nearest skin vertex's where it was cut, among the limbs its
        # garment covers (a tee's hem hangs beside the thighs: it is the trunk's)
        skin = surface.vertex_limbs()
        limb = np.full(n, -1, np.int64)
        for name, idx in net.parts.items():
            names = (covers or {}).get(name, tuple(LIMBS))
            on = np.flatnonzero(np.isin(skin, [list(LIMBS).index(k) for k in names]))
            nearest = cKDTree(surface.vertices0[on]).query(net.garment.vertices[idx])[1]
            limb[idx] = skin[on[nearest]]
        self.mesh = CL.Mesh(tris, ring.indptr.astype(np.int64), ring.indices.astype(np.int64),
                            layer, limb)
        self.tree = AABBTree(net.x, tris, owner=f"{net.name} layers")
        self.tri = np.full((n, CANDIDATES), -1, np.int64)
        self.side = np.zeros((n, CANDIDATES))
        self.age = 0  # steps since the candidates were gathered

    def start(self, nrm=None, limb=None) -> None:
        """At the step's start: each point's triangles and sides. nrm (n,3), limb (n,)
        int64: the skin's outward normal at each point's nearest skin point, and its limb
        (geometry.body_surface.LIMBS; -1 where none was found; None: every side is the side
        a point is on)."""
        x = self.net.x
        if nrm is None:
            nrm, limb = np.zeros_like(x), np.full(len(x), -1, np.int64)
        if self.age % REFRESH == 0:
            self.tree.refit(x)
            CL.gather(x, self.radius, self.tree.tree, self.mesh, self.tri)
        self.age += 1
        CL.sides(x, self.mesh, CL.Body(nrm, limb), self.tri, self.side)

    def capture(self) -> dict:
        """What the next steps depend on: the candidates and the steps since they were
        found."""
        return {"layers_tri": self.tri.copy(), "layers_age": np.array([self.age])}

    def restore(self, snap) -> None:
        self.tri[:] = snap["layers_tri"]
        self.age = int(np.asarray(snap["layers_age"]).ravel()[0])

    def project(self, h: float) -> None:
        """At the step's end (h, s): hold the sides found at its start."""
        net = self.net
        w = np.where(net.fixed, 0.0, 1.0 / net.m)
        CL.project(net.x, net.v, w, self.mesh, self.tri, self.side, self.thickness,
                   self.step, self.passes, h)
