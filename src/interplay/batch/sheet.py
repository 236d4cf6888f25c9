"""The contact sheet of a sweep: a still of every variant and its key figures, in one HTML
page at the top of the sweep's folder (contact_sheet.html), sortable by any column.

Every still is drawn by the preview renderer (outputs/render) from the variant's saved run,
at the same time and through the same camera (``--camera``, else one framing every variant's
motion), so that side by side the stills differ only where the variants do.
"""
from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from ..io.atomic import atomic_path

STILL_SIZE = (480, 270)  # px
SHEET = "contact_sheet.html"


def render_stills(out: Path, rows: list, at: float | None = None, camera=None,
                  size=STILL_SIZE) -> dict:
    """stills/<id>.png for every finished variant at time ``at`` (s; None: half its
    duration); returns {id: path relative to out}. A still already drawn with the same camera
    and time is kept."""
    from ..outputs.render.camera import default_camera
    from ..outputs.render.gl import Renderer
    from ..outputs.render.overlay import draw_label
    from ..outputs.rundata import load_run
    runs = {r["id"]: load_run(out / r["id"]) for r in rows if r["status"] == "ok"}
    if not runs:
        return {}
    times = {vid: min(run.duration / 2 if at is None else at, run.duration)
             for vid, run in runs.items()}
    if camera is None:  # frame every variant as it is in its still
        boxes = np.array([b for vid, run in runs.items() for b in run.bounds(times[vid])])
        camera = default_camera(boxes.min(0), boxes.max(0), size[0] / size[1])
    folder = out / "stills"
    folder.mkdir(exist_ok=True)
    index_path = folder / "stills.json"
    try:
        index = json.loads(index_path.read_text())
    except (OSError, ValueError):
        index = {}
    labels = {r["id"]: ", ".join(f"{k}={v}" for k, v in r["values"].items()) for r in rows}
    made = {}
    for vid, run in runs.items():
        t = times[vid]
        key = {"camera": camera.spec(), "t": t, "size": list(size)}
        path = folder / f"{vid}.png"
        if index.get(vid) != key or not path.exists():
            with Renderer(run, size, camera) as r:
                img = draw_label(r.render(run, t), [labels[vid], f"t = {t:.2f} s"])
            save_png(path, img)
            index[vid] = key
        made[vid] = f"stills/{vid}.png"
    with atomic_path(index_path) as tmp:
        tmp.write_text(json.dumps(index, indent=1))
    return made


def save_png(path: Path, img: np.ndarray):
    from PIL import Image
    with atomic_path(path) as tmp:
        Image.fromarray(img).save(tmp, format="PNG")


def _cell(v) -> tuple[str, str]:
    """(shown text, sort key) of a value."""
    if v is None or v == "":
        return "-", ""
    if isinstance(v, bool):
        return str(v), str(v)
    if isinstance(v, (int, float)):
        return f"{v:.4g}", repr(float(v))
    if isinstance(v, list) and v and all(isinstance(x, (int, float)) for x in v):
        return ", ".join(f"{x:.2f}" for x in v), repr(float(np.linalg.norm(v)))  # by length
    return str(v), str(v)


def columns(doc: dict) -> list:
    """(heading, row -> value) for every column of the sheet."""
    cols = [(k, lambda r, k=k: r["values"].get(k)) for k in doc["keys"]]
    cols.append(("status", lambda r: r["status"] if r["status"] != "error"
                 else f"error: {r.get('error')}"))
    t = lambda r, q, s: ((r.get("table") or {}).get(q) or {}).get(s)  # noqa: E731
    cols += [("force max (N)", lambda r: t(r, "force_N", "max")),
             ("force mean (N)", lambda r: t(r, "force_N", "mean")),
             ("accel. max (m/s²)", lambda r: t(r, "acceleration_m_s2", "max")),
             ("accel. mean (m/s²)", lambda r: t(r, "acceleration_m_s2", "mean"))]
    labels = dict.fromkeys(k for r in doc["variants"] for k in (r.get("figures") or {}))
    cols += [(k, lambda r, k=k: (r.get("figures") or {}).get(k)) for k in labels]
    strained = dict.fromkeys(s for r in doc["variants"]
                             for s, d in (r.get("diagnostics") or {}).items() if "max_strain" in d)
    cols += [(f"{s} max strain", lambda r, s=s: ((r.get("diagnostics") or {}).get(s) or {})
              .get("max_strain")) for s in strained]
    cols += [("advice", lambda r: r.get("advice")),
             ("warnings", lambda r: len(r["warnings"]) if "warnings" in r else None),
             ("simulate (s)", lambda r: (r.get("timings") or {}).get("simulate_s")),
             ("wall (s)", lambda r: (r.get("timings") or {}).get("wall_s"))]
    return cols


