"""A figure's skin: one smooth, closed triangle mesh over its 17 segments, skinned to them
(issue 16; SPEC 4's clothing row: garments collide with "the actor's polygonal model").

Built once per body plan:

1. **An implicit body** in a rest pose of its own (the *A-pose*: arms abducted ``arm_abduction``,
   legs ``leg_abduction``, so no limb touches the torso or the other limb and a garment fits
   around each): every segment is a smooth solid of its tissue (tapered round cones for the
   limbs, the capsule radii of ``anthropometry`` scaled by TAPER; rounded boxes for the pelvis,
   torso, feet and toes; an ellipsoid head on a neck; shoulder pads joining the arms to the
   chest), joined by a smooth union (polynomial smooth minimum of radius ``blend``, Quilez).
2. **Meshed** by marching tetrahedra on a grid of ``spacing`` (Kuhn's six tetrahedra per
   cube, which tile space consistently: the zero set of a field that is nowhere exactly zero
   on the grid is a closed 2-manifold, each triangle wound with the outside to its normal),
   then relaxed: umbrella smoothing, each vertex projected back onto the zero set (Newton along
   the field's gradient).
3. **Skinned** by linear blend skinning: a vertex follows x = sum_k w_k (R_k R0_k^T (x0 - p0_k)
   + p_k) of the segments' poses (R_k, p_k) against the A-pose (R0_k, p0_k). Weights
   w_k ~ exp(-(d_k - d_min) / skin_width) from the distance d_k to each segment's solid, over
   the nearest segment and its parent and children only (so the inner thighs never share a
   vertex), then smoothed over the mesh (``weight_spread``): the surface bends
   smoothly at the joints and never cracks, as every vertex is one point moved by a convex
   combination of rigid motions.
4. **Kept apart where limbs meet** (``contact_gap``): linear blending lets two limbs' skins
   pass through each other where they touch (the inner thighs as the legs pass). A vertex
   that lies within CONTACT_REACH of the solid of another limb it is not joined to (a leg
   and the other leg or an arm; not a leg and the pelvis) in the A-pose is, once posed,
   kept at least ``contact_gap`` (or its A-pose distance, if nearer) outside that solid,
   pushed out along the solid's gradient: soft tissue pressed flat against its neighbour,
   both sides the same way, so the two skins meet without crossing.

It works for any system with the RigidParts poses of the 17 segments (Figure, MocapFigure):
``pose(seg_pos, seg_rot)`` gives the world vertices. ``BodySurface.sdf`` is the A-pose body's
signed distance (m, negative inside): garments are fitted against it (geometry/garment.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..params import param
from .anthropometry import SEGMENTS, BodyParams, body_plan
from .skinning import Skinning

#: the body's limbs: a skin vertex belongs to the one that holds most of its weight
LIMBS = {"trunk": ("pelvis", "torso", "head"),
         "l_arm": ("l_upper_arm", "l_forearm", "l_hand"),
         "r_arm": ("r_upper_arm", "r_forearm", "r_hand"),
         "l_leg": ("l_thigh", "l_shank", "l_foot", "l_toes"),
         "r_leg": ("r_thigh", "r_shank", "r_foot", "r_toes")}
CONTACT_REACH = 0.06  # m: how near another limb's solid an A-pose vertex is watched
CONTACT_PASSES = 3  # pushes, each followed by a smoothing pass, before the last push
#: limb round-cone radii as multiples of the segment's capsule radius (proximal, distal):
#: limbs taper towards the wrist and ankle (a capsule of one radius is a mannequin's limb)
TAPER = {"upper_arm": (1.05, 0.8), "forearm": (0.95, 0.65), "hand": (0.75, 0.7),
         "thigh": (1.12, 0.64), "shank": (1.15, 0.6)}


@dataclass(frozen=True)
class SurfaceParams:
    """spacing: the meshing grid (m; triangles come out about this size); blend: smooth-union
    radius (m) between segment solids; arm_abduction, leg_abduction: the A-pose the skin is
    meshed in (deg from hanging); skin_width: the distance scale (m) over which a vertex's
    weight passes from one segment to the next; weight_spread (m): how far the weights are
    smoothed over the mesh ((weight_spread / spacing)^2 umbrella passes, a diffusion that
    spreads about sqrt(passes) edges: the same bend on any grid; 8 passes at 2.5 cm let a
    thigh fold on itself at deep hip flexion); smoothing: umbrella passes over the vertices,
    each followed by a projection onto the surface (16 leave the A-pose mesh free of
    crossings at 2.5 cm, 4 did not); contact_gap (m): the least gap kept between a limb's
    skin and another limb's solid where they meet (0: plain linear blend skinning)."""
    spacing: float = param(0.018, "m", ge=0.004, le=0.1, cost=("points", -2))
    blend: float = param(0.025, "m", ge=0.0, le=0.2)
    arm_abduction: float = param(40.0, "deg", ge=0.0, le=90.0)
    leg_abduction: float = param(6.0, "deg", ge=0.0, le=30.0)
    skin_width: float = param(0.02, "m", gt=0.0, le=0.5)
    weight_spread: float = param(0.14, "m", ge=0.0, le=1.0)
    smoothing: int = param(16, "passes", ge=0, le=50)
    contact_gap: float = param(0.002, "m", ge=0.0, le=0.05)


