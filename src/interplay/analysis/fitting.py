"""Fit a hybrid stand-in to a two-way run (``interplay fit-standin SCENE``).

The stand-in is a damping field: it can slow the primary and its spin, not turn them. So the
linear coefficient is chosen (by Brent's method) so that the primary, simulated alone with the
stand-in (the hybrid primary pass), has the two-way primary's *speed* at the spec's fit_time;
the angular coefficient likewise matches the spin rate when the primary enters spinning (a
damping field cannot create spin, so otherwise it is left as given). The report gives the
remaining difference in direction, which only the full interaction reproduces.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.optimize import brentq

from ..kernels.rigid import quat_mul


def _velocities(result, system: str, t: float):
    x, xdot = result.state_at(system, t)
    q = x[3:7] / np.linalg.norm(x[3:7])
    w = 2.0 * quat_mul(np.asarray(xdot[3:7], dtype=float), q * np.array([1.0, -1.0, -1.0, -1.0]))
    return np.array(xdot[:3]), w[1:]


def _match(fn, target, hi=1.0, grow=4.0, tries=12):
    """Smallest c >= 0 with fn(c) = target, for fn decreasing in c; bracket by growing hi."""
    if fn(0.0) <= target:
        return 0.0
    for _ in range(tries):
        if fn(hi) < target:
            return brentq(lambda c: fn(c) - target, 0.0, hi, xtol=1e-6, rtol=1e-6)
        hi *= grow
    return hi


def fit_standin(spec, params=None, reference=None, **build_kw) -> dict:
    """Fit the stand-in coefficients of a scene (its SceneSpec: ``standin``, ``fit_time``);
    returns the fit and its report.

    reference: a two-way Result to fit to (run here if None).
    """
    spec.check_fit()
    params = params if params is not None else spec.params()
    fit_time = spec.fit_time
    if reference is None:
        reference = spec.build("two-way", params=params, **build_kw).simulate()
    name = reference.primary
    v_ref, w_ref = _velocities(reference, name, fit_time)
    field = getattr(params, spec.standin)
    runs = []

    def hybrid(linear, angular):
        p = dataclasses.replace(params, **{spec.standin: dataclasses.replace(
            field, linear=float(linear), angular=float(angular), enabled=True)})
        r = spec.build("hybrid", params=p, **build_kw).simulate(primary_only=True)
        runs.append(r.primary_cycle_s)
        return _velocities(r, name, fit_time)

    linear = _match(lambda c: np.linalg.norm(hybrid(c, field.angular)[0]),
                    float(np.linalg.norm(v_ref)))
    _, w0 = _velocities(reference, name, 0.0)
    if np.linalg.norm(w0) > 1e-9:
        angular = _match(lambda c: np.linalg.norm(hybrid(linear, c)[1]),
                         float(np.linalg.norm(w_ref)), hi=0.01)
        spin_note = "angular coefficient matched to the two-way spin rate"
    else:
        angular = field.angular
        spin_note = ("the ball enters without spin and a damping field cannot create it: the "
                     "angular coefficient is left as given")
    v_fit, w_fit = hybrid(linear, angular)
    cos = float(v_fit @ v_ref / (np.linalg.norm(v_fit) * np.linalg.norm(v_ref)))
    return {"linear": float(linear), "angular": float(angular), "fit_time_s": fit_time,
            "two_way_velocity": v_ref.tolist(), "hybrid_velocity": v_fit.tolist(),
            "two_way_spin": w_ref.tolist(), "hybrid_spin": w_fit.tolist(),
            "speed_error_rel": float(abs(np.linalg.norm(v_fit) - np.linalg.norm(v_ref))
                                     / np.linalg.norm(v_ref)),
            "velocity_error_rel": float(np.linalg.norm(v_fit - v_ref) / np.linalg.norm(v_ref)),
            "direction_error_deg": float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))),
            "spin": spin_note, "evaluations": len(runs), "two_way_s": reference.total_s,
            "hybrid_primary_pass_s": float(np.median(runs))}
