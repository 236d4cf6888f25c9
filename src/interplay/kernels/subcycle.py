"""Sub-cycling a spring-mass network against moving spheres inside one kernel call.

In a coupling step of length h the network takes n substeps of h/n. Each sphere moves along its
predicted path c(tau) = c0 + v tau (its own force changes its velocity by far less than the
cords' do over h), the sphere-cord contacts are evaluated at every substep, and the impulse
(force and torque integrated over the substeps) that the cords exert on each sphere is
returned. The scheduler then applies impulse / h to the sphere, so the exchange is equal and
opposite over the step and momentum is conserved exactly, while the light, stiff network is
integrated at its own small step without a Python call per substep.
"""
import numpy as np
from numba import njit

from .contact import sphere_segments
from .springs import implicit_step, network_forces, symplectic_update


@njit(cache=True)
def substep_with_spheres(x, v, m, fixed, si, sj, l0, k, kd, tension_only, a_idx, a_pos, a_k,
                         a_c, alpha, gravity, fext, kext, dext, kvref, f, h, nsub, implicit,
                         theta, bdf2, has_prev, xp, vp, tol, max_iter, seg, centres, velocities, spins, radii, masses,
                         accels, params, impulses):
    """Advance the network by h in nsub substeps with sphere contacts re-evaluated each substep.

    centres, velocities, spins, accels (k,3): sphere states at the start of the step and their
    free accelerations; radii, masses (k,); params (k,6): thickness, c_s, c_d, mu, eps,
    constraint(0/1); impulses (k,7) receives the force (0:3) and torque (3:6) integrated over
    the step (N s, N m s) and the peak force magnitude of any substep (6, N). fext, kext, dext, kvref hold the other external forces (constant).
    """
    n = x.shape[0]
    dt = h / nsub
    ns = seg.shape[0]
    out_idx = np.zeros(2 * ns, dtype=np.int64)
    out_f = np.zeros((2 * ns, 3))
    out_dfdx = np.zeros((2 * ns, 3, 3))
    out_dfdv = np.zeros((2 * ns, 3, 3))
    out_vref = np.zeros((2 * ns, 3))
    wrench = np.zeros(6)
    fe = np.empty_like(fext)
    ke = np.empty_like(kext)
    de = np.empty_like(dext)
    kv = np.empty_like(kvref)
    acc = np.empty_like(x)
    c = np.empty(3)
    lo = np.empty(3)
    hi = np.empty(3)
    for q in range(impulses.shape[0]):
        for r in range(7):
            impulses[q, r] = 0.0
    for step in range(nsub):
        tau = step * dt
        network_forces(x, v, m, si, sj, l0, k, kd, tension_only, a_idx, a_pos, a_k, a_c,
                       alpha, gravity, fext, f)
        for r in range(3):
            lo[r] = x[0, r]
            hi[r] = x[0, r]
        for i in range(1, n):
            for r in range(3):
                lo[r] = min(lo[r], x[i, r])
                hi[r] = max(hi[r], x[i, r])
        if implicit:
            fe[:] = fext
            ke[:] = kext
            de[:] = dext
            kv[:] = kvref
        have_acc = False
        for q in range(centres.shape[0]):
            far = False
            for r in range(3):
                c[r] = centres[q, r] + velocities[q, r] * tau + 0.5 * accels[q, r] * tau * tau
                reach = radii[q] + params[q, 0]
                if c[r] + reach < lo[r] or c[r] - reach > hi[r]:
                    far = True
            if far:  # the sphere misses the network's bounding box
                continue
            if not have_acc:  # free accelerations, for the contacts' constraint term
                for i in range(n):
                    for r in range(3):
                        acc[i, r] = f[i, r] / m[i]
                have_acc = True
            vq = velocities[q] + accels[q] * tau
            cnt = sphere_segments(c, vq, spins[q], radii[q], masses[q], accels[q], x, v, m, acc,
                                  seg, params[q, 0], params[q, 1], params[q, 2], params[q, 3],
                                  params[q, 4], params[q, 5] > 0.5, dt,
                                  out_idx, out_f, out_dfdx,
                                  out_dfdv, out_vref, wrench)
            for r in range(6):
                impulses[q, r] += wrench[r] * dt
            fmag = np.sqrt(wrench[0] ** 2 + wrench[1] ** 2 + wrench[2] ** 2)
            if fmag > impulses[q, 6]:
                impulses[q, 6] = fmag
            for e in range(cnt):
                p = out_idx[e]
                for a in range(3):
                    if not implicit:
                        f[p, a] += out_f[e, a]
                        continue
                    fe[p, a] += out_f[e, a]
                    s_ = 0.0
                    for b in range(3):
                        ke[p, a, b] += out_dfdx[e, a, b]
                        de[p, a, b] += out_dfdv[e, a, b]
                        s_ += out_dfdx[e, a, b] * out_vref[e, b]
                    kv[p, a] += s_
        if implicit:
            implicit_step(x, v, m, fixed, si, sj, l0, k, kd, tension_only, a_idx, a_pos, a_k,
                          a_c, alpha, gravity, fe, ke, de, kv, f, dt, theta, bdf2,
                          has_prev or step > 0, xp, vp, tol, max_iter)
        else:
            # symplectic Euler on the forces already evaluated (internal, held, contacts)
            symplectic_update(x, v, m, fixed, f, dt)
