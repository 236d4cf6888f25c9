"""Garments from panels fitted to a body (issue 16): a tee-shirt, a vest (a tee without
sleeves), sweat pants with an elastic waistband and cuffs, a skirt; and any garment mesh read
from a file with its pinned and sewn vertex groups.

**How a garment is made.** Each garment is cut from panels: a front and a back body panel,
sleeve panels, leg panels, laid around the body in its A-pose (geometry/body_surface.py) and
sewn along their seams. A panel is a strip of rows; each row is a ring around a body part
(the torso, an arm, a leg) at the body's own girth there plus the panel's *ease* (m): the
girth is measured by casting rays from the part's axis against the body's signed distance
(``BodySurface.sdf``), so the garment is fitted to the figure's dimensions, whatever its
height and mass. Seams are *welded*: the side seams, the shoulder seams, the sleeve and leg
seams and the crotch seam share their vertices between the two panels (a sewn seam of zero
rest length and a stiffness above the fabric's is the welded vertex; welding removes that
stiff spring from the solve). The sleeves and legs start from the armhole and the crotch
loop and blend into rings around the limb over a few rows; after sewing, every vertex
closer to the body than ``min_gap`` is moved out along the body's distance gradient
(dressing's first step). The garment's rest shape is that fitted shape; the elastic bands
(waistband, cuffs) rest ``elastic`` shorter around, so they grip.

A ``Garment`` is vertices (n,3) m, triangles (m,3), named vertex groups (the openings'
boundary rows, the elastic bands, the seams), the rest-length factors of the elastic rings,
the fabric and the sizes it was cut to. ``network(garment)`` makes its spring-mass network.
``check_garment`` refuses a non-manifold mesh (an edge of more than two triangles, a vertex
whose faces do not form one fan), a too coarse mesh (edges longer than the body's thinnest
limb can hold), and names the element.

The fabrics' numbers (``FABRICS``) and their sources are in docs/clothing.md.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..params import param
from . import body_fit as BF
from .body_surface import BodySurface
# the network of a garment (systems/garments.py) is part of this API
from ..systems.garments import BAND_TENSION, LATTICE, network, spring_set  # noqa: F401,E402
from .garment_mesh import (DRESS_DEPTH, boundary_loops, check_garment,  # noqa: F401 - the API
                           check_start, even_out, load_garment, split_long_edges)
from .mesh import edges as mesh_edges


@dataclass(frozen=True)
class Fabric:
    """A textile: areal density (kg/m^2), tensile stiffness per unit width at small strain
    (N/m: force per width per unit strain), shear and bending (N m: bending rigidity per
    width), friction against skin (-), thickness (m), stretch limit (-): the largest strain
    its structural springs may take (systems/garments.Garments.limit_strain; inf: none)."""
    name: str
    density: float
    tensile: float
    shear: float
    bending: float
    friction: float
    thickness: float
    stretch_limit: float = float("inf")


#: measured fabrics (docs/clothing.md gives the sources and how the values were taken; the
#: stretch limits are chosen there: 5%, the cotton tee's bar of issue 16, for all three: a
#: woven twill stretches less than a knit. The skirt held to it once crumpled at her hip and
#: crossed itself 2.7-5x more; cut in gores and held off itself by its layers it does not,
#: docs/swing.md)
FABRICS = {
    "cotton_jersey": Fabric("cotton jersey", density=0.16, tensile=400.0, shear=60.0,
                            bending=2.0e-6, friction=0.5, thickness=0.0006,
                            stretch_limit=0.05),
    "fleece": Fabric("polyester fleece", density=0.28, tensile=250.0, shear=40.0,
                     bending=8.0e-6, friction=0.6, thickness=0.002, stretch_limit=0.05),
    "cotton_twill": Fabric("cotton twill", density=0.22, tensile=2000.0, shear=150.0,
                           bending=1.5e-5, friction=0.5, thickness=0.0007, stretch_limit=0.05),
}


@dataclass(frozen=True)
class Fit:
    """How a garment is cut: spacing (m) of its rows and columns; ease (m) between the body
    and the garment at its loosest part (chest, thighs); band_ease (m) at an elastic band;
    length (-) of sleeves as a share of the upper arm, of a skirt as a share of the thigh;
    elastic (-): an elastic band's rest girth as a share of its cut girth; min_gap (m): the
    least distance from the body after fitting; flare (deg): a skirt's opening angle; split:
    edges longer than this many spacings are split at their middle after sewing; shortest:
    edges shorter than this many spacings are lengthened after sewing (a tube that narrows,
    a pants leg to its cuff, keeps its columns: its ring edges shorten with its girth, and
    lengthened they buckle the ring over itself)."""
    spacing: float = param(0.018, "m", ge=0.004, le=0.1, cost=("points", -2))
    ease: float = param(0.02, "m", ge=0.0, le=0.3)
    band_ease: float = param(0.004, "m", ge=0.0, le=0.1)
    length: float = param(0.5, "-", ge=0.05, le=1.5)
    elastic: float = param(0.92, "-", ge=0.5, le=1.0)
    min_gap: float = param(0.008, "m", ge=0.0, le=0.05)
    flare: float = param(14.0, "deg", ge=0.0, le=60.0)
    split: float = param(1.6, "-", ge=1.2, le=10.0)
    shortest: float = param(0.6, "-", ge=0.0, le=1.0)


@dataclass
class Garment:
    """A garment mesh (see the module docstring). groups: name -> vertex indices; rings:
    structural edges (k,2) with their rest-length factor (k,) (elastic bands < 1); sizes:
    the girths and lengths (m) it was cut to; fabric: its Fabric."""
    name: str
    vertices: np.ndarray
    triangles: np.ndarray
    fabric: Fabric
    groups: dict = field(default_factory=dict)
    ring_edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    ring_factor: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sizes: dict = field(default_factory=dict)
    parts: tuple = ()  # garments joined into this one (``join``), each with its own fabric

    @property
    def area(self) -> float:
        v, t = self.vertices, self.triangles
        return float(0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]],
                                                   v[t[:, 2]] - v[t[:, 0]]), axis=1).sum())

    @property
    def mass(self) -> float:
        if self.parts:
            return float(sum(p.mass for p in self.parts))
        return self.area * self.fabric.density


# --- mesh assembly --------------------------------------------------------------------------------
class _Builder:
    def __init__(self):
        self.x: list = []
        self.tris: list = []

    def add(self, pts) -> np.ndarray:
        n = sum(len(p) for p in self.x)
        self.x.append(np.asarray(pts, float).reshape(-1, 3))
        return np.arange(n, n + len(self.x[-1]))

    def band(self, a, b, closed=True):
        """Quads (two triangles each, diagonals alternating) between index rows a and b."""
        a, b = np.asarray(a), np.asarray(b)
        m = len(a) if closed else len(a) - 1
        for i in range(m):
            j = (i + 1) % len(a)
            if i % 2:
                self.tris += [[a[i], a[j], b[j]], [a[i], b[j], b[i]]]
            else:
                self.tris += [[a[i], a[j], b[i]], [a[j], b[j], b[i]]]

    def bridge(self, a, ta, b, tb):
        """Triangles between closed index rows a and b of any lengths, their vertices at
        increasing angles ta, tb (rad) from 0: each next triangle steps along the row whose
        next vertex comes first round the ring (a gore's rows, rows of equal length as
        ``band`` with its diagonals all one way)."""
        if len(a) == len(b):
            return self.band(a, b)
        na, nb = len(a), len(b)
        ta, tb = np.append(ta, 2 * np.pi), np.append(tb, 2 * np.pi)
        i = j = 0
        while i < na or j < nb:
            if j == nb or (i < na and ta[i + 1] <= tb[j + 1]):
                self.tris.append([a[i], a[(i + 1) % na], b[j % nb]])
                i += 1
            else:
                self.tris.append([a[i % na], b[(j + 1) % nb], b[j]])
                j += 1

    def arrays(self):
        return np.concatenate(self.x), np.asarray(self.tris, np.int64)


#: m: below its waistband a skirt's ease grows from the band's to the fit's over this much (a
#: yoke): the full ease one row below the band made a shelf of long edges there
SKIRT_YOKE = 0.05


def _columns(circumference, spacing, multiple=4):
    return max(multiple * 3, int(multiple * round(circumference / spacing / multiple)))


def _blend_tube(b, loop, loop_x, axis_pts, u, w, surface, seg_idx, offsets, spacing,
                blend_rows=5, centres=None):
    """Rows from a loop (indices, positions) to rings about axis_pts (r,3) in planes (u, w)
    (per row; the rings' rays cast from ``centres``, default axis_pts), matched by arc length
    from the loop vertex nearest angle 0; returns row index arrays (the loop first)."""
    centres = axis_pts if centres is None else centres
    L = len(loop)
    seg = np.linalg.norm(np.roll(loop_x, -1, axis=0) - loop_x, axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)[:-1]]) / seg.sum()
    c0 = axis_pts[0]
    rel = loop_x - c0
    phi0 = np.arctan2(rel @ w[0], rel @ u[0])
    # the loop's direction of travel about the axis sets the rings' sense
    turn = np.sum(np.angle(np.exp(1j * (np.roll(phi0, -1) - phi0))))
    sense = 1.0 if turn > 0 else -1.0
    angles = phi0[0] + sense * 2 * np.pi * s
    rows = [np.asarray(loop)]
    for k in range(1, len(axis_pts)):
        ring = BF.ring(surface, seg_idx, centres[k], u[k], w[k], angles, offsets[k])
        beta = min(1.0, k / blend_rows)
        pts = (1 - beta) * (loop_x + (axis_pts[k] - c0)) + beta * ring
        rows.append(b.add(pts))
        b.band(rows[-2], rows[-1])
    return rows


def _perp(a):
    a = a / np.linalg.norm(a)
    u = np.cross(a, [0.0, 0.0, 1.0] if abs(a[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    return u, np.cross(a, u)


def _rows_along(p0, p1, spacing):
    n = max(2, int(np.ceil(np.linalg.norm(p1 - p0) / spacing)) + 1)
    return p0 + np.linspace(0, 1, n)[:, None] * (p1 - p0)


def _finish(name, b, surface, fabric, fit, groups, rings, sizes) -> Garment:
    x, t = b.arrays()
    # drop the vertices welded away at the seams and renumber
    used = np.zeros(len(x), bool)
    used[t.ravel()] = True
    new = np.cumsum(used) - 1
    x, t = x[used], new[t]
    groups = {k: new[np.asarray(v)[used[np.asarray(v)]]] for k, v in groups.items()}
    rings = [(new[r], f) for r, f in rings]
    # where a sleeve or leg blends from its armhole or crotch loop into rings about the limb,
    # or the panels close at a seam, some edges come out long: split them
    for _ in range(3):  # the push out of the body may lengthen edges again: split anew
        x, t, groups, rings = split_long_edges(x, t, groups, rings, fit.split * fit.spacing)
        # and where rows crowd (a crotch loop's chain beside the first leg row) edges come
        # out short: a short edge is a stiff spring that a millimetre's contact push strains
        # by tens of percent. Even the edges out towards [0.6, 1.6] spacings
        x = even_out(x, t, fit.shortest * fit.spacing, fit.split * fit.spacing)
        # dressing's first step: nothing closer to the body than min_gap (against the skin's
        # triangles, which the cloth collides with: in a crease they stand off the smooth
        # body by a chord's sag)
        for _ in range(4):
            d, n = surface.mesh_distance(x)
            close = d < fit.min_gap
            if not close.any():
                break
            x[close] += (fit.min_gap + 1e-4 - d[close])[:, None] * n[close]
        e, _, _ = mesh_edges(t)
        if np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1).max() <= fit.split * fit.spacing:
            break
    if rings:
        re = np.concatenate([r[0] for r in rings])
        rf = np.concatenate([np.full(len(r[0]), r[1]) for r in rings])
    else:
        re, rf = np.zeros((0, 2), np.int64), np.zeros(0)
    g = Garment(name, x, t, fabric, groups, re, rf, sizes)
    check_garment(g, surface)
    return g


def _ring_edges(rows):
    return np.concatenate([np.stack([r, np.roll(r, -1)], 1) for r in rows])


def _outside(ring, centre_xy, z, under, gap, spacing):
    """A horizontal ring pushed out to ``gap`` (m) beyond the under-garment's vertices near
    its height, direction by direction (a tee over the pants' waistband)."""
    if under is None:
        return ring
    near = under.vertices[np.abs(under.vertices[:, 2] - z) < 1.5 * spacing]
    if len(near) == 0:
        return ring
    rel = near[:, :2] - centre_xy
    ang = np.arctan2(rel[:, 1], rel[:, 0])
    rad = np.linalg.norm(rel, axis=1)
    d = ring[:, :2] - centre_xy
    a = np.arctan2(d[:, 1], d[:, 0])
    r = np.linalg.norm(d, axis=1)
    width = 2.5 * spacing / np.maximum(r, 1e-3)
    diff = np.abs(np.angle(np.exp(1j * (a[:, None] - ang[None, :]))))
    need = np.where(diff < width[:, None], rad[None, :], 0.0).max(axis=1) + gap
    scale = np.maximum(1.0, need / np.maximum(r, 1e-9))
    out = ring.copy()
    out[:, :2] = centre_xy + d * scale[:, None]
    return out


def _torso_body(surface, fit, fabric, sleeves: bool, name: str, over=None) -> Garment:
    """The tee's (and vest's) body: front and back panels sewn at the sides and shoulders,
    armholes left open (sleeves sewn in when ``sleeves``); ``over``: a garment under it (its
    rings kept ``fit.ease`` / 2 outside that garment's vertices)."""
    P = {s.name: k for k, s in enumerate(surface.plan)}
    trunk = BF.parts(surface, ("torso", "pelvis", "l_thigh", "r_thigh"))
    pos0 = surface.pos0
    z_hip = pos0[P["l_thigh"], 2]
    z_sh = pos0[P["l_upper_arm"], 2]
    z_top = pos0[P["head"], 2]
    r_arm = float(surface.plan[P["l_upper_arm"]].shape[1])
    z_pit = z_sh - 1.9 * r_arm
    z_hem = z_hip - 0.03
    axis_xy = np.array([pos0[P["torso"], 0], 0.0])
    chest = BF.ring(surface, trunk, np.array([*axis_xy, z_pit - 0.03]), np.array([1.0, 0, 0]),
                  np.array([0, 1.0, 0]), np.linspace(0, 2 * np.pi, 180, endpoint=False),
                  fit.ease)
    N = _columns(BF.circumference(chest), fit.spacing, 4)
    th = 2 * np.pi * np.arange(N) / N
    r_chest = BF.convex_radii(BF.ring(surface, trunk, np.array([*axis_xy, z_pit - 0.03]),
                                  np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), th, fit.ease),
                            axis_xy, th)
    zs = np.linspace(z_hem, z_top, max(4, int(np.ceil((z_top - z_hem) / fit.spacing)) + 1))
    i_pit = int(np.argmin(np.abs(zs - z_pit)))
    b = _Builder()
    rows = []
    # the armhole's half-width at the armpit, in columns: about an arm's radius
    m = int(np.clip(round(r_arm / (BF.circumference(chest) / N)), 1, N // 16))
    y_sh = float(pos0[P["l_upper_arm"], 1]) - 0.2 * r_arm  # the shoulder seam's outer end
    neck_half = 0.55 * float(surface.plan[P["head"]].shape[1])
    for i, z in enumerate(zs):
        ring = BF.ring(surface, trunk, np.array([*axis_xy, z]), np.array([1.0, 0, 0]),
                     np.array([0, 1.0, 0]), th, fit.ease)
        if z < z_pit:
            # cut straight below the chest: the panels hang across the waist's hollow
            rr = np.maximum(np.linalg.norm(ring[:, :2] - axis_xy, axis=1), r_chest)
            ring[:, :2] = axis_xy + rr[:, None] * np.stack([np.cos(th), np.sin(th)], 1)
        if i > i_pit:
            # above the armpits the front and back panels run up to the shoulder seam: their
            # columns spread from the armpit's width to the shoulders', each on the body's
            # front (back) surface plus the ease, closing front to back at the seam
            f = (z - zs[i_pit]) / (z_top - zs[i_pit])
            y_pit = np.abs(np.concatenate(b.x)[rows[i_pit]][N // 4 - m, 1])
            scale = 1.0 + f ** 2 * (y_sh / y_pit - 1.0)
            y = np.concatenate(b.x)[rows[i_pit]][:, 1] * scale
            front = np.cos(th) >= 0
            dirs = np.where(front[:, None], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0])
            c = np.stack([np.full(N, axis_xy[0]), y, np.full(N, z)], 1)
            r = BF.girth_radius(surface, trunk, c, dirs, fit.ease, allow_empty=True)
            # past the trunk's side (no body on the ray) the panel keeps the row below's depth
            below = np.abs(np.concatenate(b.x)[rows[-1]][:, 0] - axis_xy[0])
            r = np.where(r > 0, r, below)
            # the neck opening keeps its place on the body; the shoulders close to the seam
            shoulder = np.clip((np.abs(y) - neck_half) / 0.04, 0.0, 1.0)
            ring = c + (r * (1 - shoulder * f ** 3))[:, None] * dirs
        rows.append(b.add(_outside(ring, axis_xy, z, over, 0.5 * fit.ease, fit.spacing)))
    notch = set()
    for c in (N // 4, 3 * N // 4):
        notch |= {(c + d) % N for d in range(-m, m)}
    top = len(zs) - 1
    # the shoulder seam: top-row vertices of the front welded to their mirror at the back
    mirror = lambda j: (N // 2 - j) % N  # noqa: E731
    xt = np.concatenate(b.x)
    weld = {}
    for j in range(N):
        front = np.cos(th[j]) > 1e-9
        vj = rows[top][j]
        if front and abs(xt[vj, 1]) > neck_half + 0.04 - 1e-6:
            weld[rows[top][mirror(j)]] = vj
    for i in range(top):
        a, c = rows[i], rows[i + 1]
        for j in range(N):
            if i >= i_pit and j in notch:
                continue
            jj = (j + 1) % N
            quad = [a[j], a[jj], c[jj], c[j]]
            if (i + j) % 2:
                b.tris += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
            else:
                b.tris += [[quad[0], quad[1], quad[3]], [quad[1], quad[2], quad[3]]]
    # the welded top row: move each front seam vertex to the seam's midpoint
    x_all = np.concatenate(b.x)
    for back, front in weld.items():
        x_all[front] = 0.5 * (x_all[front] + x_all[back])
    b.x = [x_all]
    tri = np.asarray(b.tris)
    for back, front in weld.items():
        tri[tri == back] = front
    b.tris = tri.tolist()
    groups = {"hem": rows[0].copy()}
    armholes = []
    for side, c in (("left", N // 4), ("right", 3 * N // 4)):
        j0, j1 = (c - m) % N, (c + m) % N
        bottom = [rows[i_pit][(j0 + d) % N] for d in range(2 * m + 1)]
        back_up = [rows[i][j1] for i in range(i_pit + 1, top + 1)]
        front_down = [rows[i][j0] for i in range(top - 1, i_pit, -1)]
        loop = bottom + back_up + front_down
        loop = [weld.get(v, v) for v in loop]
        # drop the repeated welded top vertex (the back's top is the front's)
        dedup = [v for k, v in enumerate(loop) if v != loop[k - 1]]
        armholes.append((side, np.array(dedup)))
    for side, loop in armholes:
        groups[f"armhole_{side}"] = loop
    neck = [rows[top][j] for j in range(N) if rows[top][j] not in weld
            and rows[top][j] not in weld.values()]
    groups["neck"] = np.array(neck)
    sizes = {"chest_girth": BF.circumference(chest), "length": float(z_top - z_hem),
             "columns": N}
    if not sleeves:
        return _finish(name, b, surface, fabric, fit, groups, [], sizes)
    x_all = np.concatenate(b.x)
    for side, loop in armholes:
        seg = P[f"{side[0]}_upper_arm"]
        arm = BF.parts(surface, (f"{side[0]}_upper_arm",))
        a0 = surface.pos0[seg]
        bone = surface.rot0[seg] @ surface.plan[seg].bone
        L = float(np.linalg.norm(bone))
        a_dir = bone / L
        # the sleeve runs from the armhole's centre to its hem on the arm's axis
        c0 = x_all[loop].mean(axis=0)
        end = a0 + fit.length * L * a_dir
        nrow = max(4, int(np.ceil(np.linalg.norm(end - c0) / fit.spacing)) + 1)
        axis_pts = c0 + np.linspace(0, 1, nrow)[:, None] * (end - c0)
        svals = (axis_pts - a0) @ a_dir
        u, w = _perp(a_dir)
        U, W = np.tile(u, (len(svals), 1)), np.tile(w, (len(svals), 1))
        offs = np.full(len(svals), fit.ease * 0.8)
        on_axis = a0 + np.maximum(svals, 0.25 * L)[:, None] * a_dir
        # a sleeve is short: it morphs from the armhole to its hem ring over its whole length
        srows = _blend_tube(b, loop, x_all[loop], axis_pts, U, W, surface, arm, offs,
                            fit.spacing, blend_rows=len(axis_pts) - 1, centres=on_axis)
        groups[f"cuff_{side}"] = srows[-1].copy()
        sizes[f"sleeve_{side}_length"] = float(svals[-1] - svals[0])
        x_all = np.concatenate(b.x)
    return _finish(name, b, surface, fabric, fit, groups, [], sizes)


def tee(surface: BodySurface, fit: Fit = Fit(), fabric: Fabric = FABRICS["cotton_jersey"],
        name: str = "tee", over: Garment | None = None) -> Garment:
    """A short-sleeved tee-shirt fitted to the body: hem at the hips, sleeves ``fit.length``
    of the upper arm, ``fit.ease`` at the chest; ``over``: a garment it is worn over."""
    return _torso_body(surface, fit, fabric, True, name, over)


def vest(surface: BodySurface, fit: Fit = Fit(), fabric: Fabric = FABRICS["cotton_jersey"],
         name: str = "vest", over: Garment | None = None) -> Garment:
    """A sleeveless tee (a vest): the tee's front and back panels, armholes open."""
    return _torso_body(surface, fit, fabric, False, name, over)


#: the pants' cut: their legs narrow from the thigh to the ankle with the same columns, the
#: cuffs' ring edges 0.5 spacings long; held to 0.6 spacings the cuffs' rings buckled over
#: each other (66 crossing triangle pairs in the runner's cut, none at 0.3)
PANTS_FIT = Fit(ease=0.025, shortest=0.3)


def sweatpants(surface: BodySurface, fit: Fit = PANTS_FIT,
               fabric: Fabric = FABRICS["fleece"], name: str = "pants") -> Garment:
    """Sweat pants: a waistband (elastic) at the waist, the seat down to the crotch, two legs
    sewn to the crotch seam, elastic cuffs above the ankles."""
    P = {s.name: k for k, s in enumerate(surface.plan)}
    pos0 = surface.pos0
    hips = BF.parts(surface, ("pelvis", "l_thigh", "r_thigh"))
    z_w = pos0[P["torso"], 2] - 0.01
    z_hip = pos0[P["l_thigh"], 2]
    r_th = float(surface.plan[P["l_thigh"]].shape[1])
    z_c = z_hip - 0.8 * r_th  # the crotch
    band = 0.035  # m: waistband and cuff height
    probe = BF.ring(surface, hips, np.array([0.0, 0.0, z_hip]), np.array([1.0, 0, 0]),
                  np.array([0, 1.0, 0]), np.linspace(0, 2 * np.pi, 180, endpoint=False),
                  fit.ease)
    N = _columns(BF.circumference(probe), fit.spacing, 4)
    th = 2 * np.pi * np.arange(N) / N
    zs = np.linspace(z_w, z_c, max(3, int(np.ceil((z_w - z_c) / fit.spacing)) + 1))
    b = _Builder()
    rows = []
    for z in zs:
        off = fit.band_ease if z > z_w - band else fit.ease * min(1.0, (z_w - z) / 0.1)
        rows.append(b.add(BF.ring(surface, hips, np.array([0.0, 0.0, z]), np.array([1.0, 0, 0]),
                                np.array([0, 1.0, 0]), th, off)))
    for a, c in zip(rows[:-1], rows[1:]):
        b.band(a, c)
    crotch = rows[-1]
    x_all = np.concatenate(b.x)
    front, back = x_all[crotch[0]], x_all[crotch[N // 2]]
    C = max(1, int(np.ceil(np.linalg.norm(front - back) / fit.spacing)) - 1)
    chain_x = back + np.linspace(0, 1, C + 2)[1:-1, None] * (front - back)
    chain_x[:, 2] -= 0.01
    chain = b.add(chain_x)  # back to front
    groups = {"waist": rows[0].copy(),
              "waistband": np.concatenate([r for z, r in zip(zs, rows) if z > z_w - band])}
    # the elastic band grips: its points ride the skin (systems.garments.Garments.ride)
    groups["pinned"] = groups["waistband"].copy()
    rings = [(_ring_edges([r for z, r in zip(zs, rows) if z > z_w - band]), fit.elastic)]
    sizes = {"waist_girth": float(BF.circumference(np.concatenate(b.x)[rows[0]])),
             "hip_girth": BF.circumference(probe), "columns": N}
    for side in ("l", "r"):
        if side == "l":
            loop = np.concatenate([crotch[: N // 2 + 1], chain])
        else:
            loop = np.concatenate([crotch[N // 2:], crotch[:1], chain[::-1]])
        x_all = np.concatenate(b.x)
        hip_j, knee, ankle = (pos0[P[f"{side}_thigh"]], pos0[P[f"{side}_shank"]],
                              pos0[P[f"{side}_foot"]])
        z_cuff = ankle[2] + 0.035
        start = x_all[loop].mean(axis=0)
        zl = np.linspace(start[2], z_cuff, max(6, int(np.ceil((start[2] - z_cuff)
                                                                / fit.spacing)) + 1))

        def axis_at(z):
            if z >= knee[2]:
                f = (hip_j[2] - z) / (hip_j[2] - knee[2])
                return hip_j + f * (knee - hip_j)
            f = (knee[2] - z) / (knee[2] - ankle[2])
            return knee + f * (ankle - knee)

        axis_pts = np.array([axis_at(z) for z in zl])
        axis_pts[0] = start
        U = np.tile([1.0, 0.0, 0.0], (len(zl), 1))
        W = np.tile([0.0, 1.0, 0.0], (len(zl), 1))
        leg = BF.parts(surface, (f"{side}_thigh", f"{side}_shank"))
        offs = np.where(zl < z_cuff + band, fit.band_ease, fit.ease)
        lrows = _blend_tube(b, loop, x_all[loop], axis_pts, U, W, surface, leg, offs,
                            fit.spacing)
        cuff = [r for z, r in zip(zl, lrows) if z < z_cuff + band]
        groups[f"cuff_{side}"] = lrows[-1].copy()
        groups[f"cuffband_{side}"] = np.concatenate(cuff)
        # the cuffs are cut to the ankle with band_ease, at rest (not pre-stretched): an
        # elastic cuff contracting around the ankle against the skin contact caught on the
        # foot in the first steps (a stiff ring in a position-level contact)
        rings.append((_ring_edges(cuff), 1.0))
        sizes[f"inseam_{side}"] = float(z_c - z_cuff)
    groups["crotch_seam"] = chain.copy()
    return _finish(name, b, surface, fabric, fit, groups, rings, sizes)


def skirt(surface: BodySurface, fit: Fit = Fit(length=0.75, ease=0.01),
          fabric: Fabric = FABRICS["cotton_twill"], name: str = "skirt") -> Garment:
    """An A-line skirt cut in gores: an elastic waistband fitted to the body at the waist,
    below it the skirt flaring by ``fit.flare`` degrees, its ease growing from the band's to
    ``fit.ease`` over SKIRT_YOKE, its hem ``fit.length`` of the thigh below the hip joints.
    Each row has the columns its girth holds at the spacing (``_columns``; the gores): with
    the hem's columns all the way up, the waist's ring edges were a third of the spacing,
    and lengthened after sewing (``Fit.shortest``) they buckled the waist over itself (563
    crossing triangle pairs in the cut skirt)."""
    P = {s.name: k for k, s in enumerate(surface.plan)}
    pos0 = surface.pos0
    hips = BF.parts(surface, ("pelvis", "l_thigh", "r_thigh", "l_shank", "r_shank"))
    z_w = pos0[P["torso"], 2] - 0.01
    thigh = float(np.linalg.norm(surface.plan[P["l_thigh"]].bone))
    z_hem = pos0[P["l_thigh"], 2] - fit.length * thigh
    zs = np.linspace(z_w, z_hem, max(4, int(np.ceil((z_w - z_hem) / fit.spacing)) + 1))
    probe = np.linspace(0, 2 * np.pi, 180, endpoint=False)

    def radii(z, ease):  # the body's ring at height z with that ease, at the probe's angles
        ring = BF.ring(surface, hips, np.array([0.0, 0.0, z]), np.array([1.0, 0, 0]),
                       np.array([0, 1.0, 0]), probe, ease, allow_empty=True)
        return np.linalg.norm(ring[:, :2], axis=1)

    r_w = radii(z_w, fit.band_ease)  # (the skirt's waistband grips like the pants')
    tan = np.tan(np.radians(fit.flare))
    band = 0.03
    b = _Builder()
    rows, angles = [], []
    for z in zs:
        depth = z_w - z
        if depth < band:  # the waistband, fitted where it sits
            r = np.maximum(radii(z, fit.band_ease), r_w)
        else:
            f = min(1.0, (depth - band) / SKIRT_YOKE)
            ease = fit.band_ease + (fit.ease - fit.band_ease) * f * f * (3 - 2 * f)
            r = np.maximum(radii(z, ease), r_w + depth * tan)
        ring = np.stack([r * np.cos(probe), r * np.sin(probe)], 1)
        th = 2 * np.pi * np.arange(_columns(BF.circumference(ring), fit.spacing, 4))
        th /= len(th)
        rr = np.interp(th, probe, r, period=2 * np.pi)
        rows.append(b.add(np.stack([rr * np.cos(th), rr * np.sin(th), np.full(len(th), z)], 1)))
        angles.append(th)
        if len(rows) > 1:
            b.bridge(rows[-2], angles[-2], rows[-1], angles[-1])
    bandrows = [r for z, r in zip(zs, rows) if z > z_w - band]
    groups = {"waist": rows[0].copy(), "waistband": np.concatenate(bandrows),
              "hem": rows[-1].copy(), "pinned": np.concatenate(bandrows)}
    x = np.concatenate(b.x)
    sizes = {"waist_girth": BF.circumference(x[rows[0]]), "length": float(z_w - z_hem),
             "hem_girth": BF.circumference(x[rows[-1]]), "columns": len(rows[-1]),
             "waist_columns": len(rows[0])}
    return _finish(name, b, surface, fabric, fit, groups,
                   [(_ring_edges(bandrows), fit.elastic)], sizes)


def join(name: str, *garments: Garment) -> Garment:
    """Several garments as one mesh (one network: their contacts with each other are its
    self-contacts); groups are renamed "<garment>.<group>" and keep their vertices."""
    xs, ts, groups, re, rf, sizes = [], [], {}, [], [], {}
    base = 0
    for g in garments:
        xs.append(g.vertices)
        ts.append(g.triangles + base)
        for k, v in g.groups.items():
            groups[f"{g.name}.{k}"] = v + base
        groups[g.name] = np.arange(base, base + len(g.vertices))
        re.append(g.ring_edges + base)
        rf.append(g.ring_factor)
        sizes.update({f"{g.name}.{k}": v for k, v in g.sizes.items()})
        base += len(g.vertices)
    # the fabric of the first is the drawn one; masses are per garment (density below)
    return Garment(name, np.concatenate(xs), np.concatenate(ts), garments[0].fabric, groups,
                   np.concatenate(re), np.concatenate(rf), sizes, tuple(garments))
