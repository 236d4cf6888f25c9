"""Contact between any two systems with surfaces (SPEC 2.5): rigid bodies, articulated figures,
keyframed bodies, spring-mass networks and static colliders, through one path.

Detection: the points of each side (a network's particles, a body's mesh vertices) against
the other side's surface: its triangle hierarchy (``geometry.bvh``; refit every exchange for
a network or a figure over the step's motion, transformed for a rigid body) or a static
shape's signed distance. A rigid body's and a static shape's surface is closed: a point up to
``depth`` behind a face is pushed back out, which stops fast objects tunnelling as long as
they move less than ``depth`` per step. A network's triangles are two-sided sheets of
``thickness``.
Response (kernels/trimesh_contact.respond): stabilized penalty with the constraint term and
Coulomb friction, at the contact point of both sides, equal and opposite: forces split over a
triangle's vertices by barycentric weights, or a force and torque on a rigid body (segment).
Stiffness and damping default to values from each contact's effective mass m_eff and the step
h: c_s = m_eff (1/(n h))^2, c_d = 2 m_eff/(n h) with n = ``contact_steps``: the contact
resolves over a few steps, critically damped (no bounce), while the constraint term carries
the steady load (no sinking). Friction sticks through a tangential spring per point (kept
between exchanges) and slides at mu f_n.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..geometry.aabb_tree import BVH, check_points, check_thickness
from ..geometry.sphere import icosphere
from ..kernels.aabb_tree import deepest_on_segments
from ..kernels.rigid import quat_to_matrix
from ..kernels.trimesh_contact import respond, signed_triangle_distance
from ..systems.colliders import StaticShape
from ..systems.rigid import RigidBody
from ..systems.springmass import SpringNetwork
from ..systems.static import StaticPlane
from .base import Interaction


@dataclass(frozen=True)
class MeshContactParams:
    """thickness: contact skin (m; a cloth's half thickness); depth: how far inside a closed
    surface (rigid or static) a point is still pushed out (m; more than an object moves in a
    step); friction mu (-); eps: slip speed (m/s) above which sliding friction is full Coulomb;
    stiffness (N/m), damping (N s/m): None chooses them per contact from the masses and the
    step (see the module docstring); contact_steps: the steps over which a penetration is
    resolved (None: 10 when a rigid body takes part, whose rotation is integrated explicitly
    and sees several contacts' stiffness at once, else 3: a network's point settles an impact
    within its thickness); constraint: include the constraint term f_c; skin: contacts are
    kept this far (m) beyond the thickness, where the penalty turns negative and only
    lightens the constraint force, so a resting contact settles inside it instead of
    flickering at its edge (and losing its friction spring)."""
    thickness: float = 0.005
    depth: float = 0.05
    friction: float = 0.5
    eps: float = 0.01
    stiffness: float | None = None
    damping: float | None = None
    contact_steps: float | None = None
    constraint: bool = True
    skin: float = 0.002

    def validated(self, owner: str) -> "MeshContactParams":
        check_thickness(owner, self.thickness)
        require_positive(owner, "contact depth", self.depth, "m")
        if not (float(self.friction) >= 0.0) or not np.isfinite(self.friction):
            raise ParameterError(f"{owner}: friction must be zero or positive, got "
                                 f"{self.friction!r}; use 0 for frictionless contact")
        require_positive(owner, "friction eps", self.eps, "m/s")
        if self.stiffness is not None:
            require_positive(owner, "contact stiffness", self.stiffness, "N/m")
        if self.damping is not None:
            require_nonnegative(owner, "contact damping", self.damping, "N s/m")
        if self.contact_steps is not None:
            require_positive(owner, "contact_steps", self.contact_steps)
        require_nonnegative(owner, "contact skin", self.skin, "m")
        return self


class _Side:
    """One system seen by the contact: its points (world positions, velocities, accelerations
    from the other forces, inverse masses) and its surface."""

    def __init__(self, system, surface, p: MeshContactParams, owner):
        self.sys = system
        self.static = not system.dynamic or isinstance(system, (StaticShape, StaticPlane))
        # animation (keyframed bodies): a rigid surface that moves as told, infinitely heavy
        # for the contact and never pushed (accepts_forces False: only one-way applies)
        # an articulated figure (MuJoCo): rigid segments, each with its own mesh
        self.figure = hasattr(system, "segment_meshes") and hasattr(system, "seg_body")
        self.kinematic = (not system.accepts_forces and hasattr(system, "q")
                          and not self.figure)
        self.rigid = isinstance(system, RigidBody) or self.kinematic
        self.net = isinstance(system, SpringNetwork)
        self.tree = None
        if self.static:
            if isinstance(system, StaticShape):
                self.shape = system
            elif isinstance(system, StaticPlane):
                self.shape = None
            else:
                raise ParameterError(f"{owner}: {system.name} ({type(system).__name__}) has no "
                                     "collision shape; use a static collider from "
                                     "systems/colliders.py")
            return
        if self.rigid:
            if surface is None and self.kinematic and hasattr(system, "ellipsoid"):
                axes, _ = system.ellipsoid()
                v, t = icosphere(3)
                surface = (v * axes, t)
            v, t = surface if surface is not None else system.surface()
            self.tree = BVH(v, t, owner=system.name)
            self._reach = np.sqrt((self.tree.body_x ** 2).sum(axis=1).max())  # m, from centre
            self.signed = True
        elif self.figure:
            meshes = system.segment_meshes()
            self.body_v = np.concatenate([v for v, _ in meshes])
            sizes = [len(v) for v, _ in meshes]
            self.seg_of = np.repeat(np.arange(len(meshes)), sizes)
            base = np.cumsum([0] + sizes[:-1])
            tris = np.concatenate([t + b for (_, t), b in zip(meshes, base)])
            self._pose()
            self.tree = BVH(self.x, tris, owner=system.name)
            self.signed = True
            bodies = system.seg_body
            self.seg_mass = system.model.body_mass[bodies]
            self._twist = np.zeros(6)
        elif self.net:
            tris = surface[1] if surface is not None else getattr(system, "triangles", None)
            if tris is not None:
                # unpadded: nearest-triangle queries carry the reach in their radius, and a
                # padded box would only widen every query (4x slower at 1 cm on 1 cm cloth)
                self.tree = BVH(system.x, tris, owner=system.name)
            else:
                # a net of cords: its springs collide as segments (with closed surfaces)
                self.segs = BVH(system.x, system.segments(), owner=system.name,
                                pad=p.thickness + p.skin)
            self.signed = False
        else:
            raise ParameterError(f"{owner}: {system.name} ({type(system).__name__}) cannot "
                                 "collide through MeshContact; it takes rigid bodies, "
                                 "figures, keyframed bodies, spring networks and static "
                                 "colliders")

    def _pose(self):
        """A figure's world vertices from its segments' poses."""
        d, b = self.sys.data, self.sys.seg_body
        self.seg_pos = d.xpos[b][self.seg_of]
        R = d.xmat[b].reshape(-1, 3, 3)[self.seg_of]
        self.x = check_points(self.sys.name, np.einsum("vij,vj->vi", R, self.body_v)
                              + self.seg_pos)

    def _figure_update(self, h):
        """Segment velocities (MuJoCo's, world frame, at each segment's origin), vertex
        velocities, and the tree refit over the step (segments move relative to each other,
        so one tree over the whole figure is refit rather than transformed)."""
        import mujoco
        s = self.sys
        nseg = len(s.seg_body)
        self.seg_ang = np.empty((nseg, 3))
        self.seg_lin = np.empty((nseg, 3))
        for k, b in enumerate(s.seg_body):  # 17 segments: one MuJoCo call each
            mujoco.mj_objectVelocity(s.model, s.data, mujoco.mjtObj.mjOBJ_BODY, int(b),
                                     self._twist, 0)
            self.seg_ang[k], self.seg_lin[k] = self._twist[:3], self._twist[3:]
        self._pose()
        r = self.x - self.seg_pos
        self.v = self.seg_lin[self.seg_of] + np.cross(self.seg_ang[self.seg_of], r)
        self.a = np.zeros_like(self.x)  # the servos' accelerations are not known here
        self.tree.refit(self.x, self.x + self.v * h)

    def update(self, h):
        """World points, velocities, accelerations and inverse masses; refit or move the tree
        over the step's motion (h s)."""
        s = self.sys
        if self.static:
            return
        if self.figure:
            self._figure_update(h)
            return
        if self.rigid:
            self.w = getattr(s, "w", np.zeros(3))  # keyframed bodies do not spin
            self.R = quat_to_matrix(s.q)
            # the end pose of the step: translation predicted, rotation bounded by a pad
            self.tree.transform(self.R, s.x, self.R, s.x + s.v * h)
            pad = np.linalg.norm(self.w) * h * self._reach + self._pad
            self.tree.lo -= pad
            self.tree.hi += pad
            self.x = check_points(s.name, self.tree.x)
            r = self.x - s.x
            self.v = s.v + np.cross(self.w, r)
            if self.kinematic:  # prescribed: no acceleration the contact could cancel
                self.a = np.zeros_like(self.x)
                self.Iinv = np.zeros((3, 3))
            else:
                self.a = np.broadcast_to(s.gravity + s.force / s.mass, self.x.shape)
                self.Iinv = self.R @ np.diag(1.0 / s.inertia_body) @ self.R.T
        else:
            self.x = check_points(s.name, s.x)
            self.v = s.v
            self.a = s.internal_forces() / s.m[:, None]
            self.winv = np.where(s.fixed, 0.0, 1.0 / s.m)
            if self.tree is not None:
                self.tree.refit(self.x, self.x + self.v * h)
            else:
                self.segs.refit(self.x, self.x + self.v * h)

    def bounds(self, h):
        """A cheap world box (lo, hi) m holding the side's surface over the next h s, for
        skipping the exchange while the two sides are apart; None for static sides."""
        s = self.sys
        if self.static or self.figure:
            return None  # (a figure is always tested: its extent changes with its pose)
        if self.rigid:
            r = self._reach + self._pad + np.linalg.norm(s.v) * h
            return s.x - r, s.x + r
        grow = self._pad + np.abs(s.v).max() * h
        return s.x.min(axis=0) - grow, s.x.max(axis=0) + grow

    def point_inverse_mass(self, r, n):
        """Inverse effective mass (1/kg) of a rigid body along n at offsets r from its centre."""
        if self.kinematic:
            return np.zeros(len(r))
        rn = np.cross(r, n)
        return 1.0 / self.sys.mass + np.einsum("ij,jk,ik->i", rn, self.Iinv, rn)


class MeshContact(Interaction):
    """Contact between any two of: rigid bodies (through a triangle surface: ``surface()`` or
    the ``surfaces`` argument, body-frame (verts, tris)), spring networks (particles, plus
    ``triangles`` when they have them) and static colliders (StaticPlane, systems/colliders)."""

    def __init__(self, name, primary, secondary, params: MeshContactParams = MeshContactParams(),
                 mode="two-way", standin=None, surfaces=None):
        super().__init__(name, primary, secondary, mode, standin)
        self.p = params.validated(name)
        surfaces = surfaces or {}
        self.a = _Side(primary, surfaces.get(primary.name), self.p, name)
        self.b = _Side(secondary, surfaces.get(secondary.name), self.p, name)
        if self.a.static and self.b.static:
            raise ParameterError(f"{name}: both {primary.name} and {secondary.name} are static; "
                                 "a contact needs a moving side")
        for s in (self.a, self.b):
            s._pad = self.p.thickness + self.p.skin
        self._h = 0.0
        self.n_contacts = 0
        self._stretch = {}  # friction springs' stretch (m) per point, by direction

    def prepare(self, h):
        """A pass starts (or reruns from its start): step h (s); friction springs forget
        contacts from whatever ran before."""
        self._h = h
        self._stretch.clear()

    # --- detection ---------------------------------------------------------------------------
    def _queries(self, P: _Side, Q: _Side):
        """P's query points against Q: (positions (k,3), vertex indices (k,w), weights (k,w)).
        A rigid body's mesh vertices and a cloth's particles are points (w = 1); a net of
        cords against a closed surface gives each cord's deepest point (w = 2, the cord's
        ends), one contact per cord."""
        if P.net and P.tree is None:
            if Q.static or Q.net:
                n = len(P.x)
                return P.x, np.arange(n)[:, None], np.ones((n, 1))
            pairs = P.segs.overlapping(Q.tree)  # (segment, triangle)
            segs = P.segs.elements
            order = np.argsort(pairs[:, 0], kind="stable")
            start = np.searchsorted(pairs[order, 0], np.arange(len(segs) + 1))
            t, s = np.empty(len(segs)), np.empty(len(segs))
            deepest_on_segments(Q.x, Q.tree.elements, start, np.ascontiguousarray(
                pairs[order, 1]), P.x, segs, t, s)
            on = np.flatnonzero(s < self.p.thickness + self.p.skin)
            t = t[on]
            w = np.stack([1.0 - t, t], axis=1)
            vid = segs[on]
            return np.einsum("kj,kjd->kd", w, P.x[vid]), vid, w
        n = len(P.x)
        return P.x, np.arange(n)[:, None], np.ones((n, 1))

    def _contacts(self, P: _Side, Q: _Side):
        """Contacts of P's query points with Q's surface: (P's vertex indices (k,w) and weights,
        positions, s, normals towards P, Q's triangle vertex indices (k,3) and weights (k,3),
        or None for a static Q)."""
        p = self.p
        if P.static or (Q.net and Q.tree is None):
            return None
        x, pv, pw = self._queries(P, Q)
        band = p.thickness + p.skin
        if Q.static:
            if Q.shape is None:  # the floor plane z = height
                s = x[:, 2] - Q.sys.height
                n = np.zeros_like(x)
                n[:, 2] = 1.0
            else:
                s, n = Q.shape.distance(x)
            idx = np.flatnonzero((s < band) & (s > -p.depth))
            return pv[idx], pw[idx], x[idx], s[idx], n[idx], None, None
        reach = max(band, p.depth) if Q.signed else band
        tri, d, bary = Q.tree.nearest(x, reach, skip_incident=P is Q)
        idx = np.flatnonzero(tri >= 0)
        s, n = np.empty(len(idx)), np.empty((len(idx), 3))
        signed_triangle_distance(x[idx], tri[idx], bary[idx], d[idx], Q.x, Q.tree.elements,
                                 Q.signed, s, n)
        keep = s < band
        idx, s, n = idx[keep], s[keep], n[keep]
        return pv[idx], pw[idx], x[idx], s, n, Q.tree.elements[tri[idx]], bary[idx]

    # --- response ----------------------------------------------------------------------------
    @staticmethod
    def _gather(side: _Side, vid, w, xp, n):
        """Velocity, acceleration and inverse effective mass along n of a side at contact
        points xp: a rigid body's material point there, or a weighted set of network points."""
        k = len(xp)
        if side.static:
            return np.zeros((k, 3)), np.zeros((k, 3)), np.zeros(k)
        if side.rigid:
            r = xp - side.sys.x
            return (side.sys.v + np.cross(side.w, r), np.broadcast_to(side.a[0], (k, 3)),
                    side.point_inverse_mass(r, n))
        if side.figure:
            # the segment's own mass: the joints make the real effective mass larger, so the
            # contact is a little softer than it could be, never less stable
            seg = side.seg_of[vid[:, 0]]
            r = xp - side.sys.data.xpos[side.sys.seg_body[seg]]
            winv = 1.0 / side.seg_mass[seg] if side.sys.accepts_forces else np.zeros(k)
            return (side.seg_lin[seg] + np.cross(side.seg_ang[seg], r), np.zeros((k, 3)), winv)
        return (np.einsum("kj,kjd->kd", w, side.v[vid]), np.einsum("kj,kjd->kd", w, side.a[vid]),
                np.einsum("kj,kj->k", w ** 2, side.winv[vid]))

    def _forces(self, P: _Side, Q: _Side, found, key):
        """Forces at the contacts, on P (and the reactions on Q). key names the direction, for
        the friction springs' stretch, kept per P vertex (its first weighted vertex)."""
        pv, pw, xp, s, n, qv, qw = found
        p = self.p
        vP, aP, wP = self._gather(P, pv, pw, xp, n)
        vQ, aQ, wQ = self._gather(Q, qv, qw, xp, n)
        inv_m = wP + wQ
        sel = np.flatnonzero(inv_m > 0.0)  # two pinned points cannot push each other
        steps = p.contact_steps or (10.0 if (P.rigid or Q.rigid) else 3.0)
        omega = 1.0 / (steps * self._h)
        f, jx, jv = np.empty((len(sel), 3)), np.empty((len(sel), 3, 3)), np.empty(
            (len(sel), 3, 3))
        keyv = pv[sel, 0] if pv.shape[1] == 1 else pv[sel, 0] * len(P.x) + pv[sel, 1]
        old_keys, old = self._stretch.get(key, (np.zeros(0, np.int64), np.zeros((0, 3))))
        stretch = np.zeros((len(sel), 3))
        if len(old_keys):
            pos = np.searchsorted(old_keys, keyv).clip(0, len(old_keys) - 1)
            hit = old_keys[pos] == keyv
            stretch[hit] = old[pos[hit]]
        act = respond(np.ascontiguousarray(n[sel]), p.thickness - s[sel],
                      np.ascontiguousarray((vP - vQ)[sel]), np.ascontiguousarray((aP - aQ)[sel]),
                      inv_m[sel], -1.0 if p.stiffness is None else p.stiffness,
                      -1.0 if p.damping is None else p.damping, omega, p.friction, p.eps,
                      self._h, p.constraint, stretch, f, jx, jv)
        order = np.argsort(keyv[act])
        self._stretch[key] = (keyv[act][order], stretch[act][order])
        sel = sel[act]
        f, jx, jv = f[act], jx[act], jv[act]
        rec_p = (pv[sel], pw[sel], xp[sel], f, jx, jv, vQ[sel])
        rec_q = None if Q.static else (None if qv is None else qv[sel],
                                       None if qw is None else qw[sel], xp[sel], -f, jx, jv,
                                       vP[sel])
        return rec_p, rec_q

    @staticmethod
    def _apply(side: _Side, rec):
        """Apply forces at contact points: a force and torque on a rigid body, or split over
        network points by their weights (force w F, Jacobian w^2 J: equal and opposite to the
        other side's in sum)."""
        vid, w, xp, f, jx, jv, vref = rec
        if side.figure:
            # force and torque about each segment's centre of mass, one call per segment
            fig = side.sys
            seg = side.seg_of[vid[:, 0]]
            tau = np.cross(xp - fig.data.xipos[fig.seg_body[seg]], f)
            for k in np.unique(seg):
                on = seg == k
                fig.add_wrench(f[on].sum(axis=0), tau[on].sum(axis=0), body=int(k))
            return
        if side.rigid:
            side.sys.add_wrench(f.sum(axis=0), np.cross(xp - side.sys.x, f).sum(axis=0),
                                dfdx=jx.sum(axis=0), dfdv=jv.sum(axis=0))
            return
        k, m = vid.shape
        w2 = (w ** 2)[:, :, None, None]
        side.sys.add_point_forces(vid.reshape(-1), (w[:, :, None] * f[:, None, :]).reshape(-1, 3),
                                  (w2 * jx[:, None]).reshape(-1, 3, 3),
                                  (w2 * jv[:, None]).reshape(-1, 3, 3),
                                  np.repeat(vref, m, axis=0))

    def exchange(self, to_primary, to_secondary):
        A, B = self.a, self.b
        ba, bb = A.bounds(self._h), B.bounds(self._h)
        if ba is not None and bb is not None and (np.any(ba[0] > bb[1] + self.p.depth)
                                                  or np.any(bb[0] > ba[1] + self.p.depth)):
            self._stretch.clear()
            self.n_contacts = 0
            return np.zeros(3), np.zeros(3), False
        A.update(self._h)
        B.update(self._h)
        total = np.zeros(3)
        torque = np.zeros(3)
        count = 0
        # (point side, surface side, is the point side the primary?)
        for P, Q, p_is_primary in ((B, A, False), (A, B, True)):
            found = self._contacts(P, Q)
            if found is None or len(found[0]) == 0:
                self._stretch.pop(p_is_primary, None)
                continue
            rec_p, rec_q = self._forces(P, Q, found, p_is_primary)
            if len(rec_p[0]) == 0:
                continue
            count += len(rec_p[0])
            on_primary = rec_p if p_is_primary else rec_q
            if on_primary is not None:
                xp, f = on_primary[2], on_primary[3]
                total += f.sum(axis=0)
                if A.rigid:
                    torque += np.cross(xp - A.sys.x, f).sum(axis=0)
            for side, rec in ((P, rec_p), (Q, rec_q)):
                if rec is None or side.static or not side.sys.accepts_forces:
                    continue
                if (side is A and not to_primary) or (side is B and not to_secondary):
                    continue
                self._apply(side, rec)
        self.n_contacts = count
        return total, torque, count > 0


class SelfContact(MeshContact):
    """A cloth against itself: each particle against the network's own triangles, skipping the
    triangles it belongs to (SPEC 2.5 self-collision). The forces are internal: they sum to
    zero and the logged force on the "primary" (the same network) is their sum, zero."""

    def __init__(self, name, network, params: MeshContactParams = MeshContactParams()):
        Interaction.__init__(self, name, network, network, "two-way")
        self.p = params.validated(name)
        if getattr(network, "triangles", None) is None:
            raise ParameterError(f"{name}: self-collision needs a network with triangles; "
                                 f"{network.name} has none (build it with "
                                 "SpringNetwork.from_mesh)")
        self.a = self.b = _Side(network, None, self.p, name)
        self.a._pad = self.p.thickness + self.p.skin
        self._h = 0.0
        self.n_contacts = 0
        self._stretch = {}

    def exchange(self, to_primary, to_secondary):
        S = self.a
        S.update(self._h)
        found = self._contacts(S, S)
        self.n_contacts = 0
        if len(found[0]) == 0:
            self._stretch.clear()
            return np.zeros(3), np.zeros(3), False
        rec_p, rec_q = self._forces(S, S, found, True)
        self.n_contacts = len(rec_p[0])
        if self.n_contacts and (to_primary or to_secondary):
            self._apply(S, rec_p)
            self._apply(S, rec_q)
        return np.zeros(3), np.zeros(3), self.n_contacts > 0
