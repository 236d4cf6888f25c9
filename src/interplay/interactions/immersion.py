"""The parts of a body in water (SPEC 2.4, objects in water): the solids the water sees, and
the hydrodynamic drag on each part. Shared by the two-way interaction (interactions/
buoyancy.py ``BodyInWater``, against the moving water) and the still-water stand-in
(interactions/standins.py ``ViscousDragField``), so both see the same body.

Every part of a BodiesView whose primitive is a sphere, ellipsoid, capsule or box becomes a
solid (kernels/lids.py): a ball is one, a figure's 17 segments are 17. Drag on a part follows
its shape (independence principle: each velocity component meets the area normal to it), at
the part's centre, scaled by its submerged fraction f:

* sphere or ellipsoid: -1/2 rho C_d A(u) f |v| v, A(u) = pi a b c sqrt(u^T A u) the area it
  shows along u = v/|v| (pi r^2 for a sphere);
* capsule (radius r, axis segment 2 h along u): broadside -1/2 rho C_n (4 r h + pi r^2) f
  |v_n| v_n on the velocity normal to the axis, end-on -1/2 rho C_a pi r^2 f |v_a| v_a along it;
* box (half extents h): -1/2 rho C_n 4 h_i h_j f |v_k| v_k along each of its axes e_k.

Rotational drag integrates the same normal drag along a spinning part: a capsule turning at w
about an axis normal to its own feels -1/2 C_n rho r L^4 f |w| w (L = h + r its half length),
a box turning about e_k -1/2 C_n rho h_k (h_i^4 + h_j^4) f |w_k| w_k; a sphere or ellipsoid (and
a capsule's spin about its axis) -C_r rho r^5 f |w| w, r its equal-volume radius.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from ..kernels.lids import BOX, CAPSULE, ELLIPSOID, Solids

KINDS = {"sphere": ELLIPSOID, "ellipsoid": ELLIPSOID, "capsule": CAPSULE, "box": BOX}


class ImmersedParts:
    """The solids of a BodiesView's parts that have a water-displacing primitive, updated from
    the view's live poses and velocities by ``update()``.

    parts (k,) the part indices; volume (k,) m^3 exact; width (k,) m: each solid's smallest
    width (what the columns must resolve)."""

    def __init__(self, view):
        if view is None or view.kind != "bodies":
            raise SceneError(f"{getattr(view, 'name', 'the body')} has no rigid parts the water "
                             "can displace (its contact view must be a BodiesView)")
        parts, kind, local_c, local_r, size = [], [], [], [], []
        for k, prim in enumerate(view.primitives):
            if prim is None or prim.kind not in KINDS:
                continue
            parts.append(k)
            kind.append(KINDS[prim.kind])
            local_c.append(prim.middle)
            frame = np.eye(3)
            if prim.kind == "sphere":
                s = (prim.radius,) * 3
            elif prim.kind == "capsule":
                axis = np.asarray(prim.b, float) - np.asarray(prim.a, float)
                half = 0.5 * float(np.linalg.norm(axis))
                frame = _frame_along(axis)
                s = (prim.radius, half, 0.0)
            else:
                s = prim.axes
            local_r.append(frame)
            size.append(np.asarray(s, dtype=float))
        if not parts:
            raise SceneError(f"{view.name} has no shape the water can displace (its contact "
                             "view needs sphere, ellipsoid, capsule or box primitives)")
        self.view = view
        self.parts = np.array(parts, dtype=np.int64)
        self.kind = np.array(kind, dtype=np.int64)
        self._local_c = np.array(local_c, dtype=float)
        self._local_r = np.array(local_r, dtype=float)
        size = np.array(size, dtype=float)
        r, h = size[:, 0], size[:, 1]
        self.volume = np.where(self.kind == CAPSULE, math.pi * r * r * (2.0 * h + 4.0 / 3.0 * r),
                               np.where(self.kind == BOX, 8.0 * size.prod(axis=1),
                                        4.0 / 3.0 * math.pi * size.prod(axis=1)))
        self.width = np.where(self.kind == CAPSULE, 2.0 * r, 2.0 * size.min(axis=1))
        n = len(parts)
        self.solids = Solids(self.kind, np.zeros((n, 3)), np.zeros((n, 3, 3)), size,
                             self.volume, np.zeros(n))
        self.masses = view.masses[self.parts]
        self.centres = self.solids.centre     # (k,3) m, live after update()
        self.velocity = np.zeros((n, 3))     # (k,3) m/s at each solid's centre
        self.spin = np.zeros((n, 3))         # (k,3) rad/s
        self.com = np.zeros((n, 3))          # (k,3) m, the parts' centres of mass

    @property
    def count(self) -> int:
        return len(self.parts)

    def update(self) -> Solids:
        """Place the solids at the parts' current poses; their vertical speeds and
        ``velocity`` are those of each solid's centre (m/s)."""
        view, s = self.view, self.solids
        origins, rots = view.poses()
        o, R = origins[self.parts], rots[self.parts]
        np.einsum("kij,kj->ki", R, self._local_c, out=s.centre)
        np.add(s.centre, o, out=s.centre)
        np.matmul(R, self._local_r, out=s.rot)
        lin, ang = view.velocities()
        self.com[:] = view.centres()[self.parts]
        self.spin[:] = ang[self.parts]
        self.velocity[:] = lin[self.parts] + np.cross(self.spin, s.centre - self.com)
        s.vz[:] = self.velocity[:, 2]
        return s

    def drag(self, v, frac, rho, coef) -> np.ndarray:
        """(k,3) N: the form drag of the parts moving at v (k,3) m/s relative to the water,
        f = frac (k,) submerged; coef: (C_d spheres and ellipsoids, C_n broadside, C_a a
        capsule end-on)."""
        c_sphere, c_normal, c_axial = coef
        s, out = self.solids, np.zeros_like(v)
        speed = np.linalg.norm(v, axis=1)
        e = self.kind == ELLIPSOID
        if e.any():
            a2 = s.size[e] ** 2
            # u^T A u with A = R diag(1/a^2) R^T: the body-frame components of u over a^2
            ub = np.einsum("kji,kj->ki", s.rot[e], v[e]) / np.maximum(speed[e], 1e-300)[:, None]
            area = math.pi * s.size[e].prod(axis=1) * np.sqrt((ub ** 2 / a2).sum(axis=1))
            out[e] = -0.5 * rho * c_sphere * (area * frac[e] * speed[e])[:, None] * v[e]
        c = self.kind == CAPSULE
        if c.any():
            u = s.rot[c][:, :, 2]
            r, h = s.size[c, 0], s.size[c, 1]
            va = (v[c] * u).sum(axis=1)[:, None] * u
            vn = v[c] - va
            broad = c_normal * (4.0 * r * h + math.pi * r * r)
            end = c_axial * math.pi * r * r
            out[c] = -0.5 * rho * frac[c][:, None] * (
                broad[:, None] * np.linalg.norm(vn, axis=1)[:, None] * vn
                + end[:, None] * np.linalg.norm(va, axis=1)[:, None] * va)
        b = self.kind == BOX
        if b.any():
            R, h = s.rot[b], s.size[b]
            faces = 4.0 * np.stack([h[:, 1] * h[:, 2], h[:, 0] * h[:, 2], h[:, 0] * h[:, 1]], 1)
            vb = np.einsum("kji,kj->ki", R, v[b])  # components along the box axes
            fb = -0.5 * rho * c_normal * frac[b][:, None] * faces * np.abs(vb) * vb
            out[b] = np.einsum("kij,kj->ki", R, fb)
        return out

    def rotational_drag(self, w, frac, rho, c_normal, c_spin) -> np.ndarray:
        """(k,3) N m: the drag of the parts spinning at w (k,3) rad/s in still water (the
        normal drag integrated along each part), f = frac (k,) submerged."""
        s, out = self.solids, np.zeros_like(w)
        r_eq = np.cbrt(self.volume / (4.0 / 3.0 * math.pi))
        spin = -c_spin * rho * frac[:, None] * (r_eq ** 5)[:, None] \
            * np.linalg.norm(w, axis=1)[:, None] * w
        e = self.kind == ELLIPSOID
        out[e] = spin[e]
        c = self.kind == CAPSULE
        if c.any():
            u = s.rot[c][:, :, 2]
            r, length = s.size[c, 0], s.size[c, 1] + s.size[c, 0]
            wa = (w[c] * u).sum(axis=1)[:, None] * u
            wn = w[c] - wa
            out[c] = -0.5 * c_normal * rho * (frac[c] * r * length ** 4)[:, None] \
                * np.linalg.norm(wn, axis=1)[:, None] * wn
            out[c] -= c_spin * rho * (frac[c] * r ** 5)[:, None] \
                * np.linalg.norm(wa, axis=1)[:, None] * wa
        b = self.kind == BOX
        if b.any():
            R, h = s.rot[b], s.size[b]
            h4 = h ** 4
            arm = h * (h4.sum(axis=1)[:, None] - h4)  # h_k (h_i^4 + h_j^4)
            wb = np.einsum("kji,kj->ki", R, w[b])
            tb = -0.5 * c_normal * rho * frac[b][:, None] * arm * np.abs(wb) * wb
            out[b] = np.einsum("kij,kj->ki", R, tb)
        return out

    def exert(self, active, force, torque, apply=True):
        """Apply force (k,3) N at the parts' centres of mass and torque (k,3) N m to the parts
        where active (k,) is True (when ``apply``); return the total force (N) and the total
        torque about the body's centre of mass (N m)."""
        if not active.any():
            return np.zeros(3), np.zeros(3)
        view = self.view
        if apply:
            for k in np.flatnonzero(active):
                view.apply(int(self.parts[k]), force[k], torque[k])
        arm = self.com[active] - view.centre_of_mass()
        return (force[active].sum(axis=0),
                torque[active].sum(axis=0) + np.cross(arm, force[active]).sum(axis=0))


def _frame_along(axis) -> np.ndarray:
    """(3,3) orthonormal, right-handed, column 2 along axis."""
    z = np.asarray(axis, float) / np.linalg.norm(axis)
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], axis=1)
