"""Garments as a spring-mass network that certifies itself (issue 16), and dressing.

``Garments`` is a SpringNetwork built from a ``geometry.garment.Garment`` (one or several
joined: their contacts with each other are the network's self-contacts). Given the skin it is
worn on (``watch``), at every output frame it measures, exactly:

* cloth-body intersections: pairs of a cloth triangle and a skin triangle that interpenetrate
  (``AABBTree.intersections``: exact orientation predicates on every pair whose boxes
  overlap);
* penetration: the deepest a cloth point lies inside the skin (signed distance to the
  nearest skin triangle, m);
* self-intersections: pairs of the cloth's own triangles that interpenetrate, triangles
  sharing a vertex left out;
* stretch: the largest strain (l / l0 - 1) of each garment's structural springs, its elastic
  bands apart (they are cut to stretch);
* overstretched: the share of each garment's structural springs (bands apart) strained more
  than ``OVERSTRETCH`` (5%, a cotton tee's limit in issue 16): the largest strain is one
  spring's, this says whether it is a pinch or the garment.

Each step ends with the fabric's stretch limit (``limit_strain``, kernels/strain_limit.py):
structural springs past their fabric's limit are shortened back, after the skin contact's
projection and held off the skin by its planes when one acts (interactions/skin_contact).

``dress`` pulls a garment onto a body before t = 0: the skin moves from the A-pose the garment
was cut in to the pose of the first frame while the cloth follows under its springs, gravity,
the skin contact and its self-contacts, then settles; at the end each point takes the skin's
velocity there, so the first step does not see a body moving through still cloth.
"""
from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..geometry.aabb_tree import AABBTree
from ..kernels import strain_limit as SL
from ..kernels.skin_contact import signed_distance, vertex_normals
from .base import substeps
from .springmass import SpringNetwork, Springs

OVERSTRETCH = 0.05  # strain past which a cotton knit is visibly overstretched (issue 16)
#: most Gauss-Seidel passes of the strain limit a step (kernels/strain_limit.py): 60 keep the
#: runner's garments' pass within 1.3x of its time without the limit (docs/clothing.md)
LIMIT_SWEEPS = 60


