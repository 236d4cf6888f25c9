"""The HTML run report: one self-contained page (inline CSS; video and plots as files beside
it, linked relatively) an animator opens in a browser.

A run's report.html: the preview video; per interaction a plot of the force on the primary
and its effective acceleration over time (0.5 s windows marked); the Table I statistics beside
the paper's reference row when the scene has one; the advisor's verdict and reasons; timings
(primary debug cycle, total, per pass) and steps; diagnostics, warnings and the output files.
The compare report (``interplay compare``) puts the modes side by side: one video, the
primary's height over time for every mode in one plot, and the measured figures per mode.
"""
from __future__ import annotations

import html
import os
from pathlib import Path

from ..analysis.table import PAPER_TABLE_I
from ..io.atomic import atomic_path

CSS = """
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:0;
 color:#1d2330;background:#f4f5f7}
main{max-width:1100px;margin:0 auto;padding:24px}
h1{font-size:26px;margin:0 0 4px}h2{font-size:19px;margin:28px 0 8px;
 border-bottom:1px solid #d5d9e0;padding-bottom:4px}
.sub{color:#5a6372;margin:0 0 12px}
section{background:#fff;border-radius:8px;padding:4px 18px 14px;margin:14px 0;
 box-shadow:0 1px 2px rgba(0,0,0,.08)}
video,img.plot{max-width:100%;border-radius:6px;background:#000;display:block;margin:8px 0}
img.plot{background:#fff}
table{border-collapse:collapse;margin:8px 0;font-size:13.5px}
th,td{padding:4px 10px;border-bottom:1px solid #e3e6eb;text-align:right}
th:first-child,td:first-child{text-align:left}thead th{background:#eef1f5}
tr.paper td{color:#5a6372;font-style:italic}
.verdict{font-size:20px;font-weight:600}.verdict span{padding:2px 10px;border-radius:6px;
 background:#e3f2e6;color:#1b5e20}
ul{margin:6px 0}.warn{color:#8a4b00}code{background:#eef1f5;padding:1px 4px;border-radius:4px}
"""


def _e(x) -> str:
    return html.escape(str(x))


def _f(x, nd=2) -> str:
    return "-" if x is None else f"{x:.{nd}f}"


def _rel(path, base) -> str:
    return Path(os.path.relpath(path, base)).as_posix()


def _table(head, rows, classes=None) -> str:
    out = ["<table><thead><tr>", *(f"<th>{_e(h)}</th>" for h in head), "</tr></thead><tbody>"]
    for i, r in enumerate(rows):
        cls = f' class="{classes[i]}"' if classes and classes[i] else ""
        out.append(f"<tr{cls}>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def figure_text(value) -> str:
    """A scene's key figure as table text: numbers to 3 places, lists item by item (figures
    may also hold counts, names, verdicts in words, nested lists and None for "not
    measured")."""
    if value is None:
        return "-"
    if isinstance(value, (list, tuple)):
        return ", ".join(f"{v:.2f}" if isinstance(v, float) else figure_text(v) for v in value)
    if isinstance(value, float):
        return f"{value:.3f}"
    return str(value)


def _mmm(d, nd) -> str:
    return " / ".join(_f(d[k], nd) for k in ("min", "max", "mean"))


def _page(title, subtitle, sections) -> str:
    body = "".join(f'<section id="{sid}"><h2>{_e(head)}</h2>{content}</section>'
                   for sid, head, content in sections)
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width,initial-scale=1">'
            f"<title>{_e(title)}</title><style>{CSS}</style></head><body><main>"
            f"<h1>{_e(title)}</h1><p class=\"sub\">{subtitle}</p>{body}</main></body></html>")


def _write(path, text) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def _video(src, base, caption) -> str:
    if src is None:
        return "<p>No video was rendered (<code>--no-video</code>).</p>"
    return (f'<video src="{_e(_rel(src, base))}" controls muted loop playsinline '
            f'preload="auto"></video><p class="sub">{_e(caption)}</p>')


