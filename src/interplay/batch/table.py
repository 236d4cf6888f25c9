"""The sweep table: one row per variant (its values, the paper's Table I figures of its main
interaction, the scene's own figures, diagnostics, warnings, timings, exit status), written
as sweep.json (nested, every field) and sweep.csv (flat, one column per figure).

A row is data from the run's summary (summary.json), so a row read back from a finished
variant's folder is the row it had when it ran.
"""
from __future__ import annotations

import csv
import io
import json

from ..io.atomic import atomic_path
from ..result import finite

ROW_FILE = "variant.json"  # in each variant's folder: its row (written last: it marks it done)


def figures_of(summary: dict, main: str | None) -> dict:
    """The row's figures from a run's summary: Table I of the main interaction (masses, force
    and effective acceleration min/max/mean over the contact period), every interaction's
    statistics, the scene's figures, the advice, the diagnostics and the warnings."""
    masses = {s["name"]: s.get("mass_kg") for s in summary["systems"]}
    stats = [{k: it.get(k) for k in ("name", "primary", "secondary", "mode", "force_N",
                                     "acceleration_m_s2", "contact_s")}
             for it in summary["interactions"]]
    table = next((dict(s, primary_kg=masses.get(s["primary"]),
                       secondary_kg=masses.get(s["secondary"]))
                  for s in stats if s["name"] == main), None)
    return {"coupling": summary["coupling"], "table": table, "interactions": stats,
            "figures": summary.get("figures", {}), "advice": summary["advice"]["mode"],
            "diagnostics": summary["diagnostics"], "warnings": list(summary["warnings"])}


def write_table(out, doc: dict) -> list:
    """sweep.json and sweep.csv in ``out`` (atomically); returns their paths."""
    doc = finite(doc)
    paths = [out / "sweep.json", out / "sweep.csv"]
    with atomic_path(paths[0]) as tmp:
        tmp.write_text(json.dumps(doc, indent=2, allow_nan=False))
    with atomic_path(paths[1]) as tmp:
        tmp.write_text(to_csv(doc["variants"], doc["keys"]))
    return paths


def to_csv(rows: list, keys: list) -> str:
    """One line per variant, columns: id, status, exit, the varied keys, then every figure
    any row has (a variant that failed leaves its figures empty)."""
    flat = [flatten(r, keys) for r in rows]
    columns = list(dict.fromkeys(c for f in flat for c in f))
    buf = io.StringIO()
    w = csv.DictWriter(buf, columns, restval="", lineterminator="\n")
    w.writeheader()
    w.writerows(flat)
    return buf.getvalue()


def flatten(row: dict, keys: list) -> dict:
    out = {"id": row["id"], "status": row["status"], "exit": row.get("exit", "")}
    out.update({k: row["values"].get(k, "") for k in keys})
    out["coupling"] = row.get("coupling", "")
    t = row.get("table")
    if t:
        out["interaction"] = t["name"]
        for q, unit, short in (("force_N", "N", "force"), ("acceleration_m_s2", "m_s2", "accel")):
            for s in ("min", "max", "mean"):
                out[f"{short}_{s}_{unit}"] = t[q][s]
        c = t.get("contact_s") or ("", "")
        out["contact_start_s"], out["contact_end_s"] = c[0], c[1]
    for label, v in (row.get("figures") or {}).items():
        out[label] = " ".join(format(x, ".6g") for x in v) if isinstance(v, list) else v
    for system, d in (row.get("diagnostics") or {}).items():
        out[f"{system}.final_ke_J"] = (d.get("kinetic_energy_J") or {}).get("final")
        out[f"{system}.lowest_z_m"] = d.get("lowest_z_m")
        if "max_strain" in d:
            out[f"{system}.max_strain"] = d["max_strain"]
    if "advice" in row:
        out["advice"] = row["advice"]
    for k, v in (row.get("timings") or {}).items():
        if k.endswith("_s"):
            out[k] = v
    out["warnings"] = len(row.get("warnings") or [])
    out["warning_text"] = " | ".join(row.get("warnings") or [])
    out["error"] = row.get("error") or ""
    out["ran"] = row.get("ran", "")
    return {k: ("" if v is None else v) for k, v in out.items()}