class Garments(SpringNetwork):
    """A SpringNetwork of garments (see the module docstring); ``garment`` the Garment it was
    built from; ``parts`` (name -> point indices) and ``bands`` (spring indices of elastic
    bands)."""

    def setup(self, garment, kind):
        self.garment = garment
        self.spring_kind = kind
        self.parts = ({p.name: garment.groups[p.name] for p in garment.parts}
                      if garment.parts else {garment.name: np.arange(len(self.x))})
        # the points that ride the skin (a gripping waistband): fixed in the solve, moved
        # with the skin point they were cut on by the skin's own weights
        pins = [v for k, v in garment.groups.items() if k == "pinned" or k.endswith(".pinned")]
        self.pinned = np.unique(np.concatenate(pins)) if pins else np.zeros(0, np.int64)
        self.fixed[:] = False
        self.fixed[self.pinned] = True
        # the elastic bands: the rings cut short to grip, and every spring within the
        # waistband that rides the skin (both ends pinned: the skin stretches it, no cloth
        # force can); they stretch by design, apart in the certificates and not limited
        band = self.fixed[self.si] & self.fixed[self.sj]
        if len(garment.ring_edges):
            key = lambda p: p.min(axis=1) * len(self.x) + p.max(axis=1)  # noqa: E731
            rings = set(key(np.asarray(garment.ring_edges)).tolist())
            mine = key(np.stack([self.si, self.sj], 1))
            band |= np.array([k in rings for k in mine.tolist()])
        self.band = band & (kind == 0)
        # each structural spring's cap from its garment's fabric
        limit = np.full(len(self.x), np.inf)
        for p in (garment.parts or (garment,)):
            limit[self.parts[p.name]] = p.fabric.stretch_limit
        on = (kind == 0) & ~self.band & np.isfinite(limit[self.si])
        # each point's garment, in the order put on (the limit runs each on its own,
        # kernels/strain_limit.py; the layers tell inner from outer, garment_layers.py)
        self.part = np.zeros(len(self.x), np.int64)
        for k, idx in enumerate(self.parts.values()):
            self.part[idx] = k
        o, self.limit_start = SL.starts(self.part, self.si[on], len(self.parts))
        si, sj, cap = self.si[on][o], self.sj[on][o], (self.l0[on] * (1.0 + limit[self.si[on]]))[o]
        self.limits = SL.Limits(si, sj, cap)
        reach = self._reach(limit)
        o, self.reach_start = SL.starts(self.part, reach.idx, len(self.parts))
        self.reach = SL.Reach(reach.idx[o], reach.pin[o], reach.dist[o])
        # a skin contact runs the limit itself, after its projection (interactions/
        # skin_contact._Projector), so the two agree; otherwise the advance ends with it
        self.limit_by_contact = False
        self.limit_stats = np.zeros(3)  # passes at most, steps left over, excess left
        self._pin_skin = None  # geometry.skinning.Skinning of the pinned points, cut
        self._cut_skin = None  # and of all points (made on first use)
        self._skin = None
        self.certificates: list = []
        self._own = None
        self._near = None  # the certificate's nearest skin triangles, last frame (a hint)
        # systems/garment_layers.Layers: the garments held apart from themselves and each
        # other in the skin contact's projection (None: not)
        self.layers = None

    def advance(self, h, dt=None):
        super().advance(h, dt)
        if not self.limit_by_contact:
            # the velocity is the last substep's: x - x_n = (h / n) v
            self.limit_strain(h / substeps(h, self.dt if dt is None else dt))

    def limit_strain(self, h: float, planes=None, held=None) -> None:
        """Shorten the structural springs stretched past their fabric's limit back to it
        (kernels/strain_limit.py: Provot's correction, shared by inverse mass, so the points'
        linear momentum is kept; pinned points stay), keeping the points of ``planes`` (a
        strain_limit.Planes: a contact's half-spaces) on their outer sides; the velocities
        change by the move over the step h (s). held (n,) bool: points kept where they are,
        as the pinned ones (None: none)."""
        if not len(self.limits.i):
            return
        w = np.where(self.fixed if held is None else self.fixed | held, 0.0, 1.0 / self.m)
        planes = SL.no_planes() if planes is None else planes
        o, start = SL.starts(self.part, planes.idx, len(self.parts))
        passes, left = SL.limit_strain(self.x, self.v, w, self.limits, self.limit_start,
                                       self.reach, self.reach_start,
                                       SL.Planes(planes.idx[o], planes.n[o], planes.o[o]),
                                       start, h, LIMIT_SWEEPS)
        st = self.limit_stats
        st[0] = max(st[0], passes)
        st[1] += left > 0.0
        st[2] = max(st[2], left)

    def _reach(self, limit) -> SL.Reach:
        """Each free point's reach from its nearest pinned point (kernels/strain_limit.Reach):
        the shortest rest path to a pin along the structural springs, bands apart (never shorter
        than the cloth's own geodesic) times 1 + its limit (limit (n,) per point)."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra
        free = np.flatnonzero(~self.fixed & np.isfinite(limit))
        if not len(self.pinned) or not len(free):
            return SL.Reach(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
        on = (self.spring_kind == 0) & ~self.band  # a band's rest length is cut short
        n = len(self.x)
        graph = coo_matrix((self.l0[on], (self.si[on], self.sj[on])), shape=(n, n)).tocsr()
        dist, _, source = dijkstra(graph, directed=False, indices=self.pinned,
                                   return_predecessors=True, min_only=True)
        free = free[np.isfinite(dist[free])]
        return SL.Reach(free, source[free].astype(np.int64), dist[free] * (1.0 + limit[free]))

    def ride(self, surface, seg_pos, seg_rot, h: float) -> None:
        """Move the pinned points to where the skin carries them at the segment poses
        (positions (17,3), rotations (17,3,3)), their velocity the move over h (s)."""
        if not len(self.pinned):
            return
        if self._pin_skin is None:
            self._pin_skin = surface.skinning(self.garment.vertices[self.pinned])
        new = self._pin_skin.positions(*surface.transforms(seg_pos, seg_rot))
        self.v[self.pinned] = (new - self.x[self.pinned]) / h
        self.x[self.pinned] = new

    def skinned(self, surface, seg_pos, seg_rot) -> np.ndarray:
        """Where the skin's weights carry each garment point from the A-pose it was cut in
        (n,3) m: the garment's skinned reference."""
        if self._cut_skin is None:
            self._cut_skin = surface.skinning(self.garment.vertices)
        return self._cut_skin.positions(*surface.transforms(seg_pos, seg_rot))

    def tether(self, surface, seg_pos, seg_rot, radius: float) -> int:
        """Keep every point within ``radius`` (m) of its skinned reference (the maximum
        distance constraint of character cloth: NVIDIA's APEX/NvCloth, after Kim, Chentanez
        & Mueller 2012, "Long range attachments"): a point farther is moved back onto the
        sphere and its velocity away from the reference removed. It leaves the garment free
        to swing and fold within the radius, and no point can be carried off by a pinch or
        left behind a limb. Returns the points moved."""
        if not radius > 0:
            return 0
        ref = self.skinned(surface, seg_pos, seg_rot)
        d = self.x - ref
        dist = np.linalg.norm(d, axis=1)
        out = dist > radius
        if out.any():
            u = d[out] / dist[out, None]
            self.x[out] = ref[out] + radius * u
            vr = np.einsum("ij,ij->i", self.v[out], u)
            self.v[out] -= np.maximum(vr, 0.0)[:, None] * u
        return int(out.sum())

    def watch(self, skin) -> None:
        """Certify every output frame against this PosedSkin (interactions.skin_contact)."""
        self._skin = skin
        self._body_tree = AABBTree(skin.now()[0], skin.tris, owner=f"{skin.figure.name} skin")

    def stretch(self) -> tuple[dict, dict]:
        """({part: largest structural strain}, elastic bands apart as "<part> bands";
        {part: share of its structural springs, bands apart, strained more than
        OVERSTRETCH})."""
        d = np.linalg.norm(self.x[self.si] - self.x[self.sj], axis=1)
        strain = d / self.l0 - 1.0
        largest, share = {}, {}
        for name, idx in self.parts.items():
            on = np.zeros(len(self.x), bool)
            on[idx] = True
            mine = on[self.si] & (self.spring_kind == 0)
            cloth = strain[mine & ~self.band]
            largest[name] = float(cloth.max())
            share[name] = float(np.mean(cloth > OVERSTRETCH))
            if (mine & self.band).any():
                largest[f"{name} bands"] = float(strain[mine & self.band].max())
        return largest, share

    def certify(self, t: float) -> dict:
        """The frame's certificates at time t (s) against the watched skin."""
        skin = self._skin
        X, _ = skin.at(t, 0.0) if hasattr(skin.figure, "pose_at") else skin.now()
        self._body_tree.refit(X)
        if self._own is None:
            self._own = AABBTree(self.x, self.triangles, owner=self.name)
        else:
            self._own.refit(self.x)
        crossing = len(self._body_tree.intersections(self._own))
        tri, d, bary = self._body_tree.nearest(self.x, 0.05, hint=self._near)
        self._near = tri
        s, n = np.full(len(self.x), np.inf), np.zeros_like(self.x)
        vn = np.zeros_like(X)
        vertex_normals(X, skin.tris, vn)
        signed_distance(self.x, tri, bary, d, X, skin.tris, skin.across, vn, s, n)
        depth = float(max(0.0, -s.min()))
        selfx = len(self._own.intersections())
        largest, share = self.stretch()
        return {"t": float(t), "cloth_body_intersections": int(crossing),
                "penetration_m": depth, "self_intersections": int(selfx),
                "stretch": largest, "overstretched": share}

    def frame(self):
        if self._skin is not None:
            self.certificates.append(self.certify(self.time))
        return super().frame()

    def frame_size(self) -> int:
        # the network's frame, without a certificate: the estimate is not a frame
        return sum(np.asarray(v).size for v in super().frame().values())

    def extra_diagnostics(self) -> dict:
        out = dict(super().extra_diagnostics())
        st = self.limit_stats
        out["strain_limit"] = {"passes_max": int(st[0]), "steps_left_over": int(st[1]),
                               "excess_left_max": float(st[2])}
        if self.certificates:
            c = self.certificates
            out["certificates"] = {
                "frames": len(c),
                "cloth_body_intersections_max": max(f["cloth_body_intersections"] for f in c),
                "penetration_max_m": max(f["penetration_m"] for f in c),
                "self_intersections_max": max(f["self_intersections"] for f in c),
                "stretch_max": {k: max(f["stretch"][k] for f in c) for k in c[0]["stretch"]},
                "overstretched_max": {k: max(f["overstretched"][k] for f in c)
                                      for k in c[0]["overstretched"]},
                "per_frame": c}
        return out

    def capture(self):
        """The network's state and the certificates so far (one row per frame: t,
        crossings, penetration, self-crossings, then each stretch key's value, then each
        overstretched key's)."""
        snap = super().capture()
        snap["limit_stats"] = self.limit_stats.copy()
        if self.layers is not None:
            snap.update(self.layers.capture())
        c0 = self.certificates[0] if self.certificates else {"stretch": {}, "overstretched": {}}
        keys, share = sorted(c0["stretch"]), sorted(c0["overstretched"])
        rows = [[c["t"], c["cloth_body_intersections"], c["penetration_m"],
                 c["self_intersections"], *(c["stretch"][k] for k in keys),
                 *(c["overstretched"][k] for k in share)]
                for c in self.certificates]
        snap["cert"] = np.array(rows, float).reshape(len(rows), 4 + len(keys) + len(share))
        snap["cert_keys"] = np.array(keys, dtype=str)
        snap["cert_share_keys"] = np.array(share, dtype=str)
        return snap

    def restore(self, snap):
        snap = dict(snap)
        rows, keys = snap.pop("cert", None), snap.pop("cert_keys", None)
        share = snap.pop("cert_share_keys", None)
        self.limit_stats[:] = snap.pop("limit_stats", np.zeros(3))
        layers = {k: snap.pop(k) for k in ("layers_tri", "layers_forced", "layers_age")
                  if k in snap}
        if self.layers is not None and layers:
            self.layers.restore(layers)
        super().restore(snap)
        if rows is not None:
            keys = [str(k) for k in np.asarray(keys).ravel()]
            # a checkpoint written before the overstretched certificate has no share keys
            share = [] if share is None else [str(k) for k in np.asarray(share).ravel()]
            n = 4 + len(keys)
            self.certificates = [
                {"t": float(r[0]), "cloth_body_intersections": int(r[1]),
                 "penetration_m": float(r[2]), "self_intersections": int(r[3]),
                 "stretch": {k: float(v) for k, v in zip(keys, r[4:n])},
                 "overstretched": {k: float(v) for k, v in zip(share, r[n:])}}
                for r in np.asarray(rows, float).reshape(-1, n + len(share))]


