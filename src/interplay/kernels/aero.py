"""Per-triangle aerodynamic drag and lift (SPEC 2.2), spread over each triangle's points.

For triangle t with unit normal n, area s and velocity relative to the wind v (the mean of
its three points' velocities minus the wind at its centroid):

    f = -c_n s |v| (n.v) n - c_t s (v - (n.v) n)

The normal term is quadratic (pressure drag; at an angle of attack it has a component across
the wind: lift), the tangential one linear (skin friction). It is the same for either normal
orientation, so meshes need no consistent winding. Each point gets f / 3.
"""
import numpy as np
from numba import njit


@njit(cache=True)
def centroids(x, tris, out):
    """out[t] = mean of triangle t's three points (m)."""
    for t in range(tris.shape[0]):
        for c in range(3):
            out[t, c] = (x[tris[t, 0], c] + x[tris[t, 1], c] + x[tris[t, 2], c]) / 3.0


@njit(cache=True)
def triangle_forces(x, v, tris, wind, cn, ct, f, dfdv, with_jacobian):
    """Add each triangle's force f/3 (N) to f (n,3) of its points; return the total force.

    wind (m,3): the wind velocity (m/s) at each centroid; cn (N s^2/m^4 per m^2 of area and
    (m/s)^2: kg/m^3), ct (kg/(m^2 s)). With with_jacobian, dfdv (n,3,3) receives a symmetric
    negative semidefinite d f / d v per point for implicit integrators: the triangle's
    -(c_n s (|v| + |n.v|) n n^T + c_t s (I - n n^T)) (the symmetric part of the exact
    derivative, exact when v is along n) lumped as 1/3 to each point (the row sum over the
    three points sharing the triangle's velocity). The loop is serial: the scatter to shared
    points stays race-free, and a scene's aerodynamic meshes are small next to its springs.
    """
    total = np.zeros(3)
    for t in range(tris.shape[0]):
        i, j, k = tris[t, 0], tris[t, 1], tris[t, 2]
        e10 = x[j, 0] - x[i, 0]
        e11 = x[j, 1] - x[i, 1]
        e12 = x[j, 2] - x[i, 2]
        e20 = x[k, 0] - x[i, 0]
        e21 = x[k, 1] - x[i, 1]
        e22 = x[k, 2] - x[i, 2]
        n0 = e11 * e22 - e12 * e21
        n1 = e12 * e20 - e10 * e22
        n2 = e10 * e21 - e11 * e20
        a2 = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if a2 == 0.0:
            continue
        n0 /= a2
        n1 /= a2
        n2 /= a2
        s = 0.5 * a2
        r0 = (v[i, 0] + v[j, 0] + v[k, 0]) / 3.0 - wind[t, 0]
        r1 = (v[i, 1] + v[j, 1] + v[k, 1]) / 3.0 - wind[t, 1]
        r2 = (v[i, 2] + v[j, 2] + v[k, 2]) / 3.0 - wind[t, 2]
        speed = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        vn = n0 * r0 + n1 * r1 + n2 * r2
        cnn = -cn * s * speed * vn
        f0 = cnn * n0 - ct * s * (r0 - vn * n0)
        f1 = cnn * n1 - ct * s * (r1 - vn * n1)
        f2 = cnn * n2 - ct * s * (r2 - vn * n2)
        total[0] += f0
        total[1] += f1
        total[2] += f2
        for p in (i, j, k):
            f[p, 0] += f0 / 3.0
            f[p, 1] += f1 / 3.0
            f[p, 2] += f2 / 3.0
        if with_jacobian:
            dn = cn * s * (speed + abs(vn))
            dt = ct * s
            nn = (n0, n1, n2)
            for p in (i, j, k):
                for a in range(3):
                    for b in range(3):
                        eye = 1.0 if a == b else 0.0
                        dfdv[p, a, b] -= (dn * nn[a] * nn[b] + dt * (eye - nn[a] * nn[b])) / 3.0
    return total
