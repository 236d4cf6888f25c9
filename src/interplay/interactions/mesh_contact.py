"""Contact between any two systems with surfaces (SPEC 2.5): rigid bodies, spring-mass networks
and static colliders, through one path.

Detection: the points of each side (a network's particles, a rigid body's mesh vertices)
against the other side's surface: its triangle hierarchy (``geometry.bvh``; refit every
exchange for a network over the step's motion, transformed for a rigid body) or a static
shape's signed distance. A rigid body's and a static shape's surface is closed: a point up to
``depth`` behind a face is pushed back out, which stops fast objects tunnelling as long as
they move less than ``depth`` per step. A network's triangles are two-sided sheets of
``thickness``.
Response (kernels/trimesh_contact.respond): stabilized penalty with the constraint term and
regularized Coulomb friction, at the contact point of both sides, equal and opposite: forces
split over a triangle's vertices by barycentric weights, or a force and torque on a rigid body.
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
from ..geometry.bvh import BVH, check_points, check_thickness
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
    within its thickness); constraint: include the constraint term f_c; skin: contacts are kept this far
    (m) beyond the thickness, where the penalty turns negative and only lightens the
    constraint force, so a resting contact settles inside it instead of flickering at its
    edge (and losing its friction spring)."""
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
        self.rigid = isinstance(system, RigidBody)
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
            v, t = surface if surface is not None else system.surface()
            self.tree = BVH(v, t, owner=system.name)
            self.signed = True
        elif self.net:
            tris = surface[1] if surface is not None else getattr(system, "triangles", None)
            if tris is not None:
                self.tree = BVH(system.x, tris, owner=system.name, pad=p.thickness + p.skin)
            self.signed = False
        else:
            raise ParameterError(f"{owner}: {system.name} ({type(system).__name__}) cannot "
                                 "collide through MeshContact; it takes rigid bodies, spring "
                                 "networks and static colliders")

    def update(self, h):
        """World points, velocities, accelerations and inverse masses; refit or move the tree
        over the step's motion (h s)."""
        s = self.sys
        if self.static:
            return
        if self.rigid:
            self.R = quat_to_matrix(s.q)
            # the end pose of the step: translation predicted, rotation bounded by a pad
            self.tree.transform(self.R, s.x, self.R, s.x + s.v * h)
            reach = np.sqrt((self.tree.body_x ** 2).sum(axis=1).max())
            pad = np.linalg.norm(s.w) * h * reach + self._pad
            self.tree.lo -= pad
            self.tree.hi += pad
            self.x = check_points(s.name, self.tree.x)
            r = self.x - s.x
            self.v = s.v + np.cross(s.w, r)
            self.a = np.broadcast_to(s.gravity + s.force / s.mass, self.x.shape)
            self.Iinv = self.R @ np.diag(1.0 / s.inertia_body) @ self.R.T
        else:
            self.x = check_points(s.name, s.x)
            self.v = s.v
            self.a = s.internal_forces() / s.m[:, None]
            self.winv = np.where(s.fixed, 0.0, 1.0 / s.m)
            if self.tree is not None:
                self.tree.refit(self.x, self.x + self.v * h)

    def point_inverse_mass(self, r, n):
        """Inverse effective mass (1/kg) of a rigid body along n at offsets r from its centre."""
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
        self._h = h

    # --- detection ---------------------------------------------------------------------------
    def _contacts(self, P: _Side, Q: _Side):
        """Contacts of P's points with Q's surface: (point indices, s, normals towards P, Q's
        triangle vertex indices (k,3) and weights (k,3) or None)."""
        p = self.p
        if P.static or (Q.net and Q.tree is None):
            return None
        x = P.x
        if Q.static:
            if Q.shape is None:  # the floor plane z = height
                s = x[:, 2] - Q.sys.height
                n = np.zeros_like(x)
                n[:, 2] = 1.0
            else:
                s, n = Q.shape.distance(x)
            idx = np.flatnonzero((s < p.thickness + p.skin) & (s > -p.depth))
            return idx, s[idx], n[idx], None, None
        reach = max(p.thickness + p.skin, p.depth) if Q.signed else p.thickness + p.skin
        tri, d, bary = Q.tree.nearest(x, reach, skip_incident=P is Q)
        idx = np.flatnonzero(tri >= 0)
        s, n = np.empty(len(idx)), np.empty((len(idx), 3))
        signed_triangle_distance(x[idx], tri[idx], bary[idx], d[idx], Q.x, Q.tree.elements,
                                 Q.signed, s, n)
        keep = s < p.thickness + p.skin
        idx, s, n = idx[keep], s[keep], n[keep]
        return idx, s, n, Q.tree.elements[tri[idx]], bary[idx]

    # --- response ----------------------------------------------------------------------------
    def _forces(self, P: _Side, Q: _Side, found, key):
        """Forces on P's points and their reactions on Q; returns per-side force records.
        key names the direction (which side's points) for the friction springs' stretch."""
        idx, s, n, qv, qw = found
        p, k = self.p, len(idx)
        xp = P.x[idx]
        vP, aP = P.v[idx], P.a[idx]
        wP = P.point_inverse_mass(xp - P.sys.x, n) if P.rigid else P.winv[idx]
        if Q.static:
            vQ, aQ, wQ = np.zeros((k, 3)), np.zeros((k, 3)), np.zeros(k)
        elif Q.rigid:
            r = xp - Q.sys.x
            vQ = Q.sys.v + np.cross(Q.sys.w, r)
            aQ = np.broadcast_to(Q.a[0], (k, 3))
            wQ = Q.point_inverse_mass(r, n)
        else:
            vQ = np.einsum("kj,kjd->kd", qw, Q.v[qv])
            aQ = np.einsum("kj,kjd->kd", qw, Q.a[qv])
            wQ = np.einsum("kj,kj->k", qw ** 2, Q.winv[qv])
        inv_m = wP + wQ
        ok = inv_m > 0.0
        steps = p.contact_steps or (10.0 if (P.rigid or Q.rigid) else 3.0)
        omega = 1.0 / (steps * self._h)
        sel = np.flatnonzero(ok)
        if len(sel):
            fo, jxo, jvo = np.empty((len(sel), 3)), np.empty((len(sel), 3, 3)), np.empty(
                (len(sel), 3, 3))
            old = self._stretch.get(key)
            stretch = np.zeros((len(sel), 3))
            if old is not None and len(old) == len(P.x):
                stretch[:] = old[idx[sel]]
            act = respond(np.ascontiguousarray(n[sel]), p.thickness - s[sel],
                          np.ascontiguousarray((vP - vQ)[sel]),
                          np.ascontiguousarray((aP - aQ)[sel]), inv_m[sel],
                          -1.0 if p.stiffness is None else p.stiffness,
                          -1.0 if p.damping is None else p.damping, omega, p.friction, p.eps,
                          self._h, p.constraint, stretch, fo, jxo, jvo)
            kept = np.zeros((len(P.x), 3))  # contacts that ended forget their stretch
            kept[idx[sel[act]]] = stretch[act]
            self._stretch[key] = kept
            sel = sel[act]
            f, jx, jv = fo[act], jxo[act], jvo[act]
        else:
            self._stretch.pop(key, None)
            f, jx, jv = np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3, 3))
        rec_p = (idx[sel], xp[sel], f, jx, jv, vQ[sel])
        if Q.static:
            return rec_p, None
        w = None if qw is None else qw[sel]
        rec_q = (None if qv is None else qv[sel], xp[sel], -f, jx, jv, vP[sel], w)
        return rec_p, rec_q

    @staticmethod
    def _apply_points(side: _Side, rec):
        """Apply P-side records (one force per point) to a side."""
        idx, xp, f, jx, jv, vref = rec
        if side.rigid:
            side.sys.add_wrench(f.sum(axis=0), np.cross(xp - side.sys.x, f).sum(axis=0),
                                dfdx=jx.sum(axis=0), dfdv=jv.sum(axis=0))
        else:
            side.sys.add_point_forces(idx, f, jx, jv, vref)

    @staticmethod
    def _apply_surface(side: _Side, rec):
        """Apply Q-side reactions: at the contact point of a rigid body, or by barycentric
        weights on a network's triangle (force w F, Jacobian w^2 J)."""
        tv, xp, f, jx, jv, vref, w = rec
        if side.rigid:
            side.sys.add_wrench(f.sum(axis=0), np.cross(xp - side.sys.x, f).sum(axis=0),
                                dfdx=jx.sum(axis=0), dfdv=jv.sum(axis=0))
            return
        k = len(f)
        side.sys.add_point_forces(tv.reshape(-1), (w[:, :, None] * f[:, None, :]).reshape(-1, 3),
                                  ((w ** 2)[:, :, None, None] * jx[:, None]).reshape(-1, 3, 3),
                                  ((w ** 2)[:, :, None, None] * jv[:, None]).reshape(-1, 3, 3),
                                  np.repeat(vref, 3, axis=0).reshape(k * 3, 3))

    def exchange(self, to_primary, to_secondary):
        A, B = self.a, self.b
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
                xp, f = on_primary[1], on_primary[2]
                total += f.sum(axis=0)
                if A.rigid:
                    torque += np.cross(xp - A.sys.x, f).sum(axis=0)
            for side, rec, is_p in ((P, rec_p, True), (Q, rec_q, False)):
                if rec is None or side.static:
                    continue
                if (side is A and not to_primary) or (side is B and not to_secondary):
                    continue
                (self._apply_points if is_p else self._apply_surface)(side, rec)
        self.n_contacts = count
        return total, torque, count > 0
