"""Contact of rigid parts with a spring-mass network, sub-cycled in the network's substeps
(SPEC 2.5): a figure's 17 segments on a trampoline bed, a ball on a net of cords.

It reads only the two contact views: the parts' analytic primitives (spheres, capsules,
boxes: ``BodiesView.primitives``), poses, centres of mass, velocities and masses; the
network's points and its elements (the edges of its triangles, else its springs). At every
coupling step it finds, per part, the elements it may reach within the step
(kernels/part_contact.candidates) and, when any, hands the network the parts on their
predicted paths through the sub-cycling hook (``PointsView.subcycle``): the network collides
them with those elements at every one of its substeps through the one contact law, and each
part then receives the impulse it got, as the step's mean force and torque about its centre of
mass. A bed point of a few grams under a gymnast's foot is thrown across its contact skin
within a fraction of a millisecond; exchanged once per 1 ms coupling step the contact could
not be both stiff and stable, sub-cycled it is. A network that cannot sub-cycle (local/global)
gets the same law once per coupling step.

Stiffness and damping default to the pair's effective mass and the network's substep:
c_s = m_eff (1/(n dt))^2, c_d = 2 m_eff/(n dt), n = ``contact_steps`` (critically damped, no
bounce); the constraint term carries a resting load without sinking. Friction is the law's
regularised Coulomb, capped at the force that stops the slip within a substep, so a planted
foot drags the bed's points with it instead of skating over them; at low speed that cap is a
damper of a point's mass over the substep, so a foot pushed steadily creeps, and ``stick``
holds it instead by a tangential spring per touched point kept between steps.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SceneError, require_nonnegative, require_positive
from ..kernels import part_contact as PC
from ..kernels.springs import point_forces
from ..params import param
from .base import Interaction


@dataclass(frozen=True)
class PartContactParams:
    """thickness (m): the network's contact skin (half a bed's thickness); friction mu (-);
    eps (m/s): slip speed of full Coulomb friction; stiffness (N/m), damping (N s/m): None
    chooses them per contact from the effective mass and the substep; contact_steps: the
    substeps over which a penetration is resolved (with the default stiffness); constraint:
    include the constraint term; margin (m): how much farther than a part can reach in a step
    its candidate elements are gathered; rounding (m): the parts' boxes seen with their edges
    and corners rounded by this radius (within the box; a box primitive's own radius wins),
    as a torso is: cloth draped over a sharp edge is folded over it, and thrown off it;
    stick: friction sticks through a tangential spring per touched point, kept from step to
    step (contact_law.sticking_friction), instead of the regularised law, whose viscous range
    lets a foot pushed steadily along a soft network creep at v = F dt / m_point; faces: the
    parts' features (a box's corners, a capsule's ends, a sphere's centre) collide with the
    network's triangles' faces as well as their edges, so a part narrower than a facet rests
    on it instead of wedging between its edges (a foot on a trampoline's bed: without it the
    bed's 0.12 m facets let a 1500 N foot through, docs/trampoline.md); golden_steps: the
    golden-section steps of a box's deepest point along a segment, its bracket 0.618^steps of
    the segment (14: 1e-3, whose tenth-of-a-millimetre steps made a box on the trampoline's
    bed chaotic; 40: 4e-9, at no measurable cost; the swing's dressing, sensitive to a hair,
    was made at 14)."""
    thickness: float = param(0.004, "m", ge=0.0, le=0.2)
    friction: float = param(0.8, "-", ge=0.0, le=10.0)
    eps: float = param(0.01, "m/s", gt=0.0, le=10.0)
    stiffness: float | None = param(None, "N/m", gt=0.0, le=1e9, doc="None: per contact")
    damping: float | None = param(None, "N s/m", ge=0.0, le=1e7, doc="None: per contact")
    contact_steps: float = param(3.0, "substeps", ge=1.0, le=1000.0)
    constraint: bool = param(True, doc="include the constraint term")
    margin: float = param(0.01, "m", ge=0.0, le=1.0)
    rounding: float = param(0.0, "m", ge=0.0, le=0.2, doc="boxes' edges rounded by this radius")
    stick: bool = param(False, doc="friction sticks (a spring per touched point), no creep")
    faces: bool = param(False, doc="the parts' corners and ends against the triangles' faces")
    golden_steps: int = param(14, "steps", ge=1, le=60, doc="a box's deepest-point search")

    def validated(self, owner: str) -> "PartContactParams":
        require_nonnegative(owner, "contact thickness", self.thickness, "m")
        require_nonnegative(owner, "friction", self.friction)
        require_positive(owner, "friction eps", self.eps, "m/s")
        if self.stiffness is not None:
            require_positive(owner, "contact stiffness", self.stiffness, "N/m")
        if self.damping is not None:
            require_nonnegative(owner, "contact damping", self.damping, "N s/m")
        require_positive(owner, "contact_steps", self.contact_steps)
        require_nonnegative(owner, "candidate margin", self.margin, "m")
        require_nonnegative(owner, "box rounding", self.rounding, "m")
        return self

    def law(self) -> np.ndarray:
        """The law's row (kernels/contact.py); stiffness and damping -1: from the mass."""
        return np.array([self.thickness, -1.0 if self.stiffness is None else self.stiffness,
                         -1.0 if self.damping is None else self.damping, self.friction,
                         self.eps, 1.0 if self.constraint else 0.0])


def _edges(triangles) -> np.ndarray:
    """Unique edges (e,2) of a triangle set."""
    t = np.asarray(triangles, np.int64)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0)


