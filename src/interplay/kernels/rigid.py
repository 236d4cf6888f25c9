"""Rigid-body integration kernels (quaternions are (w, x, y, z); angular velocity in world frame)."""
from typing import NamedTuple

import numpy as np
from numba import njit

from .springs import inv3


class Body(NamedTuple):
    """A rigid body's state and constants: position x (3,) m, velocity v (3,) m/s, orientation
    q (4,) w, x, y, z, angular velocity w (3,) rad/s in the world frame, mass (kg), principal
    inertia (3,) kg m^2 in the body frame, gravity (3,) m/s^2."""
    x: np.ndarray
    v: np.ndarray
    q: np.ndarray
    w: np.ndarray
    mass: float
    inertia: np.ndarray
    gravity: np.ndarray


class Wrench(NamedTuple):
    """The force (3,) N and torque about the centre (3,) N m held over a step, the force's
    Jacobians kext = dF/dx (3,3) N/m and dext = dF/dv (3,3) N s/m (zero when it has none), and
    what the body carries over the step: carried (4,) [mass kg, then nothing] and
    carried_inertia (3,3) kg m^2 about its centre, world axes: points of another system tied
    to it that it accelerates with itself (their other forces are in force and torque)."""
    force: np.ndarray
    torque: np.ndarray
    kext: np.ndarray
    dext: np.ndarray
    carried: np.ndarray
    carried_inertia: np.ndarray


@njit(cache=True)
def quat_mul(a, b):
    """Hamilton product a*b."""
    return np.array([
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ])


@njit(cache=True)
def quat_to_matrix(q):
    w, x, y, z = q[0], q[1], q[2], q[3]
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


@njit(cache=True)
def rigid_step(body, wrench, h):
    """Advance one rigid Body by h under a Wrench held constant over the step.

    Translation uses x += h v + h^2 a / 2, v += h a: exact for constant acceleration (ballistic
    flight is reproduced to round-off) and second order otherwise. When the force comes with
    its Jacobians kext = dF/dx and dext = dF/dv (3x3, e.g. a stiff floor contact), the step is
    the implicit trapezoidal rule instead, (m - h D/2 - h^2 K/4) dv = h (F + m g + h K v / 2),
    x += h (v + dv/2): unconditionally stable and free of numerical damping, so a bounce keeps
    the restitution its damping gives (held explicitly, a 1e5 N/m floor at 1e-3 s would add
    energy at every bounce). With zero Jacobians it is the exact update above.
    Rotation integrates Euler's equations explicitly in the world frame and applies the exact
    rotation exp(h w) to q. Carried mass and inertia (points riding on the body) add to its
    own in the accelerations (not in its weight: their weight is among the forces). Arrays are
    updated in place.
    """
    x, v, q, w, own_mass, inertia_body, gravity = body
    force, torque, kext, dext, carried, carried_inertia = wrench
    mass = own_mass + carried[0]
    stiff = False
    for i in range(3):
        for j in range(3):
            if kext[i, j] != 0.0 or dext[i, j] != 0.0:
                stiff = True
    if stiff:
        A = np.empty((3, 3))
        b = np.empty(3)
        for i in range(3):
            kv = 0.0
            for j in range(3):
                A[i, j] = -0.5 * h * dext[i, j] - 0.25 * h * h * kext[i, j]
                kv += kext[i, j] * v[j]
            A[i, i] += mass
            b[i] = h * (force[i] + own_mass * gravity[i] + 0.5 * h * kv)
        Ainv = np.empty((3, 3))
        inv3(A, Ainv)
        for i in range(3):
            dv = Ainv[i, 0] * b[0] + Ainv[i, 1] * b[1] + Ainv[i, 2] * b[2]
            x[i] += h * (v[i] + 0.5 * dv)
            v[i] += dv
    else:
        for i in range(3):
            a = (force[i] + own_mass * gravity[i]) / mass
            x[i] += h * v[i] + 0.5 * h * h * a
            v[i] += h * a
    # I_w = R diag(I) R^T + carried, L = I_w w, dw = I_w^-1 (torque - w x L): written out
    # for 3x3 (NumPy's matmul and LAPACK's solve cost Numba seconds to compile, for nothing)
    R = quat_to_matrix(q)
    Iw = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            Iw[i, j] = carried_inertia[i, j]
            for k in range(3):
                Iw[i, j] += R[i, k] * inertia_body[k] * R[j, k]
    L = np.empty(3)
    for i in range(3):
        L[i] = Iw[i, 0] * w[0] + Iw[i, 1] * w[1] + Iw[i, 2] * w[2]
    rhs = np.array([torque[0] - (w[1] * L[2] - w[2] * L[1]),
                    torque[1] - (w[2] * L[0] - w[0] * L[2]),
                    torque[2] - (w[0] * L[1] - w[1] * L[0])])
    Iinv = np.empty((3, 3))
    inv3(Iw, Iinv)
    for i in range(3):
        w[i] += h * (Iinv[i, 0] * rhs[0] + Iinv[i, 1] * rhs[1] + Iinv[i, 2] * rhs[2])
    ang = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * h
    if ang > 0.0:
        s = np.sin(0.5 * ang) / (ang / h)
        dq = np.array([np.cos(0.5 * ang), w[0] * s, w[1] * s, w[2] * s])
        qn = quat_mul(dq, q)
        n = np.sqrt(np.sum(qn * qn))
        for i in range(4):
            q[i] = qn[i] / n


@njit(cache=True)
def generalized(x, v, q, w, gx, gv):
    """Fill gx = (x, q) and gv = (v, qdot) with qdot = (0, w) * q / 2."""
    for i in range(3):
        gx[i] = x[i]
        gv[i] = v[i]
    for i in range(4):
        gx[3 + i] = q[i]
    gv[3] = 0.5 * (-w[0] * q[1] - w[1] * q[2] - w[2] * q[3])
    gv[4] = 0.5 * (w[0] * q[0] + w[1] * q[3] - w[2] * q[2])
    gv[5] = 0.5 * (-w[0] * q[3] + w[1] * q[0] + w[2] * q[1])
    gv[6] = 0.5 * (w[0] * q[2] - w[1] * q[1] + w[2] * q[0])