def write_sheet(out: Path, doc: dict, stills: dict) -> Path:
    """contact_sheet.html in ``out``: a row per variant (still, values, figures); click a
    heading to sort by it."""
    cols = columns(doc)
    head = "".join(f"<th>{html.escape(h)}</th>" for h, _ in [("still", None), ("id", None),
                                                               *cols])
    body = []
    for r in doc["variants"]:
        vid = html.escape(r["id"])
        still = stills.get(r["id"])
        link = f"{vid}/report.html" if (out / r["id"] / "report.html").exists() else f"{vid}/"
        img = (f'<a href="{link}"><img src="{html.escape(still)}" loading="lazy"></a>' if still
               else "")
        cells = [f"<td>{img}</td>", f'<td data-v="{vid}"><a href="{link}">{vid}</a></td>']
        for _, fn in cols:
            shown, key = _cell(fn(r))
            cells.append(f'<td data-v="{html.escape(key)}">{html.escape(shown)}</td>')
        cls = "" if r["status"] == "ok" else f' class="{html.escape(r["status"])}"'
        body.append(f"<tr{cls}>{''.join(cells)}</tr>")
    counts = doc.get("counts", {})
    title = f"{doc['scene']} sweep: {len(doc['variants'])} variants"
    page = PAGE.format(title=html.escape(title), head=head, body="\n".join(body),
                       counts=html.escape(", ".join(f"{v} {k}" for k, v in counts.items())),
                       base=html.escape(_base(doc.get("base", {}))))
    path = out / SHEET
    with atomic_path(path) as tmp:
        tmp.write_text(page)
    return path


def _base(base: dict) -> str:
    """The base run as its command line."""
    opts = [f"--{k} {v}" for k, v in base.items() if k not in ("scene", "sets") and v is not None]
    return " ".join(["interplay run", str(base.get("scene", "")), *opts,
                     *(f"--set {s}" for s in base.get("sets", ()))])


PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font: 14px system-ui, sans-serif; margin: 1.5em; color: #222; }}
table {{ border-collapse: collapse; }}
th {{ cursor: pointer; background: #eee; position: sticky; top: 0; padding: 4px 8px; }}
th:hover {{ background: #ddd; }}
td {{ border-top: 1px solid #ddd; padding: 4px 8px; text-align: right; }}
td img {{ width: 240px; display: block; }}
tr.error td {{ background: #fbe9e7; }} tr.pending td {{ color: #999; }}
</style></head><body>
<h1>{title}</h1>
<p>{counts}. Every variant is <code>{base}</code> with its own values. Click a heading to sort; click a still for the
variant's report. Force and acceleration: the main interaction over its contact period (the
paper's Table I).</p>
<table id="sheet"><thead><tr>{head}</tr></thead><tbody>
{body}
</tbody></table>
<script>
document.querySelectorAll("#sheet th").forEach((th, col) => th.addEventListener("click", () => {{
  const tbody = document.querySelector("#sheet tbody");
  const rows = Array.from(tbody.rows);
  const dir = th.dataset.dir === "1" ? -1 : 1;
  th.dataset.dir = dir === 1 ? "1" : "-1";
  const key = r => r.cells[col].dataset.v ?? "";
  rows.sort((a, b) => {{
    const x = key(a), y = key(b), nx = parseFloat(x), ny = parseFloat(y);
    if (x === "" || y === "") return (x === "") - (y === "");
    return (isNaN(nx) || isNaN(ny) ? x.localeCompare(y) : nx - ny) * dir;
  }});
  rows.forEach(r => tbody.appendChild(r));
}}));
</script>
</body></html>
"""
