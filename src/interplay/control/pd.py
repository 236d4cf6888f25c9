"""PD servos: the law, the gain rule and the inertia each joint moves.

The law, on every controlled joint axis:

    tau = g_s (theta_d - theta) + g_d (thetadot_d - thetadot),   |tau| <= tau_max

(the figure adds the gravity feed-forward tau_g of control/gravity.py inside the limit)

with gains from the inertia I_eff (kg m^2) the joint moves about its axis, a natural
frequency w (rad/s) and a damping ratio zeta:

    g_s = I_eff w^2        (N m / rad)
    g_d = 2 zeta I_eff w   (N m s / rad)

so a joint whose other side is held still responds to a step in theta_d like a mass-spring-
damper of frequency w and damping ratio zeta, whatever segment it moves. I_eff is the inertia
of the segments on the joint's distal side (its subtree: what the joint swings in the air), or,
when that side is planted on the ground, the inertia of everything on the proximal side (what a
stance leg's joints carry).
"""
from __future__ import annotations

import numpy as np


def pd_gains(inertia, omega, zeta):
    """(g_s N m/rad, g_d N m s/rad) for inertias (kg m^2), frequencies (rad/s), ratios (-)."""
    inertia = np.asarray(inertia, dtype=float)
    omega = np.asarray(omega, dtype=float)
    return inertia * omega * omega, 2.0 * np.asarray(zeta, dtype=float) * inertia * omega


def pd_torque(theta_d, theta, thetadot_d, thetadot, g_s, g_d, tau_max):
    """The servo torque (N m), clamped to +-tau_max: the reference for the actuators."""
    tau = g_s * (theta_d - theta) + g_d * (thetadot_d - thetadot)
    return np.clip(tau, -tau_max, tau_max)


def axis_inertias(model, data, joint_ids, subtree_mask):
    """Inertia (kg m^2) about each hinge's axis through its anchor, of the bodies selected by
    ``subtree_mask[j]`` (a boolean row over bodies for joint j), at the current pose.

    I = sum_b ( a^T R_b I_b R_b^T a + m_b |a x (c_b - p)|^2 ) for unit axis a at point p."""
    out = np.zeros(len(joint_ids))
    mass = model.body_mass
    com = data.xipos
    for k, j in enumerate(joint_ids):
        a = data.xaxis[j]
        p = data.xanchor[j]
        sel = np.flatnonzero(subtree_mask[k])
        r = np.cross(a, com[sel] - p)
        R = data.ximat[sel].reshape(-1, 3, 3)
        local = np.einsum("bji,j->bi", R, a)  # the axis in each body's principal frame
        out[k] = float(np.sum(local * local * model.body_inertia[sel])
                       + np.sum(mass[sel] * np.sum(r * r, axis=1)))
    return out