def _rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def a_pose(plan, arm_abduction_deg: float, leg_abduction_deg: float):
    """(positions (17,3) m, rotations (17,3,3)) of the segments in the A-pose: the rest pose
    of the plan (standing, facing +x) with the arms and legs abducted (left about +x, right
    about -x) by forward kinematics from the plan's joint offsets."""
    idx = {s.name: k for k, s in enumerate(plan)}
    pos, rot = np.zeros((len(plan), 3)), np.zeros((len(plan), 3, 3))
    arm, leg = np.radians(arm_abduction_deg), np.radians(leg_abduction_deg)
    for k, s in enumerate(plan):
        local = np.eye(3)
        if s.name in ("l_upper_arm", "r_upper_arm"):
            local = _rot_x(arm if s.name[0] == "l" else -arm)
        elif s.name in ("l_thigh", "r_thigh"):
            local = _rot_x(leg if s.name[0] == "l" else -leg)
        if s.parent is None:
            pos[k], rot[k] = s.offset, local
        else:
            p = idx[s.parent]
            pos[k] = pos[p] + rot[p] @ s.offset
            rot[k] = rot[p] @ local
    return pos, rot


# --- signed distances of the solids (local frames, points (n,3), vectorised) --------------------
def _round_cone(p, a, b, r1, r2):
    """Signed distance (m) to the round cone with spheres r1 at a and r2 at b (Quilez)."""
    ba = b - a
    l2 = float(ba @ ba)
    rr = r1 - r2
    a2 = l2 - rr * rr
    pa = p - a
    y = pa @ ba
    z = y - l2
    x2 = np.sum((pa * l2 - y[:, None] * ba) ** 2, axis=1)
    y2, z2 = y * y * l2, z * z * l2
    k = np.sign(rr) * rr * rr * x2
    far = np.sign(z) * a2 * z2 > k
    near = np.sign(y) * a2 * y2 < k
    side = (np.sqrt(np.maximum(x2 * a2 / l2, 0.0)) + y * rr) / l2 - r1
    return np.where(far, np.sqrt(x2 + z2) / l2 - r2,
                    np.where(near, np.sqrt(x2 + y2) / l2 - r1, side))


def _round_box(p, centre, half, radius):
    q = np.abs(p - centre) - (half - radius)
    return (np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
            - radius)


def _ellipsoid(p, centre, radii):
    q = (p - centre) / radii
    k0 = np.linalg.norm(q, axis=1)
    k1 = np.linalg.norm(q / radii, axis=1)
    return k0 * (k0 - 1.0) / np.maximum(k1, 1e-12)


