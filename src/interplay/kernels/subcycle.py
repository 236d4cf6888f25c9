"""Sub-cycling a stiff interaction inside a spring-mass network's substeps, in one kernel call.

In a coupling step of length h the network takes n substeps of h/n. The interaction hands the
network a batch of ``Colliders`` (rigid spheres and their predicted paths c0 + v t + a t^2/2:
their own forces change their velocities by far less than the network's do over h), which the
network collides with its elements (cords as segments, or its points) at every substep through
the one contact law, accumulating the impulse each collider received. The interaction then
applies impulse / h to its rigid side, so the exchange is equal and opposite over the step and
momentum is conserved exactly, while the light, stiff network is integrated at its own small
step without a Python call per substep. The network knows nothing of what the colliders are.

An implicit network solves its free colliders (finite mass) with its points instead
(kernels.springs.implicit_step_with_bodies): their velocities are unknowns of the substep's
solve, they move by the solve (with the points' scheme), not along the predicted path, and each
receives the contact forces linearised at the substep's end, the forces its points
integrated with; so the contact is implicit on both sides and converges with the substep
(the basketball's implicit net at 1 ms, docs/coupling.md).
"""
import numpy as np
from numba import njit

from .contact import Sphere, sphere_elements, THICKNESS
from .part_contact import Touches, capacity, find_touches, touch_forces
from .springs import (Bodies, Load, PointForces, copy_load, copy_rows, implicit_step,
                      implicit_step_with_bodies, network_forces, symplectic_update)


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
def _settle_links(links, src, flin, count, x0, at, dt, impulses):
    """Correct each collider's impulse and angular impulse (accumulated with the contact
    forces at the substep's start) to the forces linearised at its end, flin, which its
    points integrated with: the exchange stays equal and opposite. The correction's lever is
    the point's start position from the collider's centre, which stands in for the contact
    point's (a cord's end is within the cord's length of it) in the correction only: the
    start forces' torque is exact."""
    for e in range(count):
        q = src[e]
        i = links.idx[e]
        d0 = links.f[e, 0] - flin[e, 0]  # the collider's share: minus the point's force
        d1 = links.f[e, 1] - flin[e, 1]
        d2 = links.f[e, 2] - flin[e, 2]
        r0, r1, r2 = x0[i, 0] - at[q, 0], x0[i, 1] - at[q, 1], x0[i, 2] - at[q, 2]
        impulses[q, 0] += d0 * dt
        impulses[q, 1] += d1 * dt
        impulses[q, 2] += d2 * dt
        impulses[q, 3] += (r1 * d2 - r2 * d1) * dt
        impulses[q, 4] += (r2 * d0 - r0 * d2) * dt
        impulses[q, 5] += (r0 * d1 - r1 * d0) * dt


def advance_with_colliders(net, load, f, h, nsub, scheme, has_prev, cols, elems):
    """Advance the Network by h in nsub substeps, the Colliders ``cols`` against its elements
    ``elems`` (segments (s,2), or points as (p, p) pairs) re-evaluated every substep.

    load: the other external forces (a Load, held constant); scheme: explicit or implicit (a
    Scheme; the contacts then add their Jacobians to the load of each substep, and free
    colliders are solved with the points: the module docstring); has_prev: whether BDF2 has a
    previous state. cols.impulses receives the impulse (0:3, N s), angular impulse (3:6,
    N m s) and the peak force (6, N) of each collider over the step.

    Two kernels, so that an explicit network never compiles the implicit solve (a first run
    of the explicit basketball: docs/first-run.md)."""
    if scheme.implicit:
        _colliders_implicit(net, load, f, h, nsub, scheme, has_prev, cols, elems)
    else:
        _colliders_explicit(net, load, f, h, nsub, cols, elems)


