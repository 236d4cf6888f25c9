"""A garment mesh's quality (issue 16): the checks that refuse what cannot be worn
(non-manifold, too coarse, deeper inside the body than dressing fixes), loading a garment
from a file with its vertex groups, and the repairs the cutter applies after sewing
(splitting long edges, evening out short ones)."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .mesh import edges as mesh_edges
from .mesh import validate


def even_out(x, t, lo, hi, passes: int = 300):
    """Positions moved so that every edge's length is within [lo, hi] (m), as nearly as
    ``passes`` Jacobi passes of position-based length constraints reach (each edge outside
    the range moves its two ends half the excess each, averaged over the edges at a point)."""
    e, _, _ = mesh_edges(t)
    x = np.array(x, float)
    for _ in range(passes):
        d = x[e[:, 1]] - x[e[:, 0]]
        length = np.linalg.norm(d, axis=1)
        target = np.clip(length, lo, hi)
        bad = np.abs(target - length) > 1e-6 * hi
        if not bad.any():
            break
        corr = ((length - target) / np.maximum(length, 1e-12))[:, None] * d * 0.5
        corr[~bad] = 0.0
        move = np.zeros_like(x)
        count = np.zeros(len(x))
        np.add.at(move, e[:, 0], corr)
        np.add.at(move, e[:, 1], -corr)
        np.add.at(count, e[bad].ravel(), 1.0)
        x += move / np.maximum(count, 1.0)[:, None]
    return x


def split_long_edges(x, t, groups, rings, max_len):
    """Split every edge longer than max_len (m) at its middle, each of its one or two
    triangles into two (winding kept), until none is: the mesh stays manifold with the same
    openings. A new vertex joins each group holding both ends; an elastic ring's edge is
    replaced by its halves."""
    x, t = np.array(x, float), np.array(t, np.int64)
    groups = {k: set(np.asarray(v).tolist()) for k, v in groups.items()}
    ring_sets = [({tuple(sorted(map(int, e))) for e in r}, f) for r, f in rings]
    for _ in range(20):
        half = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
        length = np.linalg.norm(x[half[:, 0]] - x[half[:, 1]], axis=1)
        long = np.flatnonzero(length > max_len)
        if len(long) == 0:
            break
        owner = np.tile(np.arange(len(t)), 3)
        by_edge: dict = {}
        for h in long[np.argsort(-length[long])]:
            by_edge.setdefault((int(half[h, 0]), int(half[h, 1])), []).append(int(owner[h]))
        busy, new_tris, new_x = set(), [], []
        drop = np.zeros(len(t), bool)
        for (a, b), tris in by_edge.items():
            # every triangle of the edge (found from any half-edge, long or not)
            if any(k in busy for k in tris):
                continue
            m = len(x) + len(new_x)
            new_x.append(0.5 * (x[a] + x[b]))
            for k in tris:
                busy.add(k)
                drop[k] = True
                p, q, r = t[k]
                while {p, q} != {a, b}:
                    p, q, r = q, r, p
                new_tris += [[p, m, r], [m, q, r]]
            for gset in groups.values():
                if a in gset and b in gset:
                    gset.add(m)
            for es, _ in ring_sets:
                if (a, b) in es:
                    es.discard((a, b))
                    es |= {tuple(sorted((a, m))), tuple(sorted((m, b)))}
        # an edge's second triangle may hold it only through a short half-edge: the pass
        # above found triangles by long half-edges, and both halves of a shared edge are long
        x = np.concatenate([x, np.array(new_x)])
        t = np.concatenate([t[~drop], np.array(new_tris, np.int64)])
    groups = {k: np.array(sorted(v), np.int64) for k, v in groups.items()}
    rings = [(np.array(sorted(es), np.int64).reshape(-1, 2), f) for es, f in ring_sets]
    return x, t, groups, rings


def boundary_loops(triangles) -> list[np.ndarray]:
    """The mesh's boundary loops (vertex index cycles) of edges used by one triangle."""
    e, counts, _ = mesh_edges(np.asarray(triangles, np.int64))
    b = e[counts == 1]
    nxt: dict = {}
    for i, j in b:
        nxt.setdefault(int(i), []).append(int(j))
        nxt.setdefault(int(j), []).append(int(i))
    seen, loops = set(), []
    for start in nxt:
        if start in seen:
            continue
        loop, prev, cur = [start], None, start
        seen.add(start)
        while True:
            cand = [v for v in nxt[cur] if v != prev and (v not in seen or v == start)]
            if not cand:
                break
            prev, cur = cur, cand[0]
            if cur == start:
                break
            loop.append(cur)
            seen.add(cur)
        loops.append(np.array(loop))
    return loops


