"""Interaction analysis (SPEC 3): force statistics, effective acceleration, and the advisor.

The effect of an interaction on its primary is measured as the force it exerts and the
*effective acceleration* |F| / m_primary. Statistics are min / max / mean of |F| over the
first contact period (from its first to its last active step, idle steps shorter than 0.05 s
inside it included, as the paper's Table I; later periods, e.g. the ball bouncing back up
into the net, are listed in ``episodes_s``) and over consecutive 0.5 s windows. The max is the largest instantaneous force (the
peak within each coupling step when the interaction is sub-cycled); min and mean are over the
per-step mean forces, so the mean is exactly the impulse over the period divided by its length.
"""
from __future__ import annotations

import numpy as np

#: Table I of the paper: (primary, secondary) -> force (min, max, mean) N, acceleration m/s^2
PAPER_TABLE_I = {
    ("ball", "net"): {"primary_kg": 0.68, "secondary_kg": 0.03, "force_N": (0.0, 59.9, 15.7),
                      "acceleration_m_s2": (0.00, 88.08, 23.14)},
    ("gymnast", "trampoline"): {"primary_kg": 64.38, "secondary_kg": 20.0,
                                "force_N": (60.4, 5298.8, 2215.2),
                                "acceleration_m_s2": (0.93, 82.30, 34.41)},
    ("alien", "noose"): {"primary_kg": 46.56, "secondary_kg": 3.5,
                         "force_N": (137.9, 4055.3, 575.0),
                         "acceleration_m_s2": (2.96, 87.10, 12.35)},
    ("alien", "vest"): {"primary_kg": 46.56, "secondary_kg": 0.5, "force_N": (2.1, 31.9, 6.9),
                        "acceleration_m_s2": (0.05, 0.69, 0.15)},
}


def _stats(values: np.ndarray, peaks: np.ndarray) -> dict:
    """min and mean of the per-step (mean) force magnitudes, max of the within-step peaks."""
    if len(values) == 0:
        return {"min": 0.0, "max": 0.0, "mean": 0.0}
    return {"min": float(values.min()), "max": float(peaks.max()),
            "mean": float(values.mean())}


def interaction_stats(log, window: float = 0.5) -> dict:
    """Statistics of one ForceLog: over the contact period and over ``window``-second windows."""
    mag = log.magnitude
    period = log.contact_period()
    if period is None:
        sel = np.zeros(len(mag), dtype=bool)
    else:
        sel = (log.t >= period[0]) & (log.t <= period[1])
    force = _stats(mag[sel], log.peak[sel])
    acc = {k: v / log.primary_mass for k, v in force.items()}
    windows = []
    if len(log.t):
        end = log.t[-1]
        t0 = 0.0
        while t0 < end:
            w = (log.t >= t0) & (log.t < t0 + window)
            f = _stats(mag[w], log.peak[w])
            windows.append({"t": [t0, min(t0 + window, float(end))], "force_N": f,
                            "acceleration_m_s2": {k: v / log.primary_mass for k, v in f.items()},
                            "active_fraction": float(log.active[w].mean()) if w.any() else 0.0})
            t0 += window
    out = {"name": log.name, "primary": log.primary, "secondary": log.secondary,
           "mode": log.mode, "force_N": force, "acceleration_m_s2": acc,
           "contact_s": list(period) if period else None,
           "episodes_s": [list(e) for e in log.episodes()], "windows": windows}
    if log.standin is not None:
        s = interaction_stats(log.standin, window)
        out["standin"] = {"force_N": s["force_N"], "acceleration_m_s2": s["acceleration_m_s2"],
                          "contact_s": s["contact_s"]}
    return out
