"""Sub-cycling a stiff interaction inside a spring-mass network's substeps, in one kernel call.

In a coupling step of length h the network takes n substeps of h/n. The interaction hands the
network a batch of ``Colliders`` (rigid spheres and their predicted paths c0 + v t + a t^2/2:
their own forces change their velocities by far less than the network's do over h), which the
network collides with its elements (cords as segments, or its points) at every substep through
the one contact law, accumulating the impulse each collider received. The interaction then
applies impulse / h to its rigid side, so the exchange is equal and opposite over the step and
momentum is conserved exactly, while the light, stiff network is integrated at its own small
step without a Python call per substep. The network knows nothing of what the colliders are.
"""
import numpy as np
from numba import njit

from .contact import Sphere, sphere_elements, THICKNESS
from .part_contact import Touches, find_touches, touch_forces
from .springs import Load, PointForces, implicit_step, network_forces, symplectic_update


@njit(cache=True)
def _scatter(out, count, f, load, implicit):
    """Add the first ``count`` entries of the PointForces ``out`` to the points: to the
    forces f (N) of an explicit substep, or to an implicit substep's held Load (forces, their
    Jacobians, and dfdx . vref)."""
    for e in range(count):
        p = out.idx[e]
        for a in range(3):
            if not implicit:
                f[p, a] += out.f[e, a]
                continue
            load.f[p, a] += out.f[e, a]
            s_ = 0.0
            for b in range(3):
                load.kext[p, a, b] += out.dfdx[e, a, b]
                load.dext[p, a, b] += out.dfdv[e, a, b]
                s_ += out.dfdx[e, a, b] * out.vref[e, b]
            load.kvref[p, a] += s_


@njit(cache=True)
def advance_with_colliders(net, load, f, h, nsub, scheme, has_prev, cols, elems):
    """Advance the Network by h in nsub substeps, the Colliders ``cols`` against its elements
    ``elems`` (segments (s,2), or points as (p, p) pairs) re-evaluated every substep.

    load: the other external forces (a Load, held constant); scheme: explicit or implicit (a
    Scheme; the contacts then add their Jacobians to the load of each substep); has_prev:
    whether BDF2 has a previous state. cols.impulses receives the impulse (0:3, N s), angular
    impulse (3:6, N m s) and the peak force (6, N) of each collider over the step.
    """
    x = net.pts.x
    m = net.pts.m
    n = x.shape[0]
    dt = h / nsub
    ne = elems.shape[0]
    out = PointForces(np.zeros(2 * ne, dtype=np.int64), np.zeros((2 * ne, 3)),
                      np.zeros((2 * ne, 3, 3)), np.zeros((2 * ne, 3, 3)), np.zeros((2 * ne, 3)))
    wrench = np.zeros(6)
    fe = np.empty_like(load.f)
    ke = np.empty_like(load.kext)
    de = np.empty_like(load.dext)
    kv = np.empty_like(load.kvref)
    sub_load = Load(fe, ke, de, kv)
    acc = np.empty_like(x)
    c = np.empty(3)
    lo = np.empty(3)
    hi = np.empty(3)
    implicit = scheme.implicit
    impulses = cols.impulses
    for q in range(impulses.shape[0]):
        for r in range(7):
            impulses[q, r] = 0.0
    for step in range(nsub):
        tau = step * dt
        network_forces(net, load.f, f)
        for r in range(3):
            lo[r] = x[0, r]
            hi[r] = x[0, r]
        for i in range(1, n):
            for r in range(3):
                lo[r] = min(lo[r], x[i, r])
                hi[r] = max(hi[r], x[i, r])
        if implicit:
            fe[:] = load.f
            ke[:] = load.kext
            de[:] = load.dext
            kv[:] = load.kvref
        have_acc = False
        for q in range(cols.centres.shape[0]):
            far = False
            for r in range(3):
                c[r] = (cols.centres[q, r] + cols.velocities[q, r] * tau
                        + 0.5 * cols.accels[q, r] * tau * tau)
                reach = cols.radii[q] + cols.law[q, THICKNESS]
                if c[r] + reach < lo[r] or c[r] - reach > hi[r]:
                    far = True
            if far:  # the collider misses the network's bounding box
                continue
            if not have_acc:  # free accelerations, for the contacts' constraint term
                for i in range(n):
                    for r in range(3):
                        acc[i, r] = f[i, r] / m[i]
                have_acc = True
            vq = cols.velocities[q] + cols.accels[q] * tau
            ball = Sphere(c, vq, cols.spins[q], cols.radii[q], cols.masses[q], cols.accels[q])
            cnt = sphere_elements(ball, net.pts, acc, elems, cols.law[q], dt, out, implicit,
                                  wrench)
            for r in range(6):
                impulses[q, r] += wrench[r] * dt
            fmag = np.sqrt(wrench[0] ** 2 + wrench[1] ** 2 + wrench[2] ** 2)
            if fmag > impulses[q, 6]:
                impulses[q, 6] = fmag
            _scatter(out, cnt, f, sub_load, implicit)
        if implicit:
            implicit_step(net, sub_load, f, dt, scheme, has_prev or step > 0)
        else:
            # symplectic Euler on the forces already evaluated (internal, held, contacts)
            symplectic_update(net.pts, f, dt)