def solids(plan) -> list[list[tuple]]:
    """Per segment, its solids in its own frame: ("cone", a, b, r1, r2) | ("box", centre, half,
    rounding) | ("ellipsoid", centre, radii). Limbs from their capsules (TAPER), the trunk and
    feet from their boxes, the head from its sphere (narrower than deep than tall) plus a neck,
    and a shoulder pad on the torso towards each shoulder joint."""
    out = []
    idx = {s.name: k for k, s in enumerate(plan)}
    for s in plan:
        kind = s.shape[0]
        base = s.name.split("_", 1)[-1] if s.name[:2] in ("l_", "r_") else s.name
        items = []
        if kind == "capsule":
            r = float(s.shape[1])
            f0, f1 = TAPER[base]
            end = s.bone * (0.85 if base == "hand" else 1.0)
            items.append(("cone", np.zeros(3), end, f0 * r, f1 * r))
        elif kind == "box":
            half, c = np.asarray(s.shape[1], float), np.asarray(s.shape[2], float)
            items.append(("box", c, half, 0.9 * float(min(half[0], half[1], half[2]))))
        else:
            r, c = float(s.shape[1]), np.asarray(s.shape[2], float)
            items.append(("ellipsoid", c, np.array([0.8, 0.68, 0.92]) * r))
            items.append(("cone", np.array([0.0, 0.0, -0.03]), c * 0.6, 0.42 * r, 0.42 * r))
        if s.name == "pelvis":
            # the waist: fills the pinch between the rounded pelvis and torso boxes
            half = np.asarray(s.shape[1], float)
            top = float(s.shape[2][2] + half[2])
            items.append(("box", np.array([0.0, 0.0, top]), np.array([0.9 * half[0],
                          0.88 * half[1], 0.05]), 0.8 * half[0]))
        if s.name == "torso":
            top = float(s.shape[2][2] + s.shape[1][2])
            for arm in ("l_upper_arm", "r_upper_arm"):
                j = plan[idx[arm]].offset
                ra = float(plan[idx[arm]].shape[1])
                items.append(("cone", np.array([0.0, 0.45 * j[1], top - 1.1 * ra]), j.copy(),
                              1.1 * ra, 1.1 * ra))
        out.append(items)
    return out


def _solid_distance(p, item):
    if item[0] == "cone":
        return _round_cone(p, *item[1:])
    if item[0] == "box":
        return _round_box(p, *item[1:])
    return _ellipsoid(p, *item[1:])


def smooth_min(a, b, k):
    """Polynomial smooth minimum of radius k (m): min(a, b) away from |a - b| < k."""
    if k <= 0:
        return np.minimum(a, b)
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * k / 4.0


def segment_limbs(names) -> np.ndarray:
    """(17,) the limb (index into LIMBS) each named segment belongs to."""
    return np.array([next(i for i, parts in enumerate(LIMBS.values()) if n in parts)
                     for n in names])


def solid_distance(local, items) -> np.ndarray:
    """(n,) signed distance (m) of points in a segment's frame to the union of its solids."""
    return np.min([_solid_distance(local, it) for it in items], axis=0)


def central_gradient(f, p, eps: float) -> np.ndarray:
    """(n,3) central-difference gradient of a field f(points (n,3)) -> (n,) at points p."""
    g = np.empty_like(p)
    for a in range(3):
        d = np.zeros(3)
        d[a] = eps
        g[:, a] = (f(p + d) - f(p - d)) / (2 * eps)
    return g


def solid_gradient(local, items, eps: float = 1e-5) -> np.ndarray:
    """(n,3) gradient of ``solid_distance`` (unit length off the surface)."""
    return central_gradient(lambda q: solid_distance(q, items), local, eps)


def segment_distances(points, plan_solids, pos, rot) -> np.ndarray:
    """(n,17) signed distance (m) of world points to each segment's solids posed at (pos, rot)."""
    out = np.empty((len(points), len(plan_solids)))
    for k, items in enumerate(plan_solids):
        out[:, k] = solid_distance((points - pos[k]) @ rot[k], items)
    return out


