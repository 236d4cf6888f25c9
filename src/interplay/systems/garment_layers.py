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

That alone left 200-400 crossing triangle pairs a frame on the runner, 98% of them between
triangles within two edges of each other (tight folds the point-triangle pairs leave out),
made afresh every step by the cloth's own solve. Two things make it zero:
- **Untangling** (kernels/cloth_layers.untangle): a point whose edge has gone through a
  triangle is moved back through it, ``MARGIN`` beyond (the cut's own few crossings at the
  crotch are gone within the first steps of the dressing).
- **The guard** (``guard``, last in the step, kernels/impact_zones.py): no triangle pair that
  did not cross at the step's start crosses at its end; the points of those that do move as
  zones, first with the skin under them (in the run; not in the dressing), then rigidly
  (Provot 1997; Bridson, Fedkiw & Anderson 2002), which cannot cross. The zones' rims
  stretch: the stretch limit runs again after the guard, and the guard once more, its zones
  rigid; then the limit once more, undone where it made a crossing (``undo_new_crossings``;
  interactions/skin_contact._Projector.resolve).
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix, identity
from scipy.spatial import cKDTree

from ..errors import ParameterError
from ..geometry.aabb_tree import AABBTree
from ..geometry.body_surface import LIMBS
from ..kernels import cloth_layers as CL
from ..kernels import impact_zones as IZ