@njit(cache=True)
def advance_with_parts(net, load, f, h, nsub, scheme, has_prev, parts):
    """Advance the Network by h in nsub substeps with the rigid ``parts`` (a
    kernels.part_contact.Parts, its candidates already found) evaluated against their
    candidate elements at every substep along their predicted paths: as
    ``advance_with_colliders``, for spheres, capsules and boxes. parts.impulses receives each
    part's impulse, angular impulse about its centre of mass and peak force over the step;
    parts.peak the largest total force of any substep."""
    x = net.pts.x
    m = net.pts.m
    n = x.shape[0]
    dt = h / nsub
    k_parts = parts.impulses.shape[0]
    nc = parts.start[k_parts]  # the step's candidates: at most 2 point entries each
    out = PointForces(np.zeros(2 * nc, dtype=np.int64), np.zeros((2 * nc, 3)),
                      np.zeros((2 * nc, 3, 3)), np.zeros((2 * nc, 3, 3)), np.zeros((2 * nc, 3)))
    tc = Touches(np.zeros(nc, np.int64), np.zeros(nc, np.int64), np.zeros(nc, np.int64),
                 np.zeros(nc), np.zeros(nc), np.zeros((nc, 3)), np.zeros((nc, 3)),
                 np.zeros((nc, 3)), np.zeros((k_parts, 3)), np.zeros(n))
    wrenches = np.zeros((k_parts, 6))
    fe = np.empty_like(load.f)
    ke = np.empty_like(load.kext)
    de = np.empty_like(load.dext)
    kv = np.empty_like(load.kvref)
    sub_load = Load(fe, ke, de, kv)
    acc = np.empty_like(x)
    implicit = scheme.implicit
    impulses = parts.impulses
    impulses[:, :] = 0.0
    parts.peak[0] = 0.0
    received = parts.received
    received[:] = 0.0
    for step in range(nsub):
        tau = step * dt
        network_forces(net, load.f, f)
        if implicit:
            fe[:] = load.f
            ke[:] = load.kext
            de[:] = load.dext
            kv[:] = load.kvref
        cnt = find_touches(parts, tau, x, tc) if nc > 0 else 0
        entries = 0
        if cnt > 0:
            for i in range(n):  # free accelerations, for the contacts' constraint term
                for r in range(3):
                    acc[i, r] = f[i, r] / m[i]
            entries = touch_forces(parts, tc, cnt, net.pts, acc, dt, out, implicit, wrenches)
            tx, ty, tz = 0.0, 0.0, 0.0
            for j in range(k_parts):
                for r in range(6):
                    impulses[j, r] += wrenches[j, r] * dt
                fmag = np.sqrt(wrenches[j, 0] ** 2 + wrenches[j, 1] ** 2 + wrenches[j, 2] ** 2)
                if fmag > impulses[j, 6]:
                    impulses[j, 6] = fmag
                tx += wrenches[j, 0]
                ty += wrenches[j, 1]
                tz += wrenches[j, 2]
            parts.peak[0] = max(parts.peak[0], np.sqrt(tx * tx + ty * ty + tz * tz))
        for e in range(entries):
            for a in range(3):
                received[a] += out.f[e, a] * dt
        _scatter(out, entries, f, sub_load, implicit)
        if implicit:
            implicit_step(net, sub_load, f, dt, scheme, has_prev or step > 0)
        else:
            symplectic_update(net.pts, f, dt)