def _slerp(R0, R1, f):
    from scipy.spatial.transform import Rotation
    out = np.empty_like(R0)
    for k in range(len(R0)):
        rel = Rotation.from_matrix(R1[k] @ R0[k].T).as_rotvec()
        out[k] = Rotation.from_rotvec(f * rel).as_matrix() @ R0[k]
    return out


def dress(net: Garments, surface, seg_pos, seg_rot, seconds: float = 0.8,
          settle: float = 0.4, h: float | None = None, contact=None, self_contact=None,
          skin_velocity=None, damping: float = 4.0, tether: float = 0.0,
          settle_with=()) -> dict:
    """Dress the network (cut in the surface's A-pose) on the body posed at (seg_pos (17,3),
    seg_rot (17,3,3)): ``seconds`` of the skin moving there from the A-pose (rotations by
    slerp, positions linearly, eased in and out; 0: the garment carried there by the skin's
    weights at once), then ``settle`` seconds at rest, with mass
    damping ``damping`` (1/s) on top of the cloth's own; contact: a SkinContactParams;
    self_contact: an interaction (SelfContact) exchanged every step; skin_velocity (nb,3)
    m/s: the skin's velocity at the target pose, given to the cloth at the end; tether (m): the
    points kept within it of their skinned reference (``Garments.tether``); settle_with:
    interactions on the garment exchanged in the settling steps only (colliders the garment
    is moved through while the body moves, e.g. the seat she sits down on). Returns what it
    measured at the end (intersections, penetration, steps)."""
    from ..interactions.skin_contact import SkinContactParams, _Projector
    h = net.dt if h is None else h
    contact = SkinContactParams() if contact is None else contact
    proj = _Projector(net, surface.triangles, contact, surface.vertices0,
                      surface.vertex_limbs(), carry=False)
    alpha = net.alpha
    net.alpha = alpha + damping
    steps_move = max(1, int(round(seconds / h))) if seconds > 0 else 1
    steps_settle = int(round(settle / h))
    seg_pos, seg_rot = np.asarray(seg_pos, float), np.asarray(seg_rot, float)
    if seconds <= 0:
        # placed by the skin itself: the garment's A-pose points carried to the target by
        # the skin's weights at each (as a sleeve goes with its arm), then settled against
        # the skin; its rest lengths stay the cut ones, so what the carrying stretched
        # relaxes while it settles
        net.x[:] = net.skinned(surface, seg_pos, seg_rot)
        net.v[:] = 0.0
        pos0, rot0 = seg_pos, seg_rot
    else:
        # carry the garment rigidly with the pelvis to the target first: dressing then moves
        # the limbs only, relative to the trunk
        Rp = seg_rot[0] @ surface.rot0[0].T
        tp = seg_pos[0] - Rp @ surface.pos0[0]
        net.x[:] = net.x @ Rp.T + tp
        net.v[:] = 0.0
        rot0 = np.einsum("ij,kjl->kil", Rp, surface.rot0)
        pos0 = surface.pos0 @ Rp.T + tp
    prev = surface.pose(pos0, rot0)
    net.ride(surface, pos0, rot0, h)
    net.v[net.pinned] = 0.0
    for it in settle_with:
        it.prepare(h)
    try:
        for k in range(1, steps_move + steps_settle + 1):
            f = min(1.0, k / steps_move)
            e = f * f * (3 - 2 * f)  # smoothstep: starts and stops at rest
            R = _slerp(rot0, seg_rot, e)
            P = pos0 + e * (np.asarray(seg_pos) - pos0)
            X = surface.pose(P, R)
            V = (X - prev) / h
            net.clear_forces()
            if self_contact is not None:
                self_contact.exchange(False, True)
            if k > steps_move:
                for it in settle_with:
                    it.exchange(False, True)
            net.ride(surface, P, R, h)
            proj.start()
            net.advance(h)
            net.tether(surface, P, R, tether)
            proj.resolve(X, V, h)
            prev = X
    finally:
        net.alpha = alpha
    if skin_velocity is not None:
        tri, d, bary = proj.tree.nearest(net.x, 0.2)
        hit = tri >= 0
        t = surface.triangles[tri[hit]]
        net.v[hit] = np.einsum("kj,kjd->kd", bary[hit], skin_velocity[t])
    net.time = 0.0
    body = AABBTree(X, surface.triangles)
    own = AABBTree(net.x, net.triangles)
    out = {"steps": steps_move + steps_settle, "cloth_body_intersections":
           int(len(body.intersections(own))), "self_intersections": int(len(own.intersections()))}
    if not np.all(np.isfinite(net.x)):
        raise SceneError(f"{net.name}: dressing blew up; use a smaller step")
    return out


