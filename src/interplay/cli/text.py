"""Console summaries of runs (rich tables)."""
from __future__ import annotations


def mode_row(result, figures: dict | None = None) -> dict:
    """The figures `compare` puts side by side for one run: its main interaction's Table I
    statistics, the secondary's strain, the timings, and the scene's own figures."""
    it = result.main_interaction
    stats = next(s for s in result.interaction_stats() if s["name"] == it["name"])
    return {"coupling": it["mode"], "force_N": stats["force_N"],
            "acceleration_m_s2": stats["acceleration_m_s2"], "contact_s": stats["contact_s"],
            "primary_cycle_s": result.primary_cycle_s, "total_s": result.total_s,
            "max_strain": result.diagnostics.get(it["secondary"], {}).get("max_strain"),
            "warnings": list(result.warnings), "figures": dict(figures or {})}


def print_run(console, result, figures: dict | None = None):
    """The run in a few lines: timings, Table I per interaction, the advice, the scene's own
    figures (``figures``: label -> value), the warnings."""
    from rich.table import Table
    t = result.timings()
    console.print(f"[bold]{result.scene}[/bold] ({result.coupling}): "
                  f"{result.duration:.2f} s simulated; primary debug cycle "
                  f"{t['primary_pass_s']:.3f} s, total {t['total_s']:.3f} s"
                  + (f" of which {t['compile_s']:.1f} s compiling kernels (first run only)"
                     if t["compile_s"] >= 0.5 else ""))
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
    # the other interactions on a moving primary, each with its own verdict
    for it in result.interactions:
        if it["name"] != result.main and it["primary_role"] == "dynamic":
            other = result.advice_for(it)
            console.print(f"advice for {it['name']}: [bold]{other['mode']}[/bold] - "
                          + "; ".join(other["reasons"]))
    for label, value in (figures or {}).items():
        shown = f"{value:.4g}" if isinstance(value, float) else value
        console.print(f"{label}: {shown}", markup=False, soft_wrap=True)
    for w in result.warnings:
        console.print(f"[yellow]warning:[/yellow] {w}")
