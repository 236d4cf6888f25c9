"""Contact between any two systems with surfaces (SPEC 2.5): rigid bodies, articulated figures,
keyframed bodies, spring-mass networks and static colliders, through one path that reads only
their contact views (systems/views.py).

Detection: the points of each side (a network's particles, a body's mesh vertices) against
the other side's surface: its triangle hierarchy (``geometry.aabb_tree``; transformed for a
body of one rigid part, refit every exchange over the step's motion for a network or a body of
several parts) or a static shape's signed distance. A body's and a static shape's surface is
closed: a point up to ``depth`` behind a face is pushed back out, which stops fast objects
tunnelling as long as they move less than ``depth`` per step. A network's triangles are
two-sided sheets of ``thickness``; a network without triangles collides as cords (segments).
Response (kernels/trimesh_contact.respond, the one contact law): stabilized penalty with the
constraint term and Coulomb friction, at the contact point of both sides, equal and opposite:
forces split over a triangle's vertices by barycentric weights, or a force and torque on a
rigid part. Stiffness and damping default to values from each contact's effective mass m_eff
and the step h: c_s = m_eff (1/(n h))^2, c_d = 2 m_eff/(n h) with n = ``contact_steps``: the
contact resolves over a few steps, critically damped (no bounce), while the constraint term
carries the steady load (no sinking). Friction sticks through a tangential spring per point
(kept between exchanges, part of the interaction's ``capture()``) and slides at mu f_n.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..params import param
from ..geometry.aabb_tree import AABBTree, check_points, check_thickness
from ..kernels.aabb_tree import deepest_on_segments
from ..kernels.trimesh_contact import ContactForces, Contacts, respond, signed_triangle_distance
from .base import Interaction


@dataclass(frozen=True)
class MeshContactParams:
    """thickness: contact skin (m; a cloth's half thickness); depth: how far inside a closed
    surface (rigid or static) a point is still pushed out (m; more than an object moves in a
    step); friction mu (-); eps: slip speed (m/s) above which sliding friction is full Coulomb;
    stiffness (N/m), damping (N s/m): None chooses them per contact from the masses and the
    step (see the module docstring); contact_steps: the steps over which a penetration is
    resolved (None: 10 when a rigid part takes part, whose rotation is integrated explicitly
    and sees several contacts' stiffness at once, else 3: a network's point settles an impact
    within its thickness); constraint: include the constraint term f_c; skin: contacts are
    kept this far (m) beyond the thickness, where the penalty turns negative and only
    lightens the constraint force, so a resting contact settles inside it instead of
    flickering at its edge (and losing its friction spring)."""
    thickness: float = param(0.005, "m", ge=0.0, le=1.0)
    depth: float = param(0.05, "m", ge=0.0, le=10.0)
    friction: float = param(0.5, "-", ge=0.0, le=10.0)
    eps: float = param(0.01, "m/s", gt=0.0, le=100.0)
    stiffness: float | None = param(None, "N/m", gt=0.0, le=1e9, doc="none: from the masses")
    damping: float | None = param(None, "N s/m", ge=0.0, le=1e7, doc="none: from the masses")
    contact_steps: float | None = param(None, "steps", ge=1.0, le=1000.0)
    constraint: bool = True
    skin: float = param(0.002, "m", ge=0.0, le=1.0)

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

    def law(self) -> np.ndarray:
        """The law's row (kernels/contact.py); stiffness and damping -1: from the mass."""
        return np.array([self.thickness, -1.0 if self.stiffness is None else self.stiffness,
                         -1.0 if self.damping is None else self.damping, self.friction,
                         self.eps, 1.0 if self.constraint else 0.0])


class _Side:
    """One system seen by the contact, through its contact view: its points (world positions,
    velocities, accelerations from the other forces, inverse masses) and its surface."""

    def __init__(self, system, p: MeshContactParams, owner):
        self.sys = system
        view = system.contact_view()
        if view is None:
            raise ParameterError(f"{owner}: {system.name} ({type(system).__name__}) has no "
                                 "contact view; it cannot collide")
        self.view = view
        self.static = view.kind == "shape"
        self.bodies = view.kind == "bodies"
        self.net = view.kind == "points"
        self.pad = p.thickness + p.skin
        self.tree = None
        self.rigid = False  # a body of one rigid part
        if self.bodies:
            meshes = view.meshes
            self.body_v = np.concatenate([v for v, _ in meshes])
            sizes = [len(v) for v, _ in meshes]
            self.part_of = np.repeat(np.arange(len(meshes)), sizes)
            base = np.cumsum([0] + sizes[:-1])
            tris = np.concatenate([t + b for (_, t), b in zip(meshes, base)])
            # one rigid part: its tree is transformed, never refit; several parts move
            # relative to each other, so one tree over them all is refit
            self.rigid = view.count == 1
            self._pose()
            self.tree = AABBTree(self.body_v if self.rigid else self.x, tris, owner=system.name)
            self.signed = True
        elif self.net:
            if view.triangles is not None:
                # unpadded: nearest-triangle queries carry the reach in their radius, and a
                # padded box would only widen every query (4x slower at 1 cm on 1 cm cloth)
                self.tree = AABBTree(view.x, view.triangles, owner=system.name)
            else:
                # a net of cords: its springs collide as segments (with closed surfaces)
                self.segs = AABBTree(view.x, view.segments, owner=system.name, pad=self.pad)
            self.signed = False

    def _pose(self):
        """A body's world vertices from its parts' poses."""
        pos, R = self.view.poses()
        self.origin = pos[self.part_of]
        self.x = check_points(self.sys.name, np.einsum("vij,vj->vi", R[self.part_of],
                                                       self.body_v) + self.origin)
        return pos, R

    def update(self, h):
        """World points, velocities, accelerations and inverse masses; refit or move the tree
        over the step's motion (h s)."""
        v = self.view
        if self.static:
            return
        if self.bodies:
            lin, ang = v.velocities()
            self.com = v.centres()
            self.lin, self.ang = lin, ang
            if self.rigid:
                # the end pose of the step: translation predicted, rotation bounded by a pad
                pos, R = v.poses()
                self.tree.transform(R[0], pos[0], R[0], pos[0] + lin[0] * h)
                pad = np.linalg.norm(ang[0]) * h * v.reach[0] + self.pad
                self.tree.lo -= pad
                self.tree.hi += pad
                self.x = check_points(self.sys.name, self.tree.x)
            else:
                self._pose()
            part = self.part_of
            self.v = lin[part] + np.cross(ang[part], self.x - self.com[part])
            self.a = v.free_accelerations()[part]
            self.Iinv = v.inverse_inertias()
            if not self.rigid:
                self.tree.refit(self.x, self.x + self.v * h)
            return
        self.x = check_points(self.sys.name, v.x)
        self.v = v.v
        self.a = v.accelerations()
        self.winv = v.inverse_mass
        if self.tree is not None:
            self.tree.refit(self.x, self.x + self.v * h)
        else:
            self.segs.refit(self.x, self.x + self.v * h)

    def bounds(self, h):
        """A cheap world box (lo, hi) m holding the side's surface over the next h s, for
        skipping the exchange while the two sides are apart; None for static sides."""
        v = self.view
        if self.static:
            return None
        if self.bodies:
            if not self.rigid:  # parts move relative to each other: a figure is always tested
                return None
            pos, _ = v.poses()
            r = v.reach[0] + self.pad + np.linalg.norm(v.velocities()[0][0]) * h
            return pos[0] - r, pos[0] + r
        grow = self.pad + np.abs(v.v).max() * h
        return v.x.min(axis=0) - grow, v.x.max(axis=0) + grow

    def inverse_mass_at(self, part, r, n):
        """Inverse effective mass (1/kg) of rigid parts along n at offsets r from their
        centres of mass."""
        rn = np.cross(r, n)
        return (1.0 / self.view.masses[part]
                + np.einsum("ij,ijk,ik->i", rn, self.Iinv[part], rn))


class MeshContact(Interaction):
    """Contact between any two systems with contact views: bodies (rigid parts with their
    meshes: rigid bodies, figures, keyframed bodies), points (spring networks, with their
    triangles or as cords) and static shapes (the floor, systems/colliders)."""

    def __init__(self, name, primary, secondary, params: MeshContactParams = MeshContactParams(),
                 mode="two-way", standin=None):
        super().__init__(name, primary, secondary, mode, standin)
        self.p = params.validated(name)
        self._law = self.p.law()
        self.a = _Side(primary, self.p, name)
        self.b = _Side(secondary, self.p, name)
        if self.a.static and self.b.static:
            raise ParameterError(f"{name}: both {primary.name} and {secondary.name} are static; "
                                 "a contact needs a moving side")
        self._h = 0.0
        self.n_contacts = 0
        self._stretch = {}  # friction springs' stretch (m) per point, by direction

    def prepare(self, h, dts=None):
        """A pass starts (or reruns from its start): step h (s); friction springs forget
        contacts from whatever ran before."""
        self._h = h
        self._stretch.clear()

    def capture(self):
        """The friction springs: per direction, the point keys and their stretch (m)."""
        snap = {}
        for key, (keys, stretch) in self._stretch.items():
            snap[f"stretch_keys_{int(key)}"] = keys.copy()
            snap[f"stretch_{int(key)}"] = stretch.copy()
        return snap

    def restore(self, snap):
        self._stretch = {bool(int(k.rsplit("_", 1)[1])): (snap[k].copy(),
                                                           snap[k.replace("_keys", "")].copy())
                         for k in snap if k.startswith("stretch_keys_")}

    # --- detection ---------------------------------------------------------------------------
    def _queries(self, P: _Side, Q: _Side):
        """P's query points against Q: (positions (k,3), vertex indices (k,w), weights (k,w)).
        A body's mesh vertices and a cloth's particles are points (w = 1); a net of cords
        against a closed surface gives each cord's deepest point (w = 2, the cord's ends), one
        contact per cord."""
        if P.net and P.tree is None and not (Q.static or Q.net):
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
            s, n = Q.view.distance(x)
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
        points xp: a rigid part's material point there, or a weighted set of network points."""
        k = len(xp)
        if side.static:
            return np.zeros((k, 3)), np.zeros((k, 3)), np.zeros(k)
        if side.bodies:
            part = side.part_of[vid[:, 0]]
            r = xp - side.com[part]
            return (side.lin[part] + np.cross(side.ang[part], r), side.a[vid[:, 0]],
                    side.inverse_mass_at(part, r, n))
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
        out = ContactForces(np.empty((len(sel), 3)), np.empty((len(sel), 3, 3)),
                            np.empty((len(sel), 3, 3)))
        keyv = pv[sel, 0] if pv.shape[1] == 1 else pv[sel, 0] * len(P.x) + pv[sel, 1]
        old_keys, old = self._stretch.get(key, (np.zeros(0, np.int64), np.zeros((0, 3))))
        stretch = np.zeros((len(sel), 3))
        if len(old_keys):
            pos = np.searchsorted(old_keys, keyv).clip(0, len(old_keys) - 1)
            hit = old_keys[pos] == keyv
            stretch[hit] = old[pos[hit]]
        contacts = Contacts(np.ascontiguousarray(n[sel]), p.thickness - s[sel],
                            np.ascontiguousarray((vP - vQ)[sel]),
                            np.ascontiguousarray((aP - aQ)[sel]), inv_m[sel])
        act = respond(contacts, self._law, omega, self._h, stretch, out)
        order = np.argsort(keyv[act])
        self._stretch[key] = (keyv[act][order], stretch[act][order])
        sel = sel[act]
        f, jx, jv = out.f[act], out.jx[act], out.jv[act]
        rec_p = (pv[sel], pw[sel], xp[sel], f, jx, jv, vQ[sel])
        rec_q = None if Q.static else (None if qv is None else qv[sel],
                                       None if qw is None else qw[sel], xp[sel], -f, jx, jv,
                                       vP[sel])
        return rec_p, rec_q

    @staticmethod
    def _apply(side: _Side, rec):
        """Apply forces at contact points: per rigid part touched, the force and torque about
        its centre of mass (with the summed Jacobians); or split over network points by their
        weights (force w F, Jacobian w^2 J: equal and opposite to the other side's in sum)."""
        vid, w, xp, f, jx, jv, vref = rec
        if side.bodies:
            part = side.part_of[vid[:, 0]]
            tau = np.cross(xp - side.com[part], f)
            for k in np.unique(part):
                on = part == k
                side.view.apply(int(k), f[on].sum(axis=0), tau[on].sum(axis=0),
                                dfdx=jx[on].sum(axis=0), dfdv=jv[on].sum(axis=0))
            return
        k, m = vid.shape
        w2 = (w ** 2)[:, :, None, None]
        side.view.apply(vid.reshape(-1), (w[:, :, None] * f[:, None, :]).reshape(-1, 3),
                        (w2 * jx[:, None]).reshape(-1, 3, 3), (w2 * jv[:, None]).reshape(-1, 3, 3),
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
                if A.bodies:
                    torque += np.cross(xp - A.view.centre_of_mass(), f).sum(axis=0)
            for side, rec in ((P, rec_p), (Q, rec_q)):
                if rec is None or not side.view.movable:
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
        self._law = self.p.law()
        view = network.contact_view()
        if view is None or view.kind != "points" or view.triangles is None:
            raise ParameterError(f"{name}: self-collision needs a network with triangles; "
                                 f"{network.name} has none (build it with "
                                 "SpringNetwork.from_mesh)")
        self.a = self.b = _Side(network, self.p, name)
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
