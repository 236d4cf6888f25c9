"""A vest cut to a figure's torso (the alien's of the paper's short, Table I row 4): a
sleeveless tube round the torso's box from a hem above the waist to the shoulders, where two
straps go over the top of the box from the front panel to the back, leaving a wide neckline
(the noose's loop lies round the neck inside it) and an armhole over each side panel.

It is cut from the figure's own contact primitives (a physics figure's torso and pelvis are
rigid boxes, so they are exactly the body the vest touches, through the same two-way
rigid-parts contact as the noose and the trampoline): in the torso's frame (x forward, y to
the left, z up), a rounded rectangle ``ease`` outside the larger of the two boxes, rows of it
from the hem up to where the straps turn over the shoulder, then strap rows that turn over
the box's top edge and run across its top to meet their mirror image at x = 0 (one seam
point for each front/back pair). Every ring has the same points, so the mesh is a strip of
quads; above the armholes only the front and back panels' quads are kept, and over the top
only those at least ``neck`` from the midline.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SceneError
from .garment import FABRICS
from ..params import param


@dataclass(frozen=True)
class VestParams:
    """enabled: dress him in it (its one-way pass, at the 1e-4 s the jerk needs, costs several
    times the rest of the scene: false leaves it out; docs/owl-creek.md); coupling: the vest's (one-way: its pull on him is measured,
    not applied); mass (kg, the paper's 0.5 kg: a heavy lined vest); ease (m): its clearance
    outside the torso; hem (m): its lower edge above the torso's bottom (the waist: the bound
    forearms cross behind the back below it); neck (m): half the neckline's width, the
    straps' inner edge from the midline (clear of the noose's loop); spacing (m) of its
    points; fabric: the textile whose stiffness per areal density it has (a vest as heavy as
    the paper's is many layers' worth of it: shell, lining, interfacing, pockets), scaled to
    the vest's own density (docs/owl-creek.md); dt (s): its step (implicit) and cg_tolerance
    its solve's relative residual (the flags'); damping (s): stiffness-proportional, the
    fabric's hysteresis (a dropped garment does not spring back)."""
    enabled: bool = param(True, doc="false: no vest (its pass is the scene's slowest)")
    coupling: str = param("one-way", choices=("one-way", "two-way"))
    mass: float = param(0.5, "kg", ge=0.01, le=20.0)
    ease: float = param(0.01, "m", ge=0.002, le=0.1)
    hem: float = param(0.05, "m", ge=0.0, le=0.25)
    neck: float = param(0.095, "m", ge=0.03, le=0.2)
    spacing: float = param(0.02, "m", ge=0.008, le=0.1, cost="points")
    fabric: str = param("cotton_twill", choices=tuple(FABRICS))
    damping: float = param(0.005, "s", ge=0.0, le=1.0)
    dt: float = param(1e-4, "s", ge=1e-6, le=0.01)
    cg_tolerance: float = param(1e-5, "-", ge=1e-14, le=0.1, doc="implicit solve's residual")


def rounded_rect(ax: float, ay: float, r: float, n: int) -> np.ndarray:
    """(n,2) points evenly spaced by arc length round a rectangle of half extents ax, ay (m)
    with corners of radius r, starting on the left side's middle (0, ay) and going towards
    +x, so point k and point n - k are mirror images across x = 0."""
    sx, sy = ax - r, ay - r
    pieces = [("line", (0.0, ay), (sx, ay)), ("arc", (sx, sy), np.pi / 2, 0.0),
              ("line", (ax, sy), (ax, -sy)), ("arc", (sx, -sy), 0.0, -np.pi / 2),
              ("line", (sx, -ay), (-sx, -ay)), ("arc", (-sx, -sy), -np.pi / 2, -np.pi),
              ("line", (-ax, -sy), (-ax, sy)), ("arc", (-sx, sy), np.pi, np.pi / 2),
              ("line", (-sx, ay), (0.0, ay))]
    lengths = [np.hypot(*np.subtract(p[2], p[1])) if p[0] == "line" else r * np.pi / 2
               for p in pieces]
    at = np.r_[0.0, np.cumsum(lengths)]
    s = np.arange(n) * at[-1] / n
    out = np.empty((n, 2))
    for k, sk in enumerate(s):
        i = min(int(np.searchsorted(at, sk, side="right")) - 1, len(pieces) - 1)
        u = (sk - at[i]) / lengths[i] if lengths[i] > 0 else 0.0
        p = pieces[i]
        if p[0] == "line":
            out[k] = np.add(p[1], u * np.subtract(p[2], p[1]))
        else:
            a = p[2] + u * (p[3] - p[2])
            out[k] = (p[1][0] + r * np.cos(a), p[1][1] + r * np.sin(a))
    return out