#: candidate triangles kept per point: a point between two folds of one garment and the
#: other garment meets three
CANDIDATES = 4
#: the candidates are gathered every REFRESH steps (the tree query is most of the layers'
#: cost), their sides every step: within the radius's reach over two steps of 1/240 s
REFRESH = 2
#: rounds of growing the impact zones at most (guard)
ZONE_ROUNDS = 30
#: the share of triangles moved since the last look above which all are looked at anew
FULL_LOOK = 0.3
#: rounds in which a zone's points near the skin move with it (guard)
FOLLOW_ROUNDS = 10
#: m: how far through its triangle a crossed point is moved (untangle); the layers' full
#: thickness would strain the tight folds where most crossings are
MARGIN = 0.001


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
                            net.part, limb)
        self.tree = AABBTree(net.x, tris, owner=f"{net.name} layers")
        self.tri = np.full((n, CANDIDATES), -1, np.int64)
        self.side = np.zeros((n, CANDIDATES))
        self.forced = np.zeros((n, CANDIDATES))  # the sides that undo crossings (untangle)
        self.before = np.zeros(0, np.int64)  # the crossing pairs let stand (remember, _keys)
        self._seen, self._pairs = None, np.zeros((0, 2), np.int64)  # the last look (_look)
        m = len(tris)  # each point's triangles, as rows of a sparse matrix
        self._touching = coo_matrix((np.ones(3 * m), (tris.ravel(), np.repeat(np.arange(m), 3))),
                                    shape=(n, m)).tocsr()
        self.age = 0  # steps since the candidates were gathered

    def start(self, nrm=None, limb=None) -> None:
        """At the step's start: each point's triangles and sides. nrm (n,3), limb (n,)
        int64: the skin's outward normal at each point's nearest skin point, and its limb
        (geometry.body_surface.LIMBS; -1 where none was found; None: every side is the side
        a point is on)."""
        x = self.net.x
        if nrm is None:
            nrm, limb = np.zeros_like(x), np.full(len(x), -1, np.int64)
        pairs = self.remember()
        if self.age % REFRESH == 0:
            CL.gather(x, self.radius, self.tree.tree, self.mesh, self.tri)
            CL.untangle(x, self.mesh, pairs, self.tri, self.forced)
        self.age += 1
        CL.sides(x, self.mesh, CL.Body(nrm, limb), self.tri, self.forced, self.side)

    def remember(self) -> np.ndarray:
        """The garments' crossing triangle pairs (k,2) now, remembered as the ones the guard
        lets stand."""
        pairs = self._look()
        self.before = _keys(pairs, len(self.mesh.tris))
        return pairs

    def _look(self, changed=None) -> np.ndarray:
        """The garments' crossing triangle pairs now (k,2; each once, the smaller triangle
        first): the triangles with a point moved since the last look are tested anew against
        the tree (geometry/aabb_tree.AABBTree.crossings), the pairs of the others kept; all
        anew when more than FULL_LOOK of them moved (in parallel). A zone moved by the guard
        is a few hundred triangles of 18,600: 0.3 ms to look again where a full look takes
        7 ms. Either way the pairs come in one order (sorted), so a run resumed from a
        checkpoint, whose first look is a full one, repeats the zones bit for bit. changed:
        the points that can have moved since the last look (None: any; the guard's rounds
        name their zones' points)."""
        x, tris = self.net.x, self.mesh.tris
        if self._seen is None:
            moved = np.ones(len(tris), bool)
        elif changed is None:
            moved = np.any(x != self._seen, axis=1)[tris].any(axis=1)
        else:
            moved = np.zeros(len(tris), bool)
            moved[self._touching[changed].indices] = True
        if changed is None:
            self.tree.refit(x)
        else:
            self.tree.refit_some(x, np.flatnonzero(moved))
        if moved.mean() > FULL_LOOK:
            pairs = self.tree.crossings()
        else:
            keep = self._pairs[~(moved[self._pairs[:, 0]] | moved[self._pairs[:, 1]])]
            pairs = np.unique(np.concatenate([keep, self.tree.crossings(np.flatnonzero(moved))]),
                              axis=0)
        self._seen, self._pairs = x.copy(), pairs
        return pairs

    def _new_crossings(self, changed=None) -> np.ndarray:
        """The crossing pairs now (``_look``; changed: the points moved since it last
        looked) that were not let stand at the step's start (``remember``)."""
        pairs = self._look(changed)
        return pairs[~np.isin(_keys(pairs, len(self.mesh.tris)), self.before)]

    def guard(self, x0, h: float, follow=None) -> None:
        """At the very end of the step (h, s), from the points x0 (n,3) m at its start: no
        triangle pair of the garments that did not cross at the start crosses at the end.
        The crossing triangles' points are gathered into zones (kernels/impact_zones.py),
        grown until no new crossing is left: in the first FOLLOW_ROUNDS each zone point with
        a skin point near moves as that skin point moved, ``follow`` (n,3) m (NaN where none:
        those move with the zone's best rigid fit), as cloth caught between layers is carried
        by the body; then every zone moves rigidly, which cannot cross what did not cross at
        the start (at most ZONE_ROUNDS rounds). A zone's points take the velocity of their
        move over the step."""
        net = self.net
        x = net.x
        label = np.full(len(x), -1, np.int64)
        carried = None if follow is None else ~np.isnan(follow[:, 0])
        changed = None  # the points the last round moved (None: look at all)
        for k in range(ZONE_ROUNDS):
            new = self._new_crossings(changed)
            if not len(new):
                break
            IZ.merge(self.mesh.tris, new, label)
            zone = np.flatnonzero(label >= 0)
            was = x[zone]
            IZ.move_rigidly(x0, x, net.m, net.fixed, label)
            if carried is not None and k < FOLLOW_ROUNDS:
                on = zone[carried[zone] & ~net.fixed[zone]]
                x[on] = x0[on] + follow[on]
            changed = zone[np.any(x[zone] != was, axis=1)]
        # a zone's points take its motion's velocity over the step (what the other moves of
        # the step gave them is undone with the moves: kept, it carried them through again
        # in the next step, 8 m/s in the runner's settle)
        moved = label >= 0
        net.v[moved] = (x[moved] - x0[moved]) / h

    def undo_new_crossings(self, x_safe, v_safe) -> np.ndarray:
        """After a move from x_safe (n,3) m (a state with no new crossing, velocities v_safe):
        the points of every triangle pair that came to cross go back to x_safe, until none
        is left (at worst every point: x_safe). Returns the points sent back (n,) bool."""
        x, v = self.net.x, self.net.v
        changed = None
        undone = np.zeros(len(x), bool)
        for _ in range(ZONE_ROUNDS):
            new = self._new_crossings(changed)
            if not len(new):
                return undone
            back = np.unique(self.mesh.tris[new].ravel())
            back = back[np.any(x[back] != x_safe[back], axis=1)]
            if not len(back):
                break
            x[back], v[back] = x_safe[back], v_safe[back]
            undone[back] = True
            changed = back
        x[:], v[:] = x_safe, v_safe
        undone[:] = True
        return undone

    def capture(self) -> dict:
        """What the next steps depend on: the candidates and the steps since they were
        found."""
        return {"layers_tri": self.tri.copy(), "layers_forced": self.forced.copy(),
                "layers_age": np.array([self.age])}

    def restore(self, snap) -> None:
        self.tri[:] = snap["layers_tri"]
        if "layers_forced" in snap:  # a checkpoint from before the untangling has none
            self.forced[:] = snap["layers_forced"]
        self.age = int(np.asarray(snap["layers_age"]).ravel()[0])
        self._seen = None  # the next look is a full one

    def project(self, h: float) -> None:
        """At the step's end (h, s): hold the sides found at its start."""
        net = self.net
        w = np.where(net.fixed, 0.0, 1.0 / net.m)
        CL.project(net.x, net.v, w, self.mesh, self.tri, self.side, self.forced, self.thickness,
                   MARGIN, self.step, self.passes, h)


def _keys(pairs, m: int) -> np.ndarray:
    """One integer per unordered triangle pair (k,2) of a mesh of m triangles."""
    a, b = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    return a * m + b
