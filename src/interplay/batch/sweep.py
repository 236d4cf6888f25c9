"""``interplay sweep``: every variant of a wedge as a normal run, on the executor.

Each variant runs in a worker exactly as ``interplay run`` would (the same parameter code, the
same build, the same outputs), into ``DIR/.<id>.part-<pid>/``, which is renamed to
``DIR/<id>/`` once its files and its row (``variant.json``) are written: a folder named by an
id is always complete. A variant that fails leaves its folder with the row (status, exit
status, the error) and ``error.txt`` (the traceback), and the sweep goes on. Re-running the
same sweep finds the finished variants by their ids and runs only the others (``--retry-failed``
also reruns the failed ones). The table (sweep.json, sweep.csv) is rewritten after every
variant, in the wedge's order, and the contact sheet at the end.
"""
from __future__ import annotations

import json
import os
import shutil
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

from .executor import Failure, pack, unpack, worker_info
from .table import ROW_FILE, figures_of, write_table
from .variants import Variant


@dataclass(frozen=True)
class VariantTask:
    """What a worker needs: the variant, where to write (None: a temporary folder, packed and
    returned, for executors without a shared disk) and the outputs to write."""
    variant: Variant
    out_root: str | None
    options: object


def run_variant(task: VariantTask) -> dict:
    """Run one variant in this process and write its folder; returns {"row": ...} and, when
    out_root is None, "files": the folder packed."""
    from ..cli.command import run_scene, scene_summary
    from ..outputs.writer import write_outputs
    t0 = time.perf_counter()
    v = task.variant
    root = Path(task.out_root) if task.out_root else Path(tempfile.mkdtemp(prefix="interplay-"))
    part = root / f".{v.id}.part-{os.getpid()}"
    shutil.rmtree(part, ignore_errors=True)
    part.mkdir(parents=True)
    row = {"id": v.id, "values": dict(v.values), "worker": worker_info()}
    timings = {}
    try:
        spec, coupling, kw = v.request.resolve()
        result = run_scene(spec, coupling, kw, quiet=True, force=v.request.force)
        t1 = time.perf_counter()
        options = replace(task.options, timings={}, quiet=True)  # its own timings; no bars
        write_outputs(result, part, options, scene_summary(spec, result))
        summary = json.loads((part / "summary.json").read_text())  # the row: saved data
        timings = {"simulate_s": result.total_s, **{k: v for k, v in result.timings().items()
                                                     if k in ("primary_pass_s",
                                                              "secondary_pass_s",
                                                              "compile_s")},
                   "outputs_s": time.perf_counter() - t1,
                   **{k: x for k, x in options.timings.items() if k.endswith("_s")}}
        row.update(status="ok", exit=0, error=None, **figures_of(summary, result.main))
    except Exception as e:  # the variant failed: say so in its row; the sweep goes on
        f = Failure.of(e)
        row.update(status="error", exit=f.exit, error=f.message)
        (part / "error.txt").write_text(f.detail)
    row["timings"] = {**timings, "wall_s": time.perf_counter() - t0}
    commit(part, root / v.id, row)
    if task.out_root:
        return {"row": row}
    data = pack(root / v.id)
    shutil.rmtree(root, ignore_errors=True)
    return {"row": row, "files": data}


def commit(part: Path, final: Path, row: dict):
    """Write the row into the finished folder ``part`` and rename it to ``final`` (replacing
    an earlier failed attempt): the id's folder appears complete or not at all."""
    (part / ROW_FILE).write_text(json.dumps(row, indent=2))
    if final.exists():
        shutil.rmtree(final)
    os.rename(part, final)


def finished(out: Path, v: Variant) -> dict | None:
    """The row of a variant that an earlier sweep finished in ``out`` (None if none)."""
    p = out / v.id / ROW_FILE
    try:
        row = json.loads(p.read_text())
    except (OSError, ValueError):
        return None
    return row if row.get("id") == v.id else None


def warm(v: Variant):
    """Compile (or load) every Numba kernel the scene uses, once, here, before the workers
    start (batch/warm.py). Workers then load the cache."""
    from .warm import warm_request
    try:
        warm_request(v.request)
    except Exception:  # noqa: BLE001 - the variant itself will report what went wrong
        pass


def run_sweep(variants: list, out, options, executor, meta: dict, retry_failed: bool = False,
              log=print) -> dict:
    """Run the variants not finished in ``out`` on ``executor``; returns the table (also
    written to out/sweep.json and sweep.csv after every variant). meta: what the table says
    about the sweep (scene, keys, design, base request); log(line) reports progress."""
    out = Path(out)
    for stale in out.glob(".v*.part-*"):  # left by a sweep that was killed
        shutil.rmtree(stale, ignore_errors=True)
    for stale in out.glob(".*.part"):  # its table's or sheet's temporary (io/atomic.py)
        stale.unlink(missing_ok=True)
    rows = {}
    for v in variants:
        row = finished(out, v)
        if row is not None and (row["status"] == "ok" or not retry_failed):
            rows[v.id] = dict(row, ran="earlier")
    pending = [v for v in variants if v.id not in rows]
    t0 = time.perf_counter()
    doc = dict(meta, executor={"kind": executor.kind, "address": executor.address})

    def table():
        doc["variants"] = [rows.get(v.id, {"id": v.id, "values": v.values, "status": "pending"})
                           for v in variants]
        doc["counts"] = {s: sum(r["status"] == s for r in doc["variants"])
                         for s in ("ok", "error", "pending")}
        doc["wall_s"] = time.perf_counter() - t0
        write_table(out, doc)

    log(f"{len(variants)} variants: {len(rows)} finished earlier, {len(pending)} to run")
    table()
    if not pending:
        return doc
    warm(pending[0])
    with executor as ex:
        doc["executor"]["workers"] = ex.workers
        tasks = [VariantTask(v, str(out) if ex.shared_files else None, options) for v in pending]
        for n, (i, value) in enumerate(ex.map_unordered(run_variant, tasks), 1):
            v = pending[i]
            if isinstance(value, Failure):  # its worker died: record it as a failed variant
                row = {"id": v.id, "values": dict(v.values), "status": "error",
                       "exit": value.exit, "error": value.message}
                part = out / f".{v.id}.part-driver"
                part.mkdir(parents=True, exist_ok=True)
                commit(part, out / v.id, row)
            else:
                row = value["row"]
                if "files" in value:  # gathered from a node without our disk
                    commit(unpack(value["files"], out / f".{v.id}.part-driver"), out / v.id,
                           row)
            rows[v.id] = dict(row, ran="this sweep")
            table()
            wall = row.get("timings", {}).get("wall_s")
            log(f"[{n}/{len(pending)}] {v.id} {v.label()}: {row['status']}"
                + (f" ({wall:.1f} s)" if wall else "")
                + (f": {row['error']}" if row.get("error") else ""))
    return doc
