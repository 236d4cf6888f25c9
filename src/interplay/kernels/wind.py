"""Wind as a sum of flow primitives (Wejchert & Haumann 1991), sampled at many points.

Each primitive is given at the sampling time by its kind, centre c (m), unit axis a, strength
and core radius r_c (m); the Python side (``systems.wind``) moves and gusts them. With d = p - c:

* UNIFORM: v = U a                                     (strength U, m/s)
* SOURCE (a sink is a negative source), 3D point form: v = q / (4 pi) d/|d| g(|d|)^2
                                                       (strength q, m^3/s)
* VORTEX, a line vortex along a through c: with d_perp = d - (d.a) a, r = |d_perp|,
  v = Gamma / (2 pi) g(r) (a x d_perp) / r              (strength Gamma, m^2/s)

where g(r) = r / (r^2 + r_c^2) regularizes 1/r (our choice, SPEC 2.2): it equals 1/r far from
the core, peaks at r = r_c and vanishes at the centre instead of diverging.

* TURBULENCE: frozen turbulence carried along with c (Taylor's hypothesis): a sum of Fourier
  modes v = sum_m s A_m cos(k_m . d + phi_m), each divergence-free (A_m perpendicular to k_m);
  modes (M, 8) rows [owner primitive, k (1/m), A (unit rms), phi (rad)], strength s (m/s rms).
"""
import numpy as np
from numba import njit

UNIFORM, SOURCE, VORTEX, TURBULENCE = 0, 1, 2, 3


@njit(cache=True)
def sample(points, kind, centre, axis, strength, core, modes, out):
    """out[i] = sum over primitives of their velocity (m/s) at points[i] (m)."""
    inv4pi = 1.0 / (4.0 * np.pi)
    inv2pi = 1.0 / (2.0 * np.pi)
    for i in range(points.shape[0]):
        o0 = 0.0
        o1 = 0.0
        o2 = 0.0
        for q in range(kind.shape[0]):
            a0, a1, a2 = axis[q, 0], axis[q, 1], axis[q, 2]
            s = strength[q]
            if kind[q] == UNIFORM:
                o0 += s * a0
                o1 += s * a1
                o2 += s * a2
                continue
            d0 = points[i, 0] - centre[q, 0]
            d1 = points[i, 1] - centre[q, 1]
            d2 = points[i, 2] - centre[q, 2]
            rc2 = core[q] * core[q]
            if kind[q] == TURBULENCE:
                for m in range(modes.shape[0]):
                    if int(modes[m, 0]) != q:
                        continue
                    c = s * np.cos(modes[m, 1] * d0 + modes[m, 2] * d1 + modes[m, 3] * d2
                                   + modes[m, 7])
                    o0 += c * modes[m, 4]
                    o1 += c * modes[m, 5]
                    o2 += c * modes[m, 6]
            elif kind[q] == SOURCE:
                r2 = d0 * d0 + d1 * d1 + d2 * d2
                if r2 == 0.0:
                    continue
                # q/(4 pi) (d/r) (r/(r^2+rc^2))^2 = q/(4 pi) d r / (r^2+rc^2)^2
                c = s * inv4pi * np.sqrt(r2) / ((r2 + rc2) * (r2 + rc2))
                o0 += c * d0
                o1 += c * d1
                o2 += c * d2
            else:
                da = d0 * a0 + d1 * a1 + d2 * a2
                p0 = d0 - da * a0
                p1 = d1 - da * a1
                p2 = d2 - da * a2
                r2 = p0 * p0 + p1 * p1 + p2 * p2
                if r2 == 0.0:
                    continue
                # Gamma/(2 pi) (r/(r^2+rc^2)) (a x d_perp)/r
                c = s * inv2pi / (r2 + rc2)
                o0 += c * (a1 * p2 - a2 * p1)
                o1 += c * (a2 * p0 - a0 * p2)
                o2 += c * (a0 * p1 - a1 * p0)
        out[i, 0] = o0
        out[i, 1] = o1
        out[i, 2] = o2
