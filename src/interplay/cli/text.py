"""Console summaries of runs (rich tables)."""
from __future__ import annotations

import numpy as np


def mode_row(result) -> dict:
    """The figures `compare` puts side by side for one run."""
    it = result.scene.main_interaction
    prim = result.scene.primary.name
    stats = next(s for s in result.interaction_stats() if s["name"] == it.name)
    row = {"coupling": it.mode, "force_N": stats["force_N"],
           "acceleration_m_s2": stats["acceleration_m_s2"], "contact_s": stats["contact_s"],
           "primary_cycle_s": result.primary_cycle_s, "total_s": result.total_s,
           "max_strain": result.diagnostics().get(it.secondary.name, {}).get("max_strain"),
           "warnings": list(result.warnings)}
    if stats["contact_s"] and prim in result.tracks:
        t_exit = stats["contact_s"][1]
        _, v = result.state_at(prim, t_exit)
        row["exit_time_s"] = t_exit
        row["exit_velocity"] = v[:3].tolist()
        row["exit_speed"] = float(np.linalg.norm(v[:3]))
        # free flight of the same primary: v(t) = v(0) + g t
        _, v0 = result.state_at(prim, 0.0)
        vf = v0[:3] + result.scene.primary.gravity * t_exit
        row["free_flight_exit_speed"] = float(np.linalg.norm(vf))
    return row


def print_run(console, result):
    from rich.table import Table
    t = result.timings()
    console.print(f"[bold]{result.scene.name}[/bold] ({result.scene.coupling}): "
                  f"{result.scene.duration:.2f} s simulated; primary debug cycle "
                  f"{t['primary_pass_s']:.3f} s, total {t['total_s']:.3f} s")
    table = Table("interaction", "mode", "contact (s)", "force min/max/mean (N)",
                  "accel. min/max/mean (m/s^2)")
    for s in result.interaction_stats():
        f, a = s["force_N"], s["acceleration_m_s2"]
        c = s["contact_s"]
        table.add_row(s["name"], s["mode"], f"{c[0]:.3f}-{c[1]:.3f}" if c else "none",
                      f"{f['min']:.1f} / {f['max']:.1f} / {f['mean']:.1f}",
                      f"{a['min']:.2f} / {a['max']:.2f} / {a['mean']:.2f}")
    console.print(table)
    adv = result.advice()
    console.print(f"advice: [bold]{adv['mode']}[/bold] - " + "; ".join(adv["reasons"]))
    for w in result.warnings:
        console.print(f"[yellow]warning:[/yellow] {w}")