def body_distance(points, plan_solids, pos, rot, blend) -> np.ndarray:
    """(n,) signed distance (m, negative inside) of the smooth union of all segments."""
    d = segment_distances(points, plan_solids, pos, rot)
    out = d[:, 0]
    for k in range(1, d.shape[1]):
        out = smooth_min(out, d[:, k], blend)
    return out


# --- marching tetrahedra ------------------------------------------------------------------------
_CORNERS = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])  # bit = 4i+2j+k
_KUHN = []
for _perm in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
    _c = [0]
    _step = np.zeros(3, int)
    for _ax in _perm:
        _step[_ax] = 1
        _c.append(int(4 * _step[0] + 2 * _step[1] + _step[2]))
    _KUHN.append(_c)
_KUHN = np.array(_KUHN)  # (6,4) corner ids, every tet on the cube's main diagonal


def marching_tetrahedra(field, origin, spacing):
    """Closed triangle surface of the zero set of a grid field (nx,ny,nz) (negative inside)
    with samples at origin + spacing * (i,j,k): (vertices (n,3), triangles (m,3) wound with
    the outside to their normal). The field must be positive on the grid's border."""
    f = np.array(field, dtype=float)
    tiny = 1e-9 * spacing
    f[np.abs(f) < tiny] = tiny  # no sample exactly on the surface: the zero set is a manifold
    nx, ny, nz = f.shape
    flat = f.ravel()
    inside = flat < 0
    ci, cj, ck = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1),
                             indexing="ij")
    base = (ci * ny * nz + cj * nz + ck).ravel()
    offs = _CORNERS[:, 0] * ny * nz + _CORNERS[:, 1] * nz + _CORNERS[:, 2]
    nodes = base[:, None] + offs[None, :]  # (cubes, 8)
    ins = inside[nodes]
    mixed = ins.any(axis=1) & ~ins.all(axis=1)
    nodes = nodes[mixed]
    tets = nodes[:, _KUHN].reshape(-1, 4)  # (t,4) global node ids
    tin = inside[tets]
    code = tin @ np.array([1, 2, 4, 8])
    tri_edges, tri_in = [], []
    for c in range(1, 15):
        sel = tets[code == c]
        if len(sel) == 0:
            continue
        members = [i for i in range(4) if c >> i & 1]
        others = [i for i in range(4) if not c >> i & 1]
        if len(members) in (1, 3):
            lone = members[0] if len(members) == 1 else others[0]
            rest = [i for i in range(4) if i != lone]
            tri_edges.append(np.stack([np.stack([sel[:, lone], sel[:, r]], 1) for r in rest], 1))
            tri_in.append(sel)
        else:
            a, b = members
            p, q = others
            quad = [(a, p), (a, q), (b, q), (b, p)]  # a cycle around the quad
            e = [np.stack([sel[:, u], sel[:, v]], 1) for u, v in quad]
            tri_edges.append(np.stack([e[0], e[1], e[2]], 1))
            tri_edges.append(np.stack([e[0], e[2], e[3]], 1))
            tri_in += [sel, sel]
    E = np.concatenate(tri_edges)  # (m,3,2) node pairs
    T4 = np.concatenate(tri_in)  # (m,4) the tet of each triangle
    lo, hi = np.minimum(E[..., 0], E[..., 1]), np.maximum(E[..., 0], E[..., 1])
    key = lo.astype(np.int64) * len(flat) + hi
    uniq, inv = np.unique(key.ravel(), return_inverse=True)
    tris = inv.reshape(-1, 3)
    a, b = uniq // len(flat), uniq % len(flat)

    def coords(n):
        i, r = np.divmod(n, ny * nz)
        j, k = np.divmod(r, nz)
        return origin + spacing * np.stack([i, j, k], 1).astype(float)

    fa, fb = flat[a], flat[b]
    s = fa / (fa - fb)
    verts = coords(a) + s[:, None] * (coords(b) - coords(a))
    # wind each triangle with its normal away from its tet's inside corners
    tin = inside[T4]
    cin = (coords(T4.ravel()).reshape(-1, 4, 3) * tin[..., None]).sum(1) / tin.sum(1)[:, None]
    v0, v1, v2 = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    n = np.cross(v1 - v0, v2 - v0)
    flip = np.einsum("ij,ij->i", n, (v0 + v1 + v2) / 3.0 - cin) < 0
    tris[flip] = tris[flip][:, ::-1]
    return verts, tris


