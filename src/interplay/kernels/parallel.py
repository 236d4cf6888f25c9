"""Race-free parallel spring forces for large networks.

Scattering each spring's force onto its two points from several threads would race on shared
points. Instead the forces are computed per spring in parallel into their own rows, then every
point gathers the forces of its incident springs over a CSR adjacency (point -> springs, with
the sign of its end), again in parallel and without shared writes. The per-spring arithmetic is
the serial kernel's (``springs.network_forces``); only the order of the sums differs, so results
agree to round-off.

It is opt-in (``SpringNetwork(parallel=True)``): DESIGN.md measured 1.9x on 2 threads at 59k
springs, but on this project's 2-core machines (`bench_cloth.py`, 4.9k-326k springs) it ran
0.5-0.9x the serial step with the other core busy (2026-11-22) and 0.26-0.93x with it idle
(2026-12-01): the extra pass over the per-spring buffer and the thread start-up cost more than
the second core gives. Measure on your machine before turning it on.
"""
import numpy as np
from numba import njit, prange

from .springs import spring_pull


def adjacency(n, si, sj, a_idx):
    """(indptr, spring ids, sign, anchor indptr, anchor ids, scratch): the CSR of point ->
    incident springs (sign +1 at si, -1 at sj), of point -> anchors, and an (s,3) buffer."""
    def csr(ends, ids):
        order = np.argsort(ends, kind="stable")
        indptr = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(ends, minlength=n), out=indptr[1:])
        return indptr, ids[order].astype(np.int64), order
    s = np.arange(len(si))
    indptr, ids, order = csr(np.concatenate([si, sj]), np.concatenate([s, s]))
    sign = np.concatenate([np.ones(len(si)), -np.ones(len(sj))])[order]
    a_ptr, a_ids, _ = csr(np.asarray(a_idx, dtype=np.int64), np.arange(len(a_idx)))
    return indptr, ids, sign, a_ptr, a_ids, np.empty((len(si), 3))


@njit(cache=True, parallel=True)
def explicit_step(net, fext, f, h, nsteps, adj):
    """``springs.explicit_step`` (nsteps symplectic-Euler steps of h s on a springs.Network)
    with parallel forces: two parallel loops a step, per spring then per point (gather and
    update fused). adj: ``adjacency``'s arrays. (The loop bodies read plain arrays: Numba's
    parallel loops cannot take the bundles themselves.)"""
    x, v, m, fixed = net.pts
    si, sj, l0, k, kd, tension_only = net.springs
    a_pos, a_k, a_c = net.anchors.pos, net.anchors.k, net.anchors.c
    alpha, gravity = net.alpha, net.gravity
    indptr, ids, sign, a_ptr, a_ids, fs = adj
    g0, g1, g2 = gravity[0], gravity[1], gravity[2]
    for _ in range(nsteps):
        for s in prange(si.shape[0]):
            # fs[s] (N): the force of spring s on its point si[s] (minus it on sj[s])
            _, mag, d0, d1, d2 = spring_pull(x, v, si[s], sj[s], l0[s], k[s], kd[s],
                                             tension_only[s])
            fs[s, 0] = mag * d0
            fs[s, 1] = mag * d1
            fs[s, 2] = mag * d2
        for p in prange(x.shape[0]):
            # external, gravity, mass damping, the incident springs' forces and p's anchors
            f0 = fext[p, 0] + m[p] * (g0 - alpha * v[p, 0])
            f1 = fext[p, 1] + m[p] * (g1 - alpha * v[p, 1])
            f2 = fext[p, 2] + m[p] * (g2 - alpha * v[p, 2])
            for e in range(indptr[p], indptr[p + 1]):
                q = ids[e]
                sg = sign[e]
                f0 += sg * fs[q, 0]
                f1 += sg * fs[q, 1]
                f2 += sg * fs[q, 2]
            for e in range(a_ptr[p], a_ptr[p + 1]):
                r = a_ids[e]
                f0 += -a_k[r] * (x[p, 0] - a_pos[r, 0]) - a_c[r] * v[p, 0]
                f1 += -a_k[r] * (x[p, 1] - a_pos[r, 1]) - a_c[r] * v[p, 1]
                f2 += -a_k[r] * (x[p, 2] - a_pos[r, 2]) - a_c[r] * v[p, 2]
            f[p, 0] = f0
            f[p, 1] = f1
            f[p, 2] = f2
            if fixed[p]:
                continue
            for c in range(3):
                v[p, c] += h * f[p, c] / m[p]
                x[p, c] += h * v[p, c]