def _caption(info) -> str:
    """Size, rate and the --camera spec that reproduces the view."""
    if not info:
        return ""
    w, h = info["size"]
    return f'{w}x{h} at {info["fps"]:g} frames/s; camera: --camera "{info["camera"]}"'


def _masses(summary) -> dict:
    return {s["name"]: s.get("mass_kg") for s in summary.get("systems", [])}


def table_i_rows(stats_list, masses) -> tuple[list, list]:
    """Rows (and row classes) of Table I: each interaction's statistics over its contact
    period, followed by the paper's row for the same (primary, secondary) if there is one."""
    rows, classes = [], []
    for s in stats_list:
        c = s.get("contact_s")
        rows.append([_e(s["name"]), f"{_e(s['primary'])} {_f(masses.get(s['primary']))}",
                     f"{_e(s['secondary'])} {_f(masses.get(s['secondary']))}",
                     _mmm(s["force_N"], 1), _mmm(s["acceleration_m_s2"], 2),
                     f"{c[0]:.3f}-{c[1]:.3f}" if c else "no contact"])
        classes.append("")
        if "standin" in s:
            st = s["standin"]
            rows.append([f"{_e(s['name'])} stand-in", "", "", _mmm(st["force_N"], 1),
                         _mmm(st["acceleration_m_s2"], 2), "applied in the primary's pass"])
            classes.append("")
        ref = PAPER_TABLE_I.get((s["primary"], s["secondary"]))
        if ref:
            rows.append(["paper, Table I", f"{_e(s['primary'])} {ref['primary_kg']:.2f}",
                         f"{_e(s['secondary'])} {ref['secondary_kg']:.2f}",
                         " / ".join(f"{v:.1f}" for v in ref["force_N"]),
                         " / ".join(f"{v:.2f}" for v in ref["acceleration_m_s2"]), ""])
            classes.append("paper")
    return rows, classes


TABLE_I_HEAD = ["interaction", "primary (kg)", "secondary (kg)", "force min / max / mean (N)",
                "accel. min / max / mean (m/s²)", "contact (s)"]


def _advice(adv) -> str:
    mode = adv.get("mode") or "no verdict"
    reasons = "".join(f"<li>{_e(r)}</li>" for r in adv.get("reasons", []))
    return f'<p class="verdict">Advised coupling: <span>{_e(mode)}</span></p><ul>{reasons}</ul>'


def _timings(t, output_timings) -> str:
    head = ["pass", "live systems", "played back", "steps", "coupling step (s)", "wall (s)"]
    rows = [[str(i + 1), _e(", ".join(p["systems"])), _e(", ".join(p["played"]) or "-"),
             str(p["steps"]), f"{p['coupling_dt_s']:.3g}", _f(p["wall_s"], 3)]
            for i, p in enumerate(t["passes"])]
    out = [f"<p>Primary debug-cycle time <b>{t['primary_pass_s']:.3f} s</b> (wall time until "
           f"the primary's motion is complete); secondary passes "
           f"{t['secondary_pass_s']:.3f} s; total {t['total_s']:.3f} s, of which "
           f"{t['compile_s']:.2f} s compiling or loading Numba kernels (in no pass's wall "
           "time; a first run compiles, later runs load the cache).</p>",
           _table(head, rows)]
    if output_timings:
        out.append(_table(["output", "wall (s)"],
                          [[_e(k), _f(v, 3)] for k, v in output_timings.items()]))
    return "".join(out)


def _windows_table(s) -> str:
    rows = [[f"{w['t'][0]:.2f}-{w['t'][1]:.2f}", _mmm(w["force_N"], 1),
             _mmm(w["acceleration_m_s2"], 2), f"{100 * w['active_fraction']:.0f}%"]
            for w in s.get("windows", [])]
    return _table(["window (s)", "force min / max / mean (N)", "accel. min / max / mean (m/s²)",
                   "in contact"], rows)