def vertex_neighbours(tris, n):
    """CSR (start, neighbours) of each vertex's edge neighbours."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e = np.unique(np.sort(np.concatenate([e, e[:, ::-1]]), axis=1), axis=0)
    e = np.concatenate([e, e[:, ::-1]])
    order = np.argsort(e[:, 0], kind="stable")
    e = e[order]
    start = np.searchsorted(e[:, 0], np.arange(n + 1))
    return start, e[:, 1]


def umbrella(values, start, nbr):
    """The mean of each vertex's neighbours' values."""
    sums = np.add.reduceat(values[nbr], start[:-1], axis=0)
    return sums / np.diff(start)[:, None]


def edge_use(tris) -> np.ndarray:
    """How many triangles use each undirected edge (a closed manifold: all 2)."""
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


class BodySurface:
    """The skinned surface of one body plan (see the module docstring). Lengths m.

    vertices0, triangles: the A-pose mesh; pos0, rot0: the A-pose segment poses; weights
    (n,17): skinning weights (rows sum to 1); plan: the body plan; solids: per-segment solids."""

    def __init__(self, plan, params: SurfaceParams = SurfaceParams(), name: str = "body"):
        self.name, self.plan, self.params = name, plan, params
        if len(plan) != len(SEGMENTS):
            raise ParameterError(f"{name}: a body surface needs the 17-segment plan, got "
                                 f"{len(plan)} segments")
        self.pos0, self.rot0 = a_pose(plan, params.arm_abduction, params.leg_abduction)
        self.solids = solids(plan)
        h = float(params.spacing)
        lo, hi = self._bounds()
        lo, hi = lo - 3 * h, hi + 3 * h
        shape = np.ceil((hi - lo) / h).astype(int) + 1
        g = [lo[a] + h * np.arange(shape[a]) for a in range(3)]
        P = np.stack(np.meshgrid(*g, indexing="ij"), -1).reshape(-1, 3)
        field = self.sdf(P).reshape(shape)
        v, t = marching_tetrahedra(field, lo, h)
        start, nbr = vertex_neighbours(t, len(v))
        v = self.project(v)
        # a relaxation pass moves a vertex along the surface by a fraction of an edge: one
        # Newton step brings it back to within a hair, and the last projection to the surface
        for _ in range(params.smoothing):
            v = self.project(0.5 * v + 0.5 * umbrella(v, start, nbr), iterations=1)
        v = self.project(v)
        self.vertices0, self.triangles = v, t
        self._nbr = (start, nbr)
        self.weights = self._weights(v, start, nbr)
        self.skin = Skinning(v, self.weights)
        self.contacts = self._contacts(v) if params.contact_gap > 0 else []
        # the vertices the push may move, and their neighbour lists, for the smoothing
        # between pushes (every pose: only these, not the whole mesh)
        self._watched = (np.unique(np.concatenate([idx for _, idx, _ in self.contacts]))
                         if self.contacts else np.zeros(0, np.int64))
        lists = [nbr[start[i]:start[i + 1]] for i in self._watched]
        self._watched_nbr = (np.concatenate([[0], np.cumsum([len(n) for n in lists])]),
                             np.concatenate(lists) if lists else np.zeros(0, np.int64))

    # --- geometry at the A-pose ------------------------------------------------------------------
    def _bounds(self):
        pts = []
        for k, items in enumerate(self.solids):
            for it in items:
                if it[0] == "cone":
                    ends, r = [it[1], it[2]], max(it[3], it[4])
                elif it[0] == "box":
                    ends, r = [it[1] - it[2], it[1] + it[2]], 0.0
                else:
                    ends, r = [it[1]], float(np.max(it[2]))
                for e in ends:
                    w = self.pos0[k] + self.rot0[k] @ e
                    pts += [w - r, w + r]
        pts = np.array(pts)
        return pts.min(axis=0), pts.max(axis=0)

    def sdf(self, points) -> np.ndarray:
        """Signed distance (m, negative inside) of world points from the A-pose body."""
        return body_distance(np.asarray(points, float).reshape(-1, 3), self.solids, self.pos0,
                             self.rot0, self.params.blend)

    def gradient(self, points, eps: float = 1e-4) -> np.ndarray:
        """(n,3) central-difference gradient of ``sdf`` (about unit length outside)."""
        return central_gradient(self.sdf, np.asarray(points, float), eps)

    def project(self, points, level: float = 0.0, iterations: int = 3) -> np.ndarray:
        """Points moved along the gradient onto the level set sdf = level (m) by Newton steps."""
        p = np.array(points, float)
        for _ in range(iterations):
            g = self.gradient(p)
            f = self.sdf(p) - level
            p -= (f / np.maximum(np.sum(g * g, axis=1), 1e-12))[:, None] * g
        return p

    def mesh_distance(self, points, vertices=None, reach: float = 0.1):
        """(signed distance (n,) m, outward normal (n,3)) of points from the skin mesh (at
        ``vertices``, default the A-pose): the triangles garments collide with, which lie up
        to a chord's sag off ``sdf`` (inf beyond reach)."""
        from ..kernels.skin_contact import edge_neighbours, signed_distance, vertex_normals
        from .aabb_tree import AABBTree
        X = self.vertices0 if vertices is None else np.asarray(vertices, float)
        p = np.ascontiguousarray(points, float)
        tri, d, bary = AABBTree(X, self.triangles).nearest(p, reach)
        vn = np.zeros_like(X)
        vertex_normals(X, self.triangles, vn)
        s, n = np.full(len(p), np.inf), np.zeros_like(p)
        signed_distance(p, tri, bary, d, X, self.triangles, edge_neighbours(self.triangles), vn,
                        s, n)
        return s, n

    def _weights(self, v, start, nbr) -> np.ndarray:
        d = segment_distances(v, self.solids, self.pos0, self.rot0)
        nearest = np.argmin(d, axis=1)
        allowed = np.zeros((len(SEGMENTS), len(SEGMENTS)), bool)
        idx = {s.name: k for k, s in enumerate(self.plan)}
        for k, s in enumerate(self.plan):
            allowed[k, k] = True
            if s.parent is not None:
                allowed[k, idx[s.parent]] = allowed[idx[s.parent], k] = True
        w = np.exp(-(d - d.min(axis=1, keepdims=True)) / self.params.skin_width)
        w *= allowed[nearest]
        w /= w.sum(axis=1, keepdims=True)
        for _ in range(int(round((self.params.weight_spread / self.params.spacing) ** 2))):
            w = 0.5 * w + 0.5 * umbrella(w, start, nbr)
        w[w < 1e-4] = 0.0
        return w / w.sum(axis=1, keepdims=True)

    def _contacts(self, v) -> list:
        """[(segment k, vertices (m,), least distance (m,) m)]: the vertices of other limbs
        within CONTACT_REACH of segment k's solid in the A-pose, and the distance each keeps
        from it when posed (``contact_gap``, or its A-pose distance if nearer)."""
        names = [s.name for s in self.plan]
        limb_of = segment_limbs(names)
        limb = self.vertex_limbs()
        d = segment_distances(v, self.solids, self.pos0, self.rot0)
        # limbs joined at a joint (a leg and the pelvis, an arm and the torso) overlap at it
        # by construction, and deeply when it bends (she sits: the thigh's top in the belly):
        # their meeting is the blend's, not a contact
        joined = np.eye(len(LIMBS), dtype=bool)
        for s in self.plan:
            if s.parent is not None:
                a, b = limb_of[names.index(s.name)], limb_of[names.index(s.parent)]
                joined[a, b] = joined[b, a] = True
        out = []
        for k in range(len(names)):
            near = np.flatnonzero(~joined[limb, limb_of[k]] & (d[:, k] < CONTACT_REACH))
            if len(near):
                out.append((k, near, np.minimum(self.params.contact_gap,
                                                np.maximum(d[near, k], 0.0))))
        return out

    def vertex_limbs(self) -> np.ndarray:
        """(n,) each vertex's limb (index into LIMBS): the one that carries most of its
        weight."""
        limb_of = segment_limbs([s.name for s in self.plan])
        return np.stack([self.weights[:, limb_of == i].sum(axis=1)
                         for i in range(len(LIMBS))], axis=1).argmax(axis=1)

    def _keep_apart(self, X, seg_pos, seg_rot) -> np.ndarray:
        """Posed vertices X (n,3) with each watched vertex pushed out of the other limb's solid
        to its least distance (``_contacts``); between pushes the watched vertices are
        smoothed, so a pushed patch bends into its neighbours instead of folding over them."""
        if not self.contacts:
            return X
        w = self._watched
        for _ in range(CONTACT_PASSES):
            X = self._push(X, seg_pos, seg_rot)
            X[w] = 0.5 * X[w] + 0.5 * umbrella(X, *self._watched_nbr)
        return self._push(X, seg_pos, seg_rot)

    def _push(self, X, seg_pos, seg_rot) -> np.ndarray:
        for k, idx, least in self.contacts:
            local = (X[idx] - seg_pos[k]) @ seg_rot[k]
            d = solid_distance(local, self.solids[k])
            deep = np.flatnonzero(d < least)
            if len(deep):
                p = local[deep]
                g = solid_gradient(p, self.solids[k])
                p += ((least[deep] - d[deep]) / np.maximum((g * g).sum(axis=1), 1e-12))[:, None] * g
                X[idx[deep]] = p @ seg_rot[k].T + seg_pos[k]
        return X

    # --- posing ----------------------------------------------------------------------------------
    def transforms(self, seg_pos, seg_rot):
        """Per segment, (A (17,3,3), b (17,3)): x = A x0 + b carries A-pose points with it.
        Poses of parts after her 17 segments (a swing a figure shows to contacts) are not hers:
        they are ignored."""
        k = len(self.rot0)
        A = np.einsum("kij,klj->kil", np.asarray(seg_rot, float)[:k], self.rot0)
        b = np.asarray(seg_pos, float)[:k] - np.einsum("kij,kj->ki", A, self.pos0)
        return A, b

    def pose(self, seg_pos, seg_rot) -> np.ndarray:
        """World vertices (n,3) m at the segments' poses (positions (17,3), rotations
        (17,3,3)), limbs kept apart where they meet."""
        out = self.skin.positions(*self.transforms(seg_pos, seg_rot))
        return self._keep_apart(out, np.asarray(seg_pos, float), np.asarray(seg_rot, float))

    def skinning(self, points) -> Skinning:
        """Other A-pose points (a garment's) carried by the weights of their nearest skin
        vertex."""
        from scipy.spatial import cKDTree
        _, j = cKDTree(self.vertices0).query(np.asarray(points, float))
        return Skinning(points, self.weights[j])

    def velocities(self, seg_pos, seg_rot, lin, ang, centres) -> np.ndarray:
        """(n,3) m/s of the skinned vertices for segment velocities (lin at ``centres``, ang)."""
        A, b = self.transforms(seg_pos, seg_rot)
        return self.skin.velocities(A, b, lin, ang, centres)


def figure_surface(figure, params: SurfaceParams = SurfaceParams()) -> BodySurface:
    """The body surface of a figure (Figure or MocapFigure: anything with a body ``plan``)."""
    return BodySurface(figure.plan, params, name=f"{figure.name}-skin")


def surface_for(body: BodyParams = BodyParams(), params: SurfaceParams = SurfaceParams()):
    """The body surface of a person of BodyParams (mass, height)."""
    return BodySurface(body_plan(body), params)
