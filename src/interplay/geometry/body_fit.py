"""Measuring a body for a garment (geometry/garment.py): rings fitted around its parts by
casting rays from an axis against the body's signed distance, at a given ease."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .body_surface import BodySurface, body_distance


def parts(surface: BodySurface, names):
    idx = [k for k, s in enumerate(surface.plan) if s.name in names]
    return idx


def girth_radius(surface, seg_idx, centre, dirs, offset, allow_empty=False):
    """Distance along each ray (centre (k,3) + r dirs (k,3)) to the outermost point within
    ``offset`` (m) of the solids ``seg_idx``: the ring that fits around them with that ease."""
    r = np.linspace(0.0, 0.45, 226)
    pts = (centre[:, None, :] + r[None, :, None] * dirs[:, None, :]).reshape(-1, 3)
    sol = [surface.solids[k] for k in seg_idx]
    d = body_distance(pts, sol, surface.pos0[seg_idx], surface.rot0[seg_idx],
                      surface.params.blend).reshape(len(dirs), len(r))
    inside = d <= offset
    last = np.where(inside.any(axis=1), len(r) - 1 - np.argmax(inside[:, ::-1], axis=1), 0)
    out = r[last]
    # refine between the last sample inside and the next by bisection
    if not allow_empty and not inside.any(axis=1).all():
        k = int(np.argmin(inside.any(axis=1)))
        raise ParameterError(f"garment fit: no body part around ray {k} from {centre[k]} "
                             f"towards {dirs[k]}; the garment reaches past the body here")
    lo, hi = out, np.minimum(out + r[1], r[-1])
    for _ in range(20):
        mid = 0.5 * (lo + hi)
        p = centre + mid[:, None] * dirs
        dm = body_distance(p, sol, surface.pos0[seg_idx], surface.rot0[seg_idx],
                           surface.params.blend)
        lo, hi = np.where(dm <= offset, mid, lo), np.where(dm <= offset, hi, mid)
    return np.where(inside.any(axis=1), lo, 0.0)


def ring(surface, seg_idx, centre, u, w, angles, offset, allow_empty=False):
    """Points of a ring about centre in the plane (u, w): at each angle, the fitted radius."""
    dirs = np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * w
    c = np.broadcast_to(centre, dirs.shape)
    r = girth_radius(surface, seg_idx, np.ascontiguousarray(c), dirs, offset, allow_empty)
    return c + r[:, None] * dirs


def convex_radii(ring, centre_xy, angles):
    """Radii at ``angles`` of the convex hull of a horizontal ring (a panel bridges hollows)."""
    from scipy.spatial import ConvexHull
    p = ring[:, :2] - centre_xy
    hull = p[ConvexHull(p).vertices]
    a, b = hull, np.roll(hull, -1, axis=0)
    out = np.zeros(len(angles))
    for k, t in enumerate(angles):
        d = np.array([np.cos(t), np.sin(t)])
        # ray-segment intersections: the hull contains the centre, one exit
        e = b - a
        den = d[0] * e[:, 1] - d[1] * e[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (a[:, 0] * e[:, 1] - a[:, 1] * e[:, 0]) / den
            u = (a[:, 0] * d[1] - a[:, 1] * d[0]) / den
        ok = (s > 0) & (u >= -1e-9) & (u <= 1 + 1e-9)
        out[k] = s[ok].max()
    return out


def circumference(p) -> float:
    return float(np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1).sum())
