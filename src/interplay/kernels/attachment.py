"""Attachments (``interactions.attachment``): ties between network points and points fixed on
rigid parts, evaluated for all the ties of one interaction in one call (a coupling step of a
kite evaluates five of them: the Python of a few dozen small NumPy operations per tie set
cost more than the kite's line and tail together).

Tie j joins network point index[j] to the point local[j] (m, in part parts[j]'s frame) on a
rigid part; ``inv[j]`` is that part's row in the velocities asked for once per tied part.
Each tie is a zero-length spring of stiffness k (N/m) and damping c (N s/m). The arithmetic
is written out in the order NumPy's vectorised form evaluated it (elementwise, rows summed
in order), so the interaction's results are bit for bit what they were before it moved here.
"""
import numpy as np
from numba import njit


@njit(cache=True)
def tie_points(pos, rot, centres, lin, ang, parts, inv, local, p, v):
    """World tie points p (m) and their velocities v (m/s), (n,3) each, from the parts'
    origins pos (k,3), rotations rot (k,3,3), centres of mass centres (k,3) and the tied
    parts' linear lin (u,3) and angular ang (u,3) velocities: p = pos + R local,
    v = lin + ang x (p - centre)."""
    for j in range(parts.shape[0]):
        q, u = parts[j], inv[j]
        for a in range(3):  # summed as np.einsum sums a row (the first and last, then the middle)
            p[j, a] = pos[q, a] + ((rot[q, a, 0] * local[j, 0] + rot[q, a, 2] * local[j, 2])
                                   + rot[q, a, 1] * local[j, 1])
        r0 = p[j, 0] - centres[q, 0]
        r1 = p[j, 1] - centres[q, 1]
        r2 = p[j, 2] - centres[q, 2]
        v[j, 0] = lin[u, 0] + (ang[u, 1] * r2 - ang[u, 2] * r1)
        v[j, 1] = lin[u, 1] + (ang[u, 2] * r0 - ang[u, 0] * r2)
        v[j, 2] = lin[u, 2] + (ang[u, 0] * r1 - ang[u, 1] * r0)


@njit(cache=True)
def tie_forces(x, xv, index, p, v, h, k, c, f):
    """f (n,3) N: each tie's pull on its part, k (x - (p + h v)) + c (xv - v), with the
    network point at x, moving at xv ((m,3) m and m/s, rows index) and the tie point p moving
    on at v for h s (h = 0: now)."""
    for j in range(index.shape[0]):
        i = index[j]
        for a in range(3):
            f[j, a] = k * (x[i, a] - (p[j, a] + h * v[j, a])) + c * (xv[i, a] - v[j, a])


@njit(cache=True)
def tie_wrenches(p, f, centres, parts, inv, com, force, moment):
    """Sum the ties' forces f (n,3) N into one force per tied part (force (u,3), zeroed
    here) and their moments about each part's centre of mass (moment (u,3) N m); return the
    total force (3,) and the total moment about com (3,) m, the system's centre of mass."""
    force[:] = 0.0
    moment[:] = 0.0
    total = np.zeros(3)
    torque = np.zeros(3)
    for j in range(parts.shape[0]):
        q, u = parts[j], inv[j]
        r0 = p[j, 0] - centres[q, 0]
        r1 = p[j, 1] - centres[q, 1]
        r2 = p[j, 2] - centres[q, 2]
        f0, f1, f2 = f[j, 0], f[j, 1], f[j, 2]
        _add_force(force[u], moment[u], r0, r1, r2, f0, f1, f2)
        _add_force(total, torque, p[j, 0] - com[0], p[j, 1] - com[1], p[j, 2] - com[2],
                   f0, f1, f2)
    return total, torque


@njit(cache=True, inline="always")
def _add_force(force, moment, r0, r1, r2, f0, f1, f2):
    """force (3,) += f, moment (3,) += r x f (r from the point the moment is about)."""
    force[0] += f0
    force[1] += f1
    force[2] += f2
    moment[0] += r1 * f2 - r2 * f1
    moment[1] += r2 * f0 - r0 * f2
    moment[2] += r0 * f1 - r1 * f0


@njit(cache=True)
def carried_load(x, acc, m, index, held, centre, r, load):
    """The load a carried network puts on its part: each point's mass times its acceleration
    acc (n,3) m/s^2 less the ties' held forces held (rows index) into load (n,3) N, the
    points' offsets r (n,3) m from the part's centre (3,); returns (total force (3,) N, its
    moment about the centre (3,) N m, the mass moment sum m r (3,) kg m)."""
    n = x.shape[0]
    for i in range(n):
        for a in range(3):
            load[i, a] = acc[i, a] * m[i]
            r[i, a] = x[i, a] - centre[a]
    for j in range(index.shape[0]):
        for a in range(3):
            load[index[j], a] -= held[j, a]
    force = np.zeros(3)
    moment = np.zeros(3)
    mass_moment = np.zeros(3)
    for i in range(n):
        r0, r1, r2 = r[i, 0], r[i, 1], r[i, 2]
        _add_force(force, moment, r0, r1, r2, load[i, 0], load[i, 1], load[i, 2])
        mass_moment[0] += m[i] * r0
        mass_moment[1] += m[i] * r1
        mass_moment[2] += m[i] * r2
    return force, moment, mass_moment