# The kernels' shared pieces are inlined: a kernel called from another is compiled on its
# own and then again inside its caller (Numba links the callee's code into the caller's and
# optimises the whole), so a separate layer here doubled its compile (docs/first-run.md).
@njit(cache=True, inline="always")
def _collider_work(net, load, elems, cols, implicit):
    """The buffers of ``advance_with_colliders``: the contacts' entries (out), a collider's
    wrench, the substep's load, the free accelerations, and for the implicit solve its links
    (each collider's entries one after the other, src[e] the collider of entry e: the solve
    couples those of finite mass), their linearised forces, the solved colliders' centres,
    velocities and velocity changes through the substeps and each collider's centre at the
    substep's start; three scratch 3-vectors (the network's box, a collider's centre)."""
    x = net.pts.x
    ne = elems.shape[0]
    k_cols = cols.centres.shape[0]
    cap = 2 * ne * k_cols if implicit else 0
    cols.impulses[:, :] = 0.0
    return (PointForces(np.zeros(2 * ne, dtype=np.int64), np.zeros((2 * ne, 3)),
                        np.zeros((2 * ne, 3, 3)), np.zeros((2 * ne, 3, 3)),
                        np.zeros((2 * ne, 3))),
            np.zeros(6),
            Load(np.empty_like(load.f), np.empty_like(load.kext), np.empty_like(load.dext),
                 np.empty_like(load.kvref)),
            np.empty_like(x),
            PointForces(np.zeros(cap, np.int64), np.zeros((cap, 3)), np.zeros((cap, 3, 3)),
                        np.zeros((cap, 3, 3)), np.zeros((cap, 3))),
            np.zeros(cap, np.int64), np.zeros((cap, 3)),
            cols.centres.copy(), cols.velocities.copy(), np.zeros((k_cols, 3)),
            np.empty((k_cols, 3)), np.empty((3, 3)))


@njit(cache=True, inline="always")
def _collide(net, load, f, tau, dt, implicit, cols, elems, out, wrench, sub_load, acc, links,
             src, body_c, body_v, at, scratch):
    """One substep's forces at time tau (s) into the step: the network's own (into f), then
    every collider near its bounding box against the elements, scattered into f (explicit)
    or into sub_load (implicit, which also collects the links); returns the links' count."""
    x = net.pts.x
    m = net.pts.m
    n = x.shape[0]
    network_forces(net, load.f, f)
    lo, hi, c = scratch[0], scratch[1], scratch[2]
    for r in range(3):
        lo[r] = x[0, r]
        hi[r] = x[0, r]
    for i in range(1, n):
        for r in range(3):
            lo[r] = min(lo[r], x[i, r])
            hi[r] = max(hi[r], x[i, r])
    if implicit:
        copy_load(load, sub_load)
    impulses = cols.impulses
    have_acc = False
    count = 0
    for q in range(cols.centres.shape[0]):
        solved = implicit and np.isfinite(cols.masses[q]) and cols.masses[q] > 0.0
        far = False
        for r in range(3):
            if solved:
                c[r] = body_c[q, r]
            else:
                c[r] = (cols.centres[q, r] + cols.velocities[q, r] * tau
                        + 0.5 * cols.accels[q, r] * tau * tau)
            at[q, r] = c[r]
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
        if solved:
            vq = body_v[q].copy()
        else:
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
        for e in range(cnt if implicit else 0):
            links.idx[count] = out.idx[e]
            for a in range(3):
                links.f[count, a] = out.f[e, a]
                links.vref[count, a] = out.vref[e, a]
                for b in range(3):
                    links.dfdx[count, a, b] = out.dfdx[e, a, b]
                    links.dfdv[count, a, b] = out.dfdv[e, a, b]
            src[count] = q
            count += 1
    return count


@njit(cache=True)
def _colliders_explicit(net, load, f, h, nsub, cols, elems):
    """``advance_with_colliders`` for an explicit network: symplectic Euler on the forces
    already evaluated (internal, held, contacts)."""
    dt = h / nsub
    out, wrench, sub_load, acc, links, src, _, body_c, body_v, _, at, scratch = \
        _collider_work(net, load, elems, cols, False)
    for step in range(nsub):
        _collide(net, load, f, step * dt, dt, False, cols, elems, out, wrench, sub_load, acc,
                 links, src, body_c, body_v, at, scratch)
        symplectic_update(net.pts, f, dt)


@njit(cache=True)
def _colliders_implicit(net, load, f, h, nsub, scheme, has_prev, cols, elems):
    """``advance_with_colliders`` for an implicit network: the free colliders solved with the
    points (the module docstring)."""
    dt = h / nsub
    out, wrench, sub_load, acc, links, src, flin, body_c, body_v, body_dv, at, scratch = \
        _collider_work(net, load, elems, cols, True)
    x = net.pts.x
    x0 = np.empty_like(x)
    # the solved colliders move as the points do: x += h (v + theta dv), a coupled BDF2 step
    # being backward Euler
    th = 1.0 if scheme.bdf2 else scheme.theta
    for step in range(nsub):
        count = _collide(net, load, f, step * dt, dt, True, cols, elems, out, wrench, sub_load,
                         acc, links, src, body_c, body_v, at, scratch)
        copy_rows(x, x0)
        implicit_step_with_bodies(net, sub_load, f, dt, scheme, has_prev or step > 0,
                                  Bodies(cols.masses, body_v, cols.accels, src, links,
                                         count, body_dv, flin))
        _settle_links(links, src, flin, count, x0, at, dt, cols.impulses)
        for q in range(body_c.shape[0]):
            for r in range(3):
                body_c[q, r] += dt * (body_v[q, r] + th * body_dv[q, r])
                body_v[q, r] += body_dv[q, r]