def _files(files, base) -> str:
    items = "".join(f'<li><a href="{_e(_rel(p, base))}">{_e(_rel(p, base))}</a> {_e(label)}</li>'
                    for label, p in files.items() if p is not None)
    return f"<ul>{items}</ul>"


def _diagnostics(summary) -> str:
    rows = []
    for name, d in summary.get("diagnostics", {}).items():
        ke = d["kinetic_energy_J"]
        strain = d.get("max_strain")
        rows.append([_e(name), _f(ke["initial"], 3), _f(ke["max"], 3), _f(ke["final"], 3),
                     _f(d.get("lowest_z_m"), 3), "-" if strain is None else f"{100 * strain:.1f}%"])
    out = _table(["system", "KE initial (J)", "KE max (J)", "KE final (J)", "lowest z (m)",
                  "max strain"], rows)
    warns = summary.get("warnings", [])
    out += ("".join(f'<p class="warn">warning: {_e(w)}</p>' for w in warns) if warns
            else "<p>No warnings.</p>")
    return out


def force_plots(result, out_dir, summary: dict) -> tuple[list[Path], list[str]]:
    """The report's force plot of every interaction that touched: (PNG paths, HTML parts).
    Made apart from the page so that they draw while the preview renders."""
    from .render.plots import force_plot
    out = Path(out_dir)
    written, plots = [], []
    stats = {s["name"]: s for s in summary["interactions"]}
    for it in result.interactions:
        name, primary = it["name"], it["primary"]
        log, s = result.logs[name], stats.get(name)
        if s is None or not len(log.t):
            continue
        if not log.active.any() and (log.standin is None or not log.standin.active.any()):
            plots.append(f"<h3>{_e(name)}</h3><p>No contact during the run: no force on "
                         f"{_e(primary)}.</p>")
            continue
        p = force_plot(log, s, out / f"plot_force_{_slug(name)}.png", result.duration)
        written.append(p)
        plots.append(f'<h3>{_e(name)}</h3><img class="plot" src="{_e(_rel(p, out))}" '
                     f'alt="force of {_e(name)} on {_e(primary)} over time">'
                     + _windows_table(s))
    return written, plots


def write_run_report(result, out_dir, summary: dict, files: dict, video=None,
                     output_timings: dict | None = None, video_info: dict | None = None,
                     plots: tuple | None = None) -> list[Path]:
    """Write report.html and its plots into out_dir; return their paths.

    summary: the dict saved as summary.json (its advice may carry a compare's measurements);
    files: {description: path} of the run's other outputs; video: the preview MP4 or None;
    video_info: what render_video returned (size, fps, camera), for the caption; plots: what
    ``force_plots`` returned, if it was called already.
    """
    out = Path(out_dir)
    written, parts = plots if plots is not None else force_plots(result, out, summary)
    written = list(written)
    rows, classes = table_i_rows(summary["interactions"], _masses(summary))
    sections = [
        ("video", "Preview", _video(video, out, _caption(video_info))),
        ("interactions", "Interaction forces on the primary", "".join(parts)
         or "<p>No interactions.</p>"),
        ("table-i", "Table I statistics",
         "<p>Over the first contact period; the paper's reference row in italics.</p>"
         + _table(TABLE_I_HEAD, rows, classes)),
        ("advice", "Coupling advice (the paper's Figure 17)", _advice(summary["advice"])),
        ("timings", "Timings and steps", _timings(summary["timings"], output_timings)),
        ("diagnostics", "Diagnostics", _diagnostics(summary)),
        ("files", "Files", _files(files, out)),
    ]
    sub = (f"coupling <b>{_e(result.coupling)}</b>; {result.duration:g} s simulated at "
           f"{result.fps:g} output frames/s; metres, seconds, +z up")
    written.append(_write(out / "report.html", _page(f"Interplay: {result.scene}", sub,
                                                      sections)))
    return written


def _slug(name) -> str:
    return "".join(c if c.isalnum() else "_" for c in name)


