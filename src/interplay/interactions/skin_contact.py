"""Cloth against a figure's skinned body surface (issue 16: garments "colliding with the
actor's triangles"), one-way: the figure (simulated or motion-captured) moves as it moves;
the cloth is kept outside its skin.

**What happens each coupling step h.** The exchange is deferred: the cloth first advances h
under its own forces, then every cloth point is tested against the skin *at the step's end*
(``geometry.body_surface.BodySurface`` posed from the figure's segments: exactly, for a
motion-capture clip, sampled at t + h; for any other figure extrapolated from its pose and
segment velocities at t, an error of a h^2 / 2, 0.9 mm at a = 100 m/s^2 and h = 1/240 s):
each point's nearest skin triangle within thickness + reach (an AABB tree refit to the skin),
its signed distance and normal (the triangle's winding: the skin is closed and outward wound),
and a point closer than the thickness is moved out to it along the normal, its velocity into
the skin cancelled and Coulomb friction applied with that normal impulse
(``kernels.skin_contact.project``: it sticks when the slip it would keep is below mu times the
normal velocity change, else slides by that much less).

**Why it cannot tunnel.** After each step every point within reach is outside the skin by
the thickness. Within the next step a point and the skin close in by at most
(|v_point| + |v_skin|) h; as long as that is less than the reach (so the point is found) and
less than the half-thickness of the body part it entered (so its nearest skin triangle is the
one it entered through, and the normal points back out that way), the next projection puts it
back on the side it came from. ``SkinContact.margin()`` reports the largest approach per step
met in the run against the thinnest limb's radius; the runner's summary carries it.

The reaction (minus the cloth's momentum change per step) is logged on the figure as force
and torque, never applied: the analysis's effective acceleration and the advisor read it.

Garments worn in layers (systems/garment_layers.py) are held apart from each other and from
themselves at the start of the projection, each point's sides told by the skin's normal and
limb found for it the step before; the skin contact and the stretch limit come next, and
the layers' guard last (no new crossing of the garments leaves the step; its zones move with
the skin under them, so they stay out of it).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..geometry.aabb_tree import AABBTree
from ..geometry.mesh import edges
from ..kernels.skin_contact import (Law, Nearest, Skin, edge_neighbours, project,
                                    project_edges, reaction, signed_distance, vertex_normals)
from ..kernels.strain_limit import Planes
from ..params import param
from .base import Interaction


@dataclass(frozen=True)
class SkinContactParams:
    """thickness (m): the gap kept between the cloth's points and the skin (half the fabric's
    thickness plus what keeps a triangle's middle off a curved limb); friction mu (-), cloth
    on skin; reach (m): how deep inside the skin a point is still found and pushed out (more
    than the cloth and skin close in one step); tether (m): each garment point is kept within
    it of where the skin's weights carry it (systems.garments.Garments.tether; 0: off);
    final_limits: how often a garment worn in layers has its stretch limit run last, undone
    where it crosses (see _Projector.resolve: accuracy against speed, the runner's garments'
    pass 4-17% longer for each, docs/clothing.md); edges: each cloth edge also held off the
    skin's edges (kernels/skin_contact.project_edges: a ridge sharper than the cloth's
    spacing can pass between two points held off it; the runner's garments' pass 15% longer
    and it has no such crossing without it, so off by default; on for the swing's skirt);
    final_gap (m): how near the skin the final limits may bring a point (the thickness if
    more, as by default; 2 mm with two or three final limits: the runner's tee at 5.0% at
    frame 0 and the median frame, 5.1-5.2% in its one worst frame, docs/clothing.md);
    relimits: how often the stretch limit and the layers' guard run again after the guard,
    before the final limits (the runner's tee, two final limits at 2 mm: one frame of 43 at
    5.1% with one, none over 5% with two; each is a limit and a guard more a step)."""
    thickness: float = param(0.005, "m", gt=0.0, le=0.1)
    friction: float = param(0.5, "-", ge=0.0, le=5.0)
    reach: float = param(0.03, "m", gt=0.0, le=0.5)
    tether: float = param(0.03, "m", ge=0.0, le=1.0, doc="0: none")
    final_limits: int = param(1, "passes", ge=0, le=5, doc="0: fastest")
    edges: bool = param(False, doc="edge-edge contact with the skin too")
    final_gap: float = param(0.005, "m", ge=0.0, le=0.1, doc="the thickness if more")
    relimits: int = param(1, "passes", ge=0, le=5, doc="0: fastest")


class PosedSkin:
    """A figure's body surface posed from its segments: vertices (n,3) m and velocities (n,3)
    m/s now, or at a later time for a motion-capture clip (``pose_at``)."""

    def __init__(self, figure, surface):
        self.figure, self.surface = figure, surface
        self.tris = np.ascontiguousarray(surface.triangles, np.int64)
        self.across = edge_neighbours(self.tris)

    def now(self):
        f = self.figure
        pos, R = f.part_poses()
        lin, ang = f.part_velocities()
        X = self.surface.pose(pos, R)
        V = self.surface.velocities(pos, R, lin, ang, f.part_centres())
        return X, V

    def at(self, t: float, h: float, now=None):
        """(X, V) at time t + h from the state at t (``now``: its (X, V), computed if None)."""
        f = self.figure
        if hasattr(f, "pose_at"):
            pos, R, lin, ang, centres = f.pose_at(t + h)
            return (self.surface.pose(pos, R),
                    self.surface.velocities(pos, R, lin, ang, centres))
        X, V = self.now() if now is None else now
        return X + h * V, V


#: m: the least a point that rides the skin is kept off it (see resolve)
RIDE_OFF = 0.001


def kept_off(idx, n, x, s, gap: float) -> Planes:
    """The half-spaces (kernels/strain_limit.Planes) that keep points idx (k,) at x (k,3) m,
    found s (k,) m off the skin along its outward normals n (k,3), at least ``gap`` (m) off
    it in a move after the projection (a stretch limit): n . x' >= n . x + gap - max(s, gap),
    so a point farther than gap may come to it, and one nearer may not come nearer."""
    return Planes(idx, n, np.einsum("ij,ij->i", n, x) + gap - np.maximum(s, gap))


class _Projector:
    """The projection of one cloth against a skin mesh (its triangles; X0 the skin's first
    vertices for the tree; limbs (nb,) int64 each skin vertex's limb, for a garment worn in
    layers; carry: the layers' zones move with the skin first), reused by SkinContact and by
    dressing."""

    def __init__(self, cloth, tris, params: SkinContactParams, X0, limbs=None,
                 carry: bool = True):
        self.view = cloth.contact_view()
        self.p = params
        self.tris = np.ascontiguousarray(tris, np.int64)
        self.across = edge_neighbours(self.tris)
        # the cloth's edges, for the edge-edge contact (none for bare points)
        t = self.view.triangles
        self.edges = (np.zeros((0, 2), np.int64) if t is None
                      else np.ascontiguousarray(edges(np.asarray(t))[0], np.int64))
        self.tree = AABBTree(X0, self.tris, owner=f"{cloth.name} skin")
        n = len(self.view.x)
        self.dv, self.s, self.n = np.zeros((n, 3)), np.zeros(n), np.zeros((n, 3))
        self.vn = np.zeros((len(X0), 3))
        self.x0 = self.view.x.copy()  # the points at the step's start
        # a garment's stretch limit runs after the projection, held off the skin by its
        # planes (systems/garments.Garments.limit_strain): the two then agree
        self.limiter = cloth if hasattr(cloth, "limit_strain") else None
        if self.limiter is not None:
            cloth.limit_by_contact = True
        # garments worn in layers are held apart (systems/garment_layers.py), each point's
        # side chosen at the step's start by the skin's normal and limb where it was found
        self.layers = getattr(cloth, "layers", None)
        self.limbs = (np.full(len(X0), -1, np.int64) if limbs is None
                      else np.asarray(limbs, np.int64))
        self.limb = np.full(n, -1, np.int64)  # each point's nearest skin point's limb
        self.near = np.full(n, -1, np.int64)  # each point's nearest skin triangle, last step
        # the layers' zones carried by the skin under them first (Layers.guard); not while
        # dressing: the skin then swings from the A-pose (arms 40 deg), and carried by it the
        # runner's tee stretched 45% at the shoulder (7.6% with rigid zones; docs/clothing.md)
        self.carry = carry
        self.approach = 0.0  # m: the deepest a point was found inside the skin
        self.count = 0

    def start(self):
        """Remember the points at the step's start (before the cloth advances)."""
        self.x0[:] = self.view.x
        if self.layers is not None:
            self.layers.start(self.n, self.limb)

    def resolve(self, X, V, h, centre=None):
        """Project the cloth against the skin (X, V) over a step h; (force, torque about
        centre) on the skin."""
        v = self.view
        if self.layers is not None:
            # the layers first, so that the skin contact has the last word: where the body
            # leaves no room for two layers (between the thighs) they touch rather than one
            # being pushed into the skin (systems/garment_layers.py)
            self.layers.project(h)
        self.tree.refit(X)
        tri, d, bary = self.tree.nearest(v.x, self.p.thickness + self.p.reach, hint=self.near)
        self.near = tri
        vertex_normals(X, self.tris, self.vn)
        signed_distance(v.x, tri, bary, d, X, self.tris, self.across, self.vn, self.s, self.n)
        found = self.s[tri >= 0]
        if len(found):
            self.approach = max(self.approach, float(-found.min()))
        # points that ride the skin (a gripping waistband) are placed by its weights, not
        # moved by the contact; where the skin folds (her hip flexed, seated on the swing)
        # the weights carry a few of them just inside it (0.5 mm: all 9 crossings of her skin
        # at the swing's frame 0): those go out to RIDE_OFF
        inside = v.points.fixed & (tri >= 0) & (self.s < RIDE_OFF)
        if inside.any():
            v.x[inside] += (RIDE_OFF - self.s[inside])[:, None] * self.n[inside]
        skin, law = Skin(X, V, self.tris), Law(self.p.thickness, self.p.friction, h)
        nearest = Nearest(tri, bary, self.s, self.n)
        self.count = int(project(v.points, self.x0, skin, nearest, law, self.dv))
        if self.p.edges:  # then each cloth edge off the skin's: a ridge between two points
            self.count += int(project_edges(v.points, self.x0, self.edges, skin, self.across,
                                            nearest, law, self.dv))
        self.limb[:] = np.where(tri >= 0, self.limbs[self.tris[tri, 0]], -1)
        if self.limiter is not None:
            # each point found near the skin keeps the thickness off its nearest point's
            # tangent plane. Its distance now is what was found, or the thickness where the
            # projection has just moved it out to that (a point that rides the skin is
            # not moved by the limit either way)
            near = np.flatnonzero(tri >= 0)
            now = np.maximum(self.s[near], self.p.thickness)
            planes = kept_off(near, self.n[near], v.x[near], now, self.p.thickness)
            # the final limits (below) may bring a point nearer, to final_gap: a pleat lying on
            # her chest then flattens towards the skin instead of crossing itself (docs/
            # clothing.md, "The final gap")
            final = (planes if self.p.final_gap >= self.p.thickness else
                     kept_off(near, self.n[near], v.x[near], now, self.p.final_gap))
            before = v.v.copy()
            self.limiter.limit_strain(h, planes)
            # the limit's own velocity changes join the contact's in the reaction: its
            # corrections along springs are equal and opposite pairs on one line (no net
            # force or torque), so what remains is the skin's push through the planes and
            # the pull of the waistband that rides it
            self.dv += v.v - before
        if self.layers is not None:
            # last: no new crossing of the garments survives the step (its moves are the
            # cloth's own, not the skin's push: they stay out of the reaction). The zones it
            # moves stretch the springs at their rims; the limit then shortens them and the
            # guard looks again (``relimits`` times: the runner's tee at 95% largest strain
            # without, 32% with one), its zones rigid from the first round: carried by the
            # skin they stretch within (the tee's worst 31%, 12% rigid; docs/clothing.md)
            follow = None
            if self.carry:
                hit = tri >= 0
                follow = np.full_like(v.x, np.nan)
                follow[hit] = h * np.einsum("kj,kjd->kd", bary[hit], V[self.tris[tri[hit]]])
            self.layers.guard(self.x0, h, follow)
            for _ in range(self.p.relimits if self.limiter is not None else 0):
                before = v.v.copy()
                self.limiter.limit_strain(h, planes)
                self.dv += v.v - before
                self.layers.guard(self.x0, h)
            # the guard's rims, shortened where that crosses nothing: the limit once more, and
            # the points of the triangles it made cross go back (the runner's tee: median
            # frame 7.0 -> 5.7%, worst 11.9 -> 8.7%). A further limit holds the points sent
            # back: it shortens their springs from the other end (run free again, they made
            # the same crossings: twice, the tee's worst frame 8.9%, held 8.1%; three times
            # held 6.5%; docs/clothing.md)
            held = np.zeros(len(v.x), bool)
            for _ in range(self.p.final_limits if self.limiter is not None else 0):
                safe_x, safe_v = v.x.copy(), v.v.copy()
                self.limiter.limit_strain(h, final, held)
                held |= self.layers.undo_new_crossings(safe_x, safe_v)
                self.dv += v.v - safe_v
        c = np.zeros(3) if centre is None else np.asarray(centre, float)
        return reaction(v.x, v.masses, self.dv, h, c)


class SkinContact(Interaction):
    """Cloth (a SpringNetwork with points) kept outside a figure's skin (see the module
    docstring). figure: Figure or MocapFigure (anything with RigidParts poses of the 17
    segments); surface: its BodySurface."""

    two_way_supported = False

    def __init__(self, name, figure, cloth, surface, params: SkinContactParams =
                 SkinContactParams(), mode: str = "one-way"):
        super().__init__(name, figure, cloth, mode)
        require_positive(name, "thickness", params.thickness, "m")
        require_nonnegative(name, "friction", params.friction)
        require_positive(name, "reach", params.reach, "m")
        view = cloth.contact_view()
        if view is None or view.kind != "points":
            raise ParameterError(f"{name}: {cloth.name} is not a system of points (cloth); "
                                 "a skin contact keeps cloth points outside a body")
        if not hasattr(figure, "part_poses") or getattr(figure, "plan", None) is None:
            raise ParameterError(f"{name}: {figure.name} has no segments to pose a skin from; "
                                 "use a Figure or MocapFigure")
        self.p = params
        self.cloth, self.view = cloth, view
        self.skin = PosedSkin(figure, surface)
        self.proj = _Projector(cloth, surface.triangles, params, self.skin.now()[0],
                               surface.vertex_limbs())
        self._h = 0.0
        self._t = 0.0
        self.n_contacts = 0
        self.tethered = 0
        self.thinnest = min(float(s.shape[1]) for s in surface.plan if s.shape[0] == "capsule")

    def prepare(self, h, dts=None):
        self._h = float(h)

    def exchange(self, to_primary, to_secondary):
        """Deferred: the cloth advances first, then ``complete`` projects it."""
        self._t = self.cloth.time
        # points that ride the skin (a gripping waistband) go where it is at the step's end
        if getattr(self.cloth, "pinned", None) is not None and len(self.cloth.pinned):
            f = self.primary
            pos, R = (f.pose_at(self._t + self._h)[:2] if hasattr(f, "pose_at")
                      else f.part_poses())
            self.cloth.ride(self.skin.surface, pos, R, self._h)
        self.proj.start()
        return None

    def complete(self, to_primary):
        f = self.primary
        if self.p.tether > 0 and hasattr(self.cloth, "tether"):
            pos, R = (f.pose_at(self._t + self._h)[:2] if hasattr(f, "pose_at")
                      else f.part_poses())
            self.tethered = self.cloth.tether(self.skin.surface, pos, R, self.p.tether)
        X, V = self.skin.at(self._t, self._h)
        f, tau = self.proj.resolve(X, V, self._h, self.primary.centre_of_mass())
        self.n_contacts = self.proj.count
        return f, tau, self.n_contacts > 0

    def margin(self) -> dict:
        """The tunnelling certificate: the deepest a point was found inside the skin over
        the run (m) against the thinnest limb radius (m) and the reach."""
        a = self.proj.approach
        return {"deepest_found_m": a, "thinnest_limb_radius_m": self.thinnest,
                "reach_m": self.p.reach, "safe": bool(a < min(self.thinnest, self.p.reach))}

    def describe(self) -> dict:
        out = super().describe()
        out["tunnelling"] = self.margin()
        return out

    def capture(self) -> dict:
        out = {"approach": np.array([self.proj.approach])}
        if self.proj.layers is not None:
            # the next step's layer sides are told by the skin found at this step's end
            out.update(normal=self.proj.n.copy(), limb=self.proj.limb.copy())
        return out

    def restore(self, snap):
        if "approach" in snap:
            self.proj.approach = float(np.asarray(snap["approach"]).ravel()[0])
        if "normal" in snap and self.proj.layers is not None:
            self.proj.n[:] = snap["normal"]
            self.proj.limb[:] = snap["limb"]