def advance_with_parts(net, load, f, h, nsub, scheme, has_prev, parts):
    """Advance the Network by h in nsub substeps with the rigid ``parts`` (a
    kernels.part_contact.Parts, its candidates already found) evaluated against their
    candidate elements at every substep along their predicted paths: as
    ``advance_with_colliders``, for spheres, capsules and boxes (and as there, one kernel for
    an explicit network and one for an implicit). parts.impulses receives each part's
    impulse, angular impulse about its centre of mass and peak force over the step;
    parts.peak the largest total force of any substep."""
    if scheme.implicit:
        _parts_implicit(net, load, f, h, nsub, scheme, has_prev, parts)
    else:
        _parts_explicit(net, load, f, h, nsub, parts)


@njit(cache=True, inline="always")
def _part_work(net, load, parts):
    """The buffers of ``advance_with_parts``: the contacts' entries, the touches, the parts'
    wrenches, the substep's load and the free accelerations."""
    x = net.pts.x
    n = x.shape[0]
    k_parts = parts.impulses.shape[0]
    nc = capacity(parts)  # the step's touches at most: at most 3 point entries each
    parts.impulses[:, :] = 0.0
    parts.peak[0] = 0.0
    parts.received[:] = 0.0
    return (PointForces(np.zeros(3 * nc, dtype=np.int64), np.zeros((3 * nc, 3)),
                        np.zeros((3 * nc, 3, 3)), np.zeros((3 * nc, 3, 3)),
                        np.zeros((3 * nc, 3))),
            Touches(np.zeros(nc, np.int64), np.zeros((nc, 3), np.int64), np.zeros((nc, 3)),
                    np.zeros(nc), np.zeros((nc, 3)), np.zeros((nc, 3)), np.zeros((nc, 3)),
                    np.zeros((k_parts, 3)), np.zeros(n), np.zeros(1)),
            np.zeros((k_parts, 6)),
            Load(np.empty_like(load.f), np.empty_like(load.kext), np.empty_like(load.dext),
                 np.empty_like(load.kvref)),
            np.empty_like(x))


@njit(cache=True, inline="always")
def _touch_parts(net, load, f, tau, dt, implicit, parts, out, tc, wrenches, sub_load, acc):
    """One substep's forces at time tau (s) into the step: the network's own (into f), then
    the parts' touches, scattered into f (explicit) or sub_load (implicit)."""
    x = net.pts.x
    m = net.pts.m
    n = x.shape[0]
    k_parts = parts.impulses.shape[0]
    nc = parts.start[k_parts]
    impulses = parts.impulses
    network_forces(net, load.f, f)
    if implicit:
        copy_load(load, sub_load)
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
            parts.received[a] += out.f[e, a] * dt
    _scatter(out, entries, f, sub_load, implicit)


@njit(cache=True)
def _parts_explicit(net, load, f, h, nsub, parts):
    """``advance_with_parts`` for an explicit network (symplectic Euler)."""
    dt = h / nsub
    out, tc, wrenches, sub_load, acc = _part_work(net, load, parts)
    for step in range(nsub):
        _touch_parts(net, load, f, step * dt, dt, False, parts, out, tc, wrenches, sub_load,
                     acc)
        symplectic_update(net.pts, f, dt)


@njit(cache=True)
def _parts_implicit(net, load, f, h, nsub, scheme, has_prev, parts):
    """``advance_with_parts`` for an implicit network (the scheme's implicit step)."""
    dt = h / nsub
    out, tc, wrenches, sub_load, acc = _part_work(net, load, parts)
    for step in range(nsub):
        _touch_parts(net, load, f, step * dt, dt, True, parts, out, tc, wrenches, sub_load,
                     acc)
        implicit_step(net, sub_load, f, dt, scheme, has_prev or step > 0)