def write_compare_report(runs: dict, out_dir, rows: dict, advice: dict, video=None,
                         mode_reports: dict | None = None, files: dict | None = None,
                         pair: tuple | None = None, video_info: dict | None = None
                         ) -> list[Path]:
    """Write the compare report (report.html) into out_dir: the modes side by side.

    runs: {mode: RunData}; rows: {mode: compare row (cli.text.mode_row)}; advice: the
    advisor's verdict with the measurements of all modes; mode_reports: {mode: report path};
    pair: (primary, secondary) names of the compared interaction, for the paper's Table I row;
    video_info: what render_side_by_side returned, for the caption.
    """
    from .render.plots import height_plot, primary_height
    out = Path(out_dir)
    written = []
    series = {m: h for m, r in runs.items() if (h := primary_height(r)) is not None}
    first = next(iter(runs.values()))
    plot_html = ""
    if series:
        p = height_plot(series, out / "plot_height.png",
                        f"{first.primary} height over time, every coupling mode")
        written.append(p)
        plot_html = (f'<img class="plot" src="{_e(_rel(p, out))}" '
                     f'alt="{_e(first.primary)} height over time">')
    modes = list(rows)
    line = lambda label, fn: [_e(label), *(fn(rows[m]) for m in modes)]  # noqa: E731
    labels = list(dict.fromkeys(k for r in rows.values() for k in r.get("figures", {})))
    table = _table(["", *modes], [
        *(line(label, lambda r, k=label: figure_text(r.get("figures", {}).get(k)))
          for label in labels),
        line("contact (s)", lambda r: "{:.3f}-{:.3f}".format(*r["contact_s"])
             if r.get("contact_s") else "none"),
        line("force min / max / mean (N)", lambda r: _mmm(r["force_N"], 1)),
        line("accel. min / max / mean (m/s²)", lambda r: _mmm(r["acceleration_m_s2"], 2)),
        line("max secondary strain", lambda r: "-" if r.get("max_strain") is None
             else f"{100 * r['max_strain']:.1f}%"),
        line("primary debug cycle (s)", lambda r: _f(r["primary_cycle_s"], 3)),
        line("total wall time (s)", lambda r: _f(r["total_s"], 3)),
        line("warnings", lambda r: str(len(r["warnings"]))),
    ])
    ref_rows = []
    ref = PAPER_TABLE_I.get(tuple(pair)) if pair else None
    if ref:
        ref_rows.append([f"paper: {pair[0]} / {pair[1]}",
                         " / ".join(f"{v:.1f}" for v in ref["force_N"]),
                         " / ".join(f"{v:.2f}" for v in ref["acceleration_m_s2"])])
    ref_html = (_table(["Table I reference", "force min / max / mean (N)",
                        "accel. min / max / mean (m/s²)"], ref_rows, ["paper"] * len(ref_rows))
                if ref_rows else "")
    reports = "".join(f'<li><a href="{_e(_rel(p, out))}">{_e(m)}</a>: its own report '
                      "(force plots, windows, timings, files)</li>"
                      for m, p in (mode_reports or {}).items())
    warns = "".join(f'<p class="warn">{_e(m)}: {_e(w)}</p>' for m in modes
                    for w in rows[m]["warnings"])
    sections = [
        ("video", "The modes side by side",
         _video(video, out, " | ".join(modes) + "; " + _caption(video_info))),
        ("height", "Primary height over time", plot_html or "<p>No primary recorded.</p>"),
        ("modes", "Measured figures per mode", table + ref_html + warns),
        ("advice", "Coupling advice (the paper's Figure 17)", _advice(advice)),
        ("runs", "Per-mode reports", f"<ul>{reports}</ul>"),
        ("files", "Files", _files(files or {}, out)),
    ]
    sub = (f"{first.duration:g} s simulated in each of {', '.join(_e(m) for m in modes)}; "
           "the paper's Figure 2 as a movie")
    written.append(_write(out / "report.html",
                          _page(f"Interplay: {first.scene}, coupling modes compared", sub,
                                sections)))
    return written
