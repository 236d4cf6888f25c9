"""The explicit step's stability for a spring network (SpringNetwork inherits it).

Symplectic Euler on x'' + c x' + w^2 x = 0 is stable for h c < 2 and h^2 w^2 + 2 h c < 4; at a
network's point w^2 and c are read from its springs (sum k / m, sum kd / m + alpha). Three
criteria (``explicit_bounds``): the undamped one of a chain's highest mode, h^2 sum k / m < 2;
with springs' own damping, h c < 2; and, where a scene leaves part of the limit to what acts
on the network (a sub-cycled contact), h^2 w^2 + 2 h c <= ``stability_share``. A refused step
names its criterion and advises the largest step that passes all three.
"""
from __future__ import annotations

import numpy as np

from ..errors import StabilityError, usable_below

FREE_SHARE = 1.5  # of the worst case's 2 (free_step)


class ExplicitStability:
    """Mixin over a network's arrays: x, m, fixed, si, sj, k, kd, beta, alpha, a_idx, a_k,
    integrator, name; stability_share (None or the share of 4), dt_key and step_cure (the
    refusal's wording)."""

    def _per_point(self, values) -> np.ndarray:
        """(n,) each point's sum of ``values`` over the springs it ends."""
        out = np.zeros(len(self.x))
        np.add.at(out, self.si, values)
        np.add.at(out, self.sj, values)
        return out

    def damping_rates(self) -> np.ndarray:
        """(n,) 1/s: each point's damping rate, sum of its springs' kd over its mass plus
        alpha: an explicit step h must keep h times it under 2 (a step that takes away more
        than twice a point's velocity relative to its neighbours reverses and grows it)."""
        return self._per_point(self.kd) / self.m + self.alpha

    def stable_step(self) -> float:
        """Explicit (symplectic Euler) bound, dt < min_i sqrt(2 m_i / sum_j k_ij)  (s)."""
        ksum = self._per_point(self.k)
        np.add.at(ksum, self.a_idx, self.a_k)
        free = (ksum > 0) & ~self.fixed
        if not np.any(free):
            return np.inf
        return float(np.min(np.sqrt(2.0 * self.m[free] / ksum[free])))

    def explicit_bounds(self) -> dict:
        """The largest explicit step (s) each criterion allows, at the stiffest free point:
        "stiffness", h^2 sum k / m < 2 (``stable_step``: a chain's highest mode); with the
        springs' own damping, "damping", h c < 2 (c = ``damping_rates``: a step taking more
        than twice a point's velocity relative to its neighbours reverses and grows it); with
        ``stability_share``, "share", h^2 w^2 + 2 h c <= stability_share (w^2 = sum k / m),
        damped symplectic Euler's h^2 w^2 + 2 h c < 4 less what is left to others."""
        out = {"stiffness": self.stable_step()}
        c = self.damping_rates()[~self.fixed]
        if np.any(self.kd > self.beta * self.k) and len(c) and c.max() > 0:
            out["damping"] = 2.0 / float(c.max())
        if self.stability_share is not None:
            w2, c = self._share_rates()
            if len(w2):
                out["share"] = _largest_step(self.stability_share, w2, c)
        return out

    def free_step(self) -> float:
        """(s) The explicit step when nothing sub-cycled can touch the network: the largest h
        with h^2 w^2 + 2 h c <= FREE_SHARE at every free point (w^2 = its springs' and
        anchors' sum k / m, c = ``damping_rates``). The network's stiffness and damping
        matrices have eigenvalues up to twice those sums (Gershgorin: the checkerboard mode of
        a net), so symplectic Euler's h^2 lambda + 2 h gamma < 4 is h^2 w^2 + 2 h c < 2 at
        worst; FREE_SHARE keeps a quarter of that back (the basketball net at rest: stable to
        3.49e-5 s, its linearised step's spectral radius, against 2.3e-5 s)."""
        w2 = self._per_point(self.k)
        np.add.at(w2, self.a_idx, self.a_k)
        on = ~self.fixed & (w2 > 0)
        if not np.any(on):
            return np.inf
        return _largest_step(FREE_SHARE, w2[on] / self.m[on], self.damping_rates()[on])

    def _share_rates(self):
        """(w^2 = sum k / m (1/s^2), c (1/s)) at the free points with springs."""
        w2 = self._per_point(self.k)
        on = ~self.fixed & (w2 > 0)
        return w2[on] / self.m[on], self.damping_rates()[on]

    def check_step(self, dt: float):
        """Refuse an explicit step past any of ``explicit_bounds``, naming the criterion and
        advising the largest step that passes them all (so following the advice is not
        refused by the next criterion)."""
        if self.integrator != "explicit":
            return
        b = self.explicit_bounds()
        if dt < min(b.values()):
            return
        cure = (f"use {self.dt_key} < {usable_below(min(b.values()))} s, or "
                f"{self.step_cure}, or --integrator implicit")
        if dt >= b["stiffness"]:
            raise StabilityError(f"{self.name}: dt={dt:.3g} s is above the explicit stability "
                                 f"bound {b['stiffness']:.4g} s; {cure}")
        if dt >= b.get("damping", np.inf):
            c = 2.0 / b["damping"]
            raise StabilityError(
                f"{self.name}: dt={dt:.3g} s times the largest damping rate {c:.3g} 1/s "
                f"(sum of kd / m + alpha) is {dt * c:.2f}, at least 2: unstable; {cure}")
        if dt > b.get("share", np.inf):
            w2, c = self._share_rates()
            worst = float(np.max(dt * dt * w2 + 2.0 * dt * c))
            raise StabilityError(
                f"{self.name}: dt={dt:.3g} s is too large for its stiffness and damping "
                f"(explicit stability number {worst:.2f}, at most {self.stability_share}); "
                f"{cure}")


def _largest_step(share, w2, c) -> float:
    """(s) The largest h with h^2 w^2 + 2 h c <= share at every point (w2 1/s^2, c 1/s)."""
    return float(np.min((np.sqrt(c ** 2 + share * w2) - c) / w2))