#: m: the radius of the vest's vertical corners and of its turn over each shoulder, the
#: largest that clears a box's sharp edge by more than the contact skin at the default ease
#: (a radius q round an edge e outside it clears it by q - sqrt(2) (q - e): 5.9 mm here)
CORNER = 0.02


def vest_mesh(p: VestParams, torso, pelvis, torso_top: float):
    """(vertices (n,3), triangles (m,3)) of the vest in the torso's frame (m). torso,
    pelvis: (centre (3,), half extents (3,)) of the two boxes in that frame; torso_top: the
    top of the torso box (z, m), where the straps lie. The side panels end an armhole's
    depth (a third of the torso) below the shoulders; the front and back panels rise to
    where the straps turn over the shoulder on an arc of radius CORNER, then run flat over
    the top to the seam."""
    (tc, th), (pc, ph) = (np.asarray(a, float) for a in torso), (np.asarray(a, float)
                                                                  for a in pelvis)
    ax = max(abs(tc[0]) + th[0], abs(pc[0]) + ph[0]) + p.ease
    ay = max(abs(tc[1]) + th[1], abs(pc[1]) + ph[1]) + p.ease
    if p.neck >= ay - p.spacing:
        raise SceneError(f"vest: neck={p.neck} m leaves no straps on a torso {2 * ay:.3f} m "
                         f"wide; give vest.neck at most {ay - 2 * p.spacing:.3f}")
    top = torso_top + p.ease  # the straps' height over the shoulders
    turn = top - CORNER
    armpit = torso_top - 2.0 * th[2] / 3.0
    bottom = tc[2] - th[2] + p.hem
    if armpit <= bottom + p.spacing:
        raise SceneError(f"vest: hem={p.hem} m leaves no body below the armholes; give "
                         f"vest.hem less than {armpit - tc[2] + th[2] - p.spacing:.3f}")
    r = CORNER
    perimeter = 4 * (ax - r) + 4 * (ay - r) + 2 * np.pi * r
    n = 2 * int(np.ceil(perimeter / p.spacing / 2))  # even: mirror pairs k, n - k
    ring = rounded_rect(ax, ay, r, n)
    X = ring[:, 0]
    walls = np.linspace(bottom, turn, max(2, int(np.ceil((turn - bottom) / p.spacing)) + 1))
    rows = [np.c_[ring, np.full(n, z)] for z in walls]
    arc = max(2, int(np.ceil(0.5 * np.pi * CORNER / p.spacing)))
    for a in np.linspace(0.0, 0.5 * np.pi, arc + 1)[1:]:  # over the shoulder's edge
        rows.append(np.c_[X - np.sign(X) * CORNER * (1.0 - np.cos(a)), ring[:, 1],
                          np.full(n, turn + CORNER * np.sin(a))])
    flat = max(1, int(np.ceil((ax - CORNER) / p.spacing)))
    for v in np.linspace(0.0, 1.0, flat + 1)[1:]:  # across the top to the seam at x = 0
        rows.append(np.c_[(X - np.sign(X) * CORNER) * (1.0 - v), ring[:, 1], np.full(n, top)])
    x = np.concatenate(rows)
    R = len(rows)
    idx = np.arange(R * n).reshape(R, n)
    # the panels that rise above the armholes (front and back, with their corners: not the
    # side panels under the arms); of them, the straps (off the neckline) go over the top
    panel = np.abs(X) >= ax - r - 1e-9
    strap = panel & (np.abs(ring[:, 1]) >= p.neck)
    z_row = np.r_[walls, np.full(R - len(walls), top)]
    # the last row's front and back points are one seam point: k stands for n - k
    seam = idx[-1].copy()
    k = np.arange(1, n // 2)
    seam[n - k] = seam[k]
    idx[-1] = seam
    tris = []
    for row in range(R - 1):
        a, b = idx[row], idx[row + 1]
        keep = strap if row >= len(walls) - 1 else panel if z_row[row + 1] > armpit else None
        for k in range(n):
            k1 = (k + 1) % n
            if keep is not None and not (keep[k] and keep[k1]):
                continue  # an armhole, or the neckline
            quad = (a[k], a[k1], b[k1], b[k])
            if (row + k) % 2:  # alternate the diagonals: no preferred shear direction
                tris += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
            else:
                tris += [(quad[0], quad[1], quad[3]), (quad[1], quad[2], quad[3])]
    t = np.array(tris, np.int64)
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    used = np.unique(t)
    remap = np.full(len(x), -1, np.int64)
    remap[used] = np.arange(len(used))
    return x[used], remap[t]