def check_garment(g, surface=None, max_edge: float | None = None):
    """ParameterError naming the element unless the garment is a valid, manifold cloth mesh
    fine enough for the body: every edge used by one or two triangles, every vertex's
    triangles one fan (no bow-tie vertex), no edge longer than ``max_edge`` (default: the
    1.5 x the thinnest limb it covers, its capsule radius: a triangle can bridge no more)."""
    x, t = validate(g.vertices, g.triangles, g.name)
    e, counts, _ = mesh_edges(t)
    bad = np.flatnonzero(counts > 2)
    if len(bad):
        i, j = e[bad[0]]
        raise ParameterError(f"garment {g.name}: edge ({i}, {j}) is shared by {counts[bad[0]]} "
                             "triangles; a cloth mesh must be manifold (at most two per edge): "
                             "split the seam or remove the extra face")
    # bow-tie vertices: a vertex on more boundary edges than two
    be = e[counts == 1].ravel()
    if len(be):
        vb, nb = np.unique(be, return_counts=True)
        if (nb > 2).any():
            v = int(vb[np.argmax(nb > 2)])
            raise ParameterError(f"garment {g.name}: vertex {v} joins two separate fans of "
                                 "triangles (a non-manifold vertex); split it into two vertices")
    length = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)
    if max_edge is None and surface is not None:
        from .body_surface import segment_distances
        d = segment_distances(x, surface.solids, surface.pos0, surface.rot0)
        covered = np.unique(np.argmin(d, axis=1))
        radii = [float(surface.plan[k].shape[1]) for k in covered
                 if surface.plan[k].shape[0] == "capsule"]
        max_edge = 1.5 * min(radii) if radii else None
    if max_edge is not None and length.max() > max_edge:
        k = int(np.argmax(length))
        raise ParameterError(f"garment {g.name}: edge ({e[k, 0]}, {e[k, 1]}) is "
                             f"{length[k] * 100:.1f} cm long, too coarse for this body (at most "
                             f"{max_edge * 100:.1f} cm, so a triangle cannot bridge a limb); "
                             "refine the mesh")
    return g


def load_garment(path, fabric=None, groups: dict | None = None, surface=None,
                 name: str | None = None):
    """A garment from a mesh file (OBJ/PLY/STL: geometry.mesh.load) in the body's A-pose, with
    named vertex groups (name -> indices, e.g. {"pinned": [...], "waistband": [...]}); with a
    surface, refused when the garment crosses into the body beyond what dressing fixes
    (a vertex more than ``DRESS_DEPTH`` inside)."""
    from .garment import FABRICS, Garment
    from .mesh import load
    fabric = FABRICS["cotton_jersey"] if fabric is None else fabric
    x, t = load(path, name)
    g = Garment(name or str(path), x, t, fabric, {k: np.asarray(v, np.int64)
                                                   for k, v in (groups or {}).items()})
    for key, idx in g.groups.items():
        if len(idx) and (idx.min() < 0 or idx.max() >= len(x)):
            raise ParameterError(f"garment {g.name}: group {key!r} names vertex "
                                 f"{int(idx.max() if idx.max() >= len(x) else idx.min())}, "
                                 f"outside 0..{len(x) - 1}")
    check_garment(g, surface)
    if surface is not None:
        check_start(g, surface)
    return g


#: m: a garment vertex this far inside the body cannot be dressed out (it may be on the wrong
#: side of a limb)
DRESS_DEPTH = 0.02


def check_start(g, surface) -> None:
    """ParameterError naming the deepest vertex when the garment starts deeper than
    DRESS_DEPTH inside the body."""
    d = surface.sdf(g.vertices)
    k = int(np.argmin(d))
    if d[k] < -DRESS_DEPTH:
        raise ParameterError(f"garment {g.name}: vertex {k} starts {-d[k] * 100:.1f} cm inside "
                             f"the body (at most {DRESS_DEPTH * 100:.0f} cm can be dressed "
                             "out); place the garment around the body in its A-pose")