# --- a garment as a spring-mass network ----------------------------------------------------
#: a triangular lattice of springs k has the sheet stiffness Y = 2 k / sqrt(3) (per unit width
#: per unit strain), whatever its spacing: k = sqrt(3) / 2 Y for the structural springs
LATTICE = np.sqrt(3.0) / 2.0


#: N: the pull of an elastic band's webbing along the band when worn (a waistband holds a pair
#: of sweat pants, ~0.3 kg, by friction of mu ~0.5 over its pressure: 2 pi T mu >> m g)
BAND_TENSION = 3.0


def spring_set(g: Garment):
    """(Springs, kinds (s,), masses (n,)) of a garment: structural springs on its edges at
    k = LATTICE x tensile stiffness, shear springs across quad diagonals at k = LATTICE x
    shear, bending springs across the other interior edges at k = 3 B / l0^2 (B the bending
    rigidity, N m: a hinge of two edges of length l0 resisting a fold), masses by area at the
    fabric's areal density. Elastic rings rest at ``ring_factor`` of their cut length."""
    from ..geometry.mesh import mesh_springs
    if g.parts:
        sets, base = [], 0
        for p in g.parts:
            sp, kd, m = spring_set(p)
            sets.append((Springs(sp.i + base, sp.j + base, sp.rest, sp.stiffness,
                                 sp.tension_only), kd, m))
            base += len(p.vertices)
        return (Springs.concat(*[a for a, _, _ in sets]), np.concatenate([b for _, b, _ in sets]),
                np.concatenate([c for _, _, c in sets]))
    f = g.fabric
    ms = mesh_springs(g.vertices, g.triangles, g.mass, "area", g.name)
    x = g.vertices
    rest = np.linalg.norm(x[ms.pairs[:, 0]] - x[ms.pairs[:, 1]], axis=1)
    k = np.choose(ms.kind, [np.full(len(rest), LATTICE * f.tensile),
                            np.full(len(rest), LATTICE * f.shear),
                            3.0 * f.bending / rest ** 2])
    if len(g.ring_edges):
        key = lambda p: np.sort(p, axis=1) @ np.array([len(x), 1])  # noqa: E731
        factor = dict(zip(key(g.ring_edges).tolist(), g.ring_factor.tolist()))
        kk = key(ms.pairs)
        scale = np.array([factor.get(int(v), 1.0) for v in kk])
        band = (ms.kind == 0) & (scale != 1.0)
        rest = rest * np.where(band, scale, 1.0)
        # the band's elastic webbing sewn into the fabric: BAND_TENSION (N) at rest
        k = np.where(band, np.maximum(k, BAND_TENSION / np.maximum(1.0 / scale - 1.0, 1e-3)
                                      / rest), k)
    springs = Springs(ms.pairs[:, 0].copy(), ms.pairs[:, 1].copy(), rest, k,
                      np.zeros(len(rest), bool))
    return springs, ms.kind, ms.masses


def network(g: Garment, dt: float = 1.0 / 240.0, integrator: str = "localglobal",
            mass_damping: float = 0.3, stiffness_damping: float = 0.0, color=None, **kw):
    """The garment's network (systems/garments.Garments: a SpringNetwork that certifies
    itself against the skin it is worn on), drawn as cloth."""
    springs, kind, masses = spring_set(g)
    net = Garments(g.name, g.vertices.copy(), masses, springs, dt=dt, integrator=integrator,
                   mass_damping=mass_damping, stiffness_damping=stiffness_damping,
                   triangles=g.triangles, color=color, **kw)
    net.setup(g, kind)
    return net
