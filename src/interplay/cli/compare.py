"""`interplay compare`: the coupling modes a scene supports, side by side (the paper's Figure 2)."""
from __future__ import annotations

import json
from pathlib import Path

from ..io.atomic import atomic_path
from ..outputs.report import figure_text
from .text import mode_row


def compare_modes(spec, kw, out: Path, quiet: bool, console, options=None) -> dict:
    """Run every coupling the scene's spec supports, save each under out/MODE, print one
    table, write out/compare.json.

    options: an outputs.OutputOptions to also write each mode's USD, OBJ, video and report,
    and the side-by-side video and compare report in out (None: summary and tracks only)."""
    from .command import run_scene, scene_summary
    if options is not None:
        from ..outputs.writer import preflight
        preflight(out, options)
    results = {}
    for mode in spec.couplings:
        if not quiet:
            console.print(f"[bold]{mode}[/bold] ...")
        results[mode] = run_scene(spec, mode, kw, quiet)
    reference = results.get("two-way")
    one_way_stable = (not any(results["one-way"].warnings)) if "one-way" in results else None
    two_way_cost = reference.work if reference is not None else None
    wall = reference.total_s - reference.compile_s if reference is not None else None
    debug = None
    if spec.debug_ratio is not None and wall is not None and "hybrid" in results:
        # a primary tuned by hand: the advisor weighs the measured debug cycles
        debug = {"two_way_s": wall, "primary_s": results["hybrid"].primary_cycle_s,
                 "ratio": spec.debug_ratio}
    rows, paths = {}, []
    for mode, r in results.items():
        summary = scene_summary(spec, r, one_way_stable=one_way_stable,
                                two_way_work=two_way_cost, two_way_wall_s=wall,
                                debug_cycle=debug)
        if options is None:
            paths += r.save(out / mode, summary)
        else:
            from ..outputs.writer import write_outputs
            paths += write_outputs(r, out / mode, options, summary)
        rows[mode] = mode_row(r, summary.get("figures", {}))
    first = reference or next(iter(results.values()))
    advice = first.advice(one_way_stable=one_way_stable, two_way_work=two_way_cost,
                          two_way_wall_s=wall, debug_cycle=debug)
    report = {"scene": spec.name, "modes": rows, "advice": advice}
    if spec.contrast is not None:
        report["contrast"] = spec.contrast(results)
        for label, value in report["contrast"].items():
            console.print(f"{label}: {figure_text(value)}", markup=False)
    path = out / "compare.json"
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(report, indent=2))
    paths.append(path)
    if options is not None:
        from ..outputs.writer import write_compare_outputs
        paths += write_compare_outputs(results, out, rows, advice, options)
    _print_table(console, rows, advice)
    for p in paths:
        console.print(f"wrote {p}", markup=False, soft_wrap=True)
    return report


def _print_table(console, rows, advice):
    from rich.table import Table
    table = Table(title="coupling modes side by side")
    for col in ("", *rows):
        table.add_column(col, justify="right")

    def line(label, fn):
        table.add_row(label, *(fn(r) for r in rows.values()))

    labels = list(dict.fromkeys(k for r in rows.values() for k in r["figures"]))
    for label in labels:
        line(label, lambda r, k=label: figure_text(r["figures"][k]) if k in r["figures"] else "-")
    line("max secondary strain", lambda r: f"{100 * r['max_strain']:.1f}%"
         if r["max_strain"] is not None else "-")
    line("force min/max/mean (N)", lambda r: "{min:.1f}/{max:.1f}/{mean:.1f}".format(**r["force_N"]))
    line("accel. min/max/mean (m/s^2)",
         lambda r: "{min:.2f}/{max:.2f}/{mean:.2f}".format(**r["acceleration_m_s2"]))
    line("primary debug cycle (s)", lambda r: f"{r['primary_cycle_s']:.3f}")
    line("total wall time (s)", lambda r: f"{r['total_s']:.3f}")
    line("warnings", lambda r: str(len(r["warnings"])))
    console.print(table)
    console.print(f"advice: [bold]{advice['mode']}[/bold] - " + "; ".join(advice["reasons"]))
    for mode, r in rows.items():
        for w in r["warnings"]:
            console.print(f"[yellow]{mode}:[/yellow] {w}")