class PartContact(Interaction):
    """Rigid parts (primary: any system seen as BodiesView with primitives) against a spring
    network's elements (secondary: a PointsView). elements (s,2): point pairs to collide
    ((p, p) for points); default the edges of its triangles, else its springs; with
    ``params.faces`` its triangles' faces too. extra:
    ((part name, Primitive), ...) more primitives that parts have for this contact beside their
    own (a figure's neck, which its sphere of a head leaves out, for a noose round it); each
    pushes on its part. parts: the names of the parts whose own primitives collide (default
    all; a swing's seat alone, where another contact keeps the cloth off her body)."""

    def __init__(self, name, bodies, network, params: PartContactParams = PartContactParams(),
                 mode="two-way", standin=None, elements=None, extra=(), parts=None):
        super().__init__(name, bodies, network, mode, standin)
        self.p = params.validated(name)
        view, net = bodies.contact_view(), network.contact_view()
        if view is None or view.kind != "bodies":
            raise SceneError(f"interaction {name}: {bodies.name} is not seen as rigid parts; "
                             "this contact needs a body or a figure")
        if net is None or net.kind != "points":
            raise SceneError(f"interaction {name}: {network.name} is not a spring-mass "
                             "network; use MeshContact for other surfaces")
        own = list(view.names) if parts is None else list(parts)
        unknown = [nm for nm in own + [nm for nm, _ in extra] if nm not in view.names]
        if unknown:
            raise SceneError(f"interaction {name}: {bodies.name} has no parts "
                             f"{', '.join(unknown)}; its parts are {', '.join(view.names)}")
        # one row of the kernels' bundle per primitive: the parts' own, then the extra ones
        self.owner = np.array([view.names.index(nm) for nm in own]
                              + [view.names.index(nm) for nm, _ in extra], dtype=np.int64)
        self.primitives = ([view.primitives[view.names.index(nm)] for nm in own]
                           + [pr for _, pr in extra])
        missing = [view.names[o] for o, pr in zip(self.owner, self.primitives) if pr is None
                   or pr.kind not in PC.KINDS]
        if missing:
            raise SceneError(f"interaction {name}: parts {', '.join(missing)} of "
                             f"{bodies.name} have no sphere, capsule or box primitive; use "
                             "MeshContact")
        self.view, self.net = view, net
        if elements is None:
            elements = _edges(net.triangles) if net.triangles is not None else net.segments
        pairs = np.ascontiguousarray(elements, dtype=np.int64).reshape(-1, 2)
        if len(pairs) and (pairs.min() < 0 or pairs.max() >= len(net.x)):
            raise ParameterError(f"interaction {name}: elements reference points outside "
                                 f"0..{len(net.x) - 1} of {network.name}")
        if self.p.faces and net.triangles is None:
            raise SceneError(f"interaction {name}: contact faces asked for, but {network.name} "
                             "has no triangles; leave faces off")
        faces = (np.asarray(net.triangles, np.int64).reshape(-1, 3) if self.p.faces
                 else np.zeros((0, 3), np.int64))
        elems = np.concatenate([np.column_stack([pairs, np.full(len(pairs), -1)]), faces])
        self.parts = self._parts(elems)
        rows = len(self.owner)
        # every element a candidate of every part: one touch per segment, a face's per feature
        most = int(sum(len(pairs) + len(faces) * PC.features(kind) for kind in self.parts.kind))
        self._out = point_forces(3 * most)
        self._touches = PC.touches(most, rows, len(net.x))
        self._wrenches = np.zeros((rows, 6))
        self._h = 0.0
        self.n_contacts = 0
        self.deepest = 0.0  # m: the deepest any element went into a part's skin, over the run

    def _parts(self, elems) -> PC.Parts:
        """The kernels' bundle: each primitive relative to its part's centre of mass (fixed in
        the part's frame, so computed once from the current pose)."""
        v, own = self.view, self.owner
        k = len(own)
        origin, R = v.poses()
        com = v.centres()
        kind, p, q, size, reach = (np.zeros(k, np.int64), np.zeros((k, 3)), np.zeros((k, 3)),
                                   np.zeros((k, 3)), np.zeros(k))
        for j, pr in enumerate(self.primitives):
            o = own[j]
            off = R[o].T @ (com[o] - origin[o])  # the centre of mass in the part's frame
            kind[j] = PC.KINDS[pr.kind]
            if pr.kind == "capsule":
                p[j], q[j] = np.asarray(pr.a) - off, np.asarray(pr.b) - off
                size[j, 0] = pr.radius
                reach[j] = max(np.linalg.norm(p[j]), np.linalg.norm(q[j])) + pr.radius
            elif pr.kind == "box":
                p[j], size[j] = np.asarray(pr.centre) - off, pr.axes
                q[j, 0] = min(pr.radius or self.p.rounding, min(pr.axes))  # its rounding
                reach[j] = np.linalg.norm(p[j]) + np.linalg.norm(size[j])
            else:
                p[j], size[j, 0] = np.asarray(pr.centre) - off, pr.radius
                reach[j] = np.linalg.norm(p[j]) + pr.radius
        law = np.tile(self.p.law(), (k, 1))
        n = len(self.net.x) if self.p.stick else 0
        return PC.Parts(kind, p, q, size, reach, np.zeros((k, 3)), np.zeros((k, 3, 3)),
                        np.zeros((k, 3)), np.zeros((k, 3)), np.zeros((k, 3)),
                        np.asarray(v.masses, float)[own].copy(), law,
                        float(self.p.contact_steps), int(self.p.golden_steps),
                        elems, np.zeros(k + 1, np.int64), np.zeros(k * len(elems), np.int64),
                        np.zeros((k, 7)), np.zeros(1), np.zeros(3),
                        np.zeros((k, n, 3)), np.full((k, n), -2, np.int64),
                        np.zeros(1, np.int64), np.zeros((k, n, 3)), np.zeros((k, n)))

    def prepare(self, h, dts=None):
        self._h = h

    def capture(self) -> dict:
        """The stand-in's memory, the deepest penetration so far and, when friction sticks,
        the touched points' springs."""
        cap = getattr(self.standin, "capture", None)
        out = {f"standin_{k}": v for k, v in cap().items()} if cap else {}
        out["deepest"] = np.array(self.deepest)
        if self.p.stick:
            P = self.parts
            out.update(stretch=P.stretch.copy(), stamp=P.stamp.copy(), clock=P.clock.copy())
        return out

    def restore(self, snap: dict):
        self.deepest = float(snap["deepest"])
        if self.p.stick:
            for key in ("stretch", "stamp", "clock"):
                getattr(self.parts, key)[...] = snap[key]
        if self.standin is not None and hasattr(self.standin, "restore"):
            self.standin.restore({k[8:]: v for k, v in snap.items() if k.startswith("standin_")})

    def _motion(self):
        """Copy the parts' state now into the bundle."""
        P, v, own = self.parts, self.view, self.owner
        _, R = v.poses()
        P.rotations[:] = R[own]
        P.centres[:] = v.centres()[own]
        lin, ang = v.velocities()
        P.velocities[:], P.spins[:] = lin[own], ang[own]
        P.accels[:] = v.free_accelerations()[own]

    def exchange(self, to_primary, to_secondary):
        self._motion()
        net = self.net
        if PC.candidates(self.parts, net.x, net.v, self._h, self.p.margin) == 0:
            self.parts.clock[0] += 1  # a step without contact: the next one starts unstretched
            self.n_contacts = 0
            self.parts.impulses[:] = 0.0
            self.parts.received[:] = 0.0
            return np.zeros(3), np.zeros(3), False
        if to_secondary and net.subcycle(self.parts, self.parts.elems):
            return None
        return self._lock_step(to_primary, to_secondary)

    def _lock_step(self, to_primary, to_secondary):
        """The law once per coupling step (a network that cannot sub-cycle): forces from the
        states now, held over the step."""
        P, net = self.parts, self.net
        acc = net.accelerations() if self.p.constraint else np.zeros_like(net.x)
        cnt = PC.find_touches(P, 0.0, net.x, self._touches)
        k = PC.touch_forces(P, self._touches, cnt, net.points, acc, self._h, self._out,
                            net.jacobians, self._wrenches)
        P.impulses[:, :6] = self._wrenches * self._h
        P.impulses[:, 6] = np.linalg.norm(self._wrenches[:, :3], axis=1)
        P.peak[0] = np.linalg.norm(self._wrenches[:, :3].sum(axis=0))
        P.received[:] = self._out.f[:k].sum(axis=0) * self._h
        if to_secondary and k:
            o = self._out
            net.apply(o.idx[:k], o.f[:k], o.dfdx[:k], o.dfdv[:k], o.vref[:k])
        return self.complete(to_primary)

    def complete(self, to_primary):
        """The step's mean force and torque on each part (impulse / h), applied at its centre
        of mass; returns their sum and torque about the system's centre of mass."""
        P, h = self.parts, self._h
        self._measure_depth()
        touched = np.flatnonzero(P.impulses[:, 6] > 0.0)
        self.n_contacts = len(touched)
        f = P.impulses[touched, :3] / h
        tau = P.impulses[touched, 3:6] / h
        if to_primary:
            for j, fj, tj in zip(touched, f, tau):
                self.view.apply(int(self.owner[j]), fj, tj)
            self.view.touched(np.unique(self.owner[touched]))
        total = f.sum(axis=0)
        if not len(touched):
            return np.zeros(3), np.zeros(3), False
        arm = P.centres[touched] - self.view.centre_of_mass()
        torque = (tau + np.cross(arm, f)).sum(axis=0)
        return total, torque, True, float(P.peak[0])

    def _measure_depth(self):
        """The deepest penetration of the contact skin at the end of the step: the network's
        new points against the parts' predicted poses (what the law let through)."""
        tc = self._touches
        cnt = PC.find_touches(self.parts, self._h, self.net.x, tc)
        if cnt:
            self.deepest = max(self.deepest, float(tc.pen[:cnt].max()))
        tc.share[:] = 0.0

    def describe(self) -> dict:
        return dict(super().describe(), deepest_m=self.deepest)

    def segment_forces(self) -> np.ndarray:
        """(k,3) the last step's mean force (N) on each part."""
        out = np.zeros((self.view.count, 3))
        np.add.at(out, self.owner, self.parts.impulses[:, :3] / self._h)
        return out
