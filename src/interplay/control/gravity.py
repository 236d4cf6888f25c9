"""Gravity compensation: the feed-forward joint torques that hold a pose still against gravity.

The servo torque on every hinge is the PD law of control/pd.py plus this term:

    tau = g_s (theta_d - theta) + g_d (thetadot_d - thetadot) + tau_g(theta_d)

tau_g comes from MuJoCo's recursive Newton-Euler inverse dynamics (``mj_rne`` with zero
velocity and acceleration: the generalized gravity force ``qfrc_bias``) evaluated at the
*desired* pose, less what the ground carries:

    tau_g = qfrc_bias(q_d) - sum_feet J_f(q_d)^T F_f

* a fixed base (the pelvis welded to the world): no ground term; each hinge holds the weight
  of its distal side;
* standing on k feet: each foot pushes up with F_f = m g / k at a point directly under the
  centre of mass (shifted by the foot's own offset from the feet's mean), so the feet carry the
  whole weight with no moment about the centre of mass and the stance legs' hinges hold the
  body above them;
* in flight: zero. A free-falling body needs no internal torque against gravity (every
  segment falls alike), so any compensation would only bend it.

With the weight carried by tau_g the PD gains only have to correct errors: they can be soft
enough that a new target does not drive the servos into their torque limits.
"""
from __future__ import annotations

import numpy as np


class GravityCompensation:
    """Feed-forward torques (N m) for one figure model; keeps its own scratch ``MjData`` so the
    desired pose never disturbs the simulated state.

    model: the compiled figure; qadr, vadr: the hinges' qpos and dof addresses; foot_bodies:
    body ids of the feet that may carry weight; sole_geoms: their geoms (whose centres are the
    feet's positions); free: the root is a free joint."""

    def __init__(self, model, qadr, vadr, foot_bodies, sole_geoms, free: bool):
        import mujoco
        self._mj = mujoco
        self.model = model
        self.data = mujoco.MjData(model)
        self.qadr, self.vadr = qadr, vadr
        self.foot_bodies, self.sole_geoms = foot_bodies, sole_geoms
        self.free = free
        self.weight = -float(model.body_mass.sum()) * float(model.opt.gravity[2])  # N, up
        self._bias = np.zeros(model.nv)
        self._jac = np.zeros((3, model.nv))
        self._point = np.zeros(3)
        self._none = np.zeros(len(qadr))
        self.root_residual = np.zeros(6 if free else 0)  # generalized force left on the root

    def torques(self, qpos, targets, feet) -> np.ndarray:
        """tau_g (N m) per hinge for the desired angles ``targets`` (rad), the root where it is
        in ``qpos``; feet: indices into foot_bodies of the feet on the ground (empty: flight
        for a free figure)."""
        if self.free and len(feet) == 0:
            return self._none.copy()
        m, d, mj = self.model, self.data, self._mj
        d.qpos[:] = qpos
        d.qpos[self.qadr] = targets
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        mj.mj_rne(m, d, 0, self._bias)  # qvel = 0 in this scratch data: gravity only
        tau = self._bias
        if self.free:
            com = d.subtree_com[1]
            pos = d.geom_xpos[self.sole_geoms[feet]]
            shift = com[:2] - pos[:, :2].mean(axis=0)
            share = self.weight / len(feet)
            for f, p in zip(feet, pos):
                self._point[:2] = p[:2] + shift
                self._point[2] = p[2]
                mj.mj_jac(m, d, self._jac, None, self._point, int(self.foot_bodies[f]))
                tau -= share * self._jac[2]  # the upward push's generalized force
            self.root_residual = tau[:6].copy()
        return tau[self.vadr]
