"""Report plots (matplotlib, Agg canvas: no pyplot global state, no display needed)."""
from __future__ import annotations

import numpy as np

from ...errors import InterplayError
from ...io.atomic import atomic_path

G = 9.81  # m/s^2
MODE_COLORS = {"two-way": "#1f77b4", "one-way": "#d62728", "hybrid": "#2ca02c"}


def _figure(w_in, h_in, rows=1):
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise InterplayError("the run report's plots need matplotlib: pip install "
                             "'matplotlib>=3.8', or skip the report with --no-report") from None
    fig = Figure(figsize=(w_in, h_in), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    return fig, axes


def _save(fig, path):
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100)
    return path


def _windows(ax, stats, key, scale=1.0):
    """Mark the 0.5 s windows (dotted bounds) and each window's mean (a short bar)."""
    for i, w in enumerate(stats.get("windows", [])):
        t0, t1 = w["t"]
        ax.axvline(t0, color="0.6", lw=0.8, ls=":")
        ax.hlines(w[key]["mean"] * scale, t0, t1, color="#ff7f0e", lw=2,
                  label="0.5 s window mean" if i == 0 else None)
    c = stats.get("contact_s")
    if c:
        ax.axvspan(c[0], c[1], color="#ffd54f", alpha=0.25, lw=0, label="contact period")


def force_plot(log, stats: dict, path, duration: float | None = None):
    """Force of one interaction on its primary (N) and its effective acceleration (m/s^2)
    over time, with the 0.5 s windows and the contact period marked. Returns path."""
    fig, (ax_f, ax_a) = _figure(8.0, 4.6, rows=2)
    t, mag, peak = log.t, log.magnitude, log.peak
    m = log.primary_mass
    ax_f.plot(t, peak, color="#9ecae1", lw=0.8, label="peak within step")
    ax_f.plot(t, mag, color="#1f77b4", lw=1.2, label="|F| (step mean)")
    if log.standin is not None and len(log.standin.t):
        ax_f.plot(log.standin.t, log.standin.magnitude, color="#2ca02c", lw=1.0, ls="--",
                  label="stand-in (applied in the primary's pass)")
    _windows(ax_f, stats, "force_N")
    ax_f.set_ylabel("force on primary (N)")
    ax_f.set_title(f"{log.name}: {log.secondary} on {log.primary} ({log.mode}), "
                   f"primary {m:g} kg", fontsize=10)
    ax_f.legend(fontsize=7, loc="upper right")
    ax_a.plot(t, peak / m, color="#9ecae1", lw=0.8, label="peak / m")
    ax_a.plot(t, mag / m, color="#1f77b4", lw=1.2, label="|F| / m")
    ax_a.axhline(G, color="0.3", lw=0.8, ls="--", label="g")
    _windows(ax_a, stats, "acceleration_m_s2")
    ax_a.set_ylabel("effective accel. (m/s$^2$)")
    ax_a.set_xlabel("time (s)")
    ax_a.legend(fontsize=7, loc="upper right")
    if duration:
        ax_a.set_xlim(0, duration)
    for ax in (ax_f, ax_a):
        ax.grid(alpha=0.3)
    return _save(fig, path)


def height_plot(series: dict, path, title: str, ylabel: str = "height (m)"):
    """Lines z(t) for several runs on one axis: series = {label: (t (s), z (m))}."""
    fig, (ax,) = _figure(8.0, 3.6)
    for label, (t, z) in series.items():
        ax.plot(t, z, lw=1.6, label=label, color=MODE_COLORS.get(label))
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, path)


def primary_height(run) -> tuple[np.ndarray, np.ndarray] | None:
    """(t, z) of the run's primary: a body's centre or the mean of a network's points."""
    name = run.primary
    fr = run.frames.get(name) if name else None
    if not fr:
        return None
    if "position" in fr:
        return np.asarray(fr["t"]), np.asarray(fr["position"])[:, 2]
    if "points" in fr:
        return np.asarray(fr["t"]), np.asarray(fr["points"])[:, :, 2].mean(axis=1)
    return None
