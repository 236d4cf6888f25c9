"""Checkpoints of a run: every system's and interaction's ``capture()`` plus the scheduler's
own state (which pass, which step, the logs, tracks, frames and monitors so far), as one
``.npz`` of plain arrays with a JSON header, written atomically, read back with
``allow_pickle=False``.

A checkpoint is taken at a coupling-step boundary, so restoring it and running on repeats the
uninterrupted run bit for bit (the systems' restore is exact: tests/test_contracts.py). The
run's *request* (scene, coupling, parameters, duration, ...) travels in the header, so
``interplay run --resume DIR`` rebuilds the same scene before restoring into it.
"""
from __future__ import annotations

import json
import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..io.atomic import atomic_path

FORMAT = 1
FILE = "checkpoint.npz"


@dataclass
class Checkpointer:
    """When and where a run saves its checkpoints: every ``every_s`` simulated seconds
    and every ``every_wall_s`` seconds of wall time (None: never by that clock), into
    ``path``; ``request``: the JSON-able description of the run (it is resumed from it)."""
    path: Path
    request: dict = field(default_factory=dict)
    every_s: float | None = None
    every_wall_s: float | None = 300.0
    saved: int = 0
    _next_sim: float = 0.0
    _next_wall: float = 0.0

    def start(self, t_sim: float):
        self._next_sim = t_sim + self.every_s if self.every_s else float("inf")
        self._next_wall = (wallclock.monotonic() + self.every_wall_s if self.every_wall_s
                           else float("inf"))

    def due(self, t_sim: float) -> bool:
        return t_sim >= self._next_sim or wallclock.monotonic() >= self._next_wall

    def save(self, header: dict, arrays: dict, t_sim: float):
        write(self.path, {**header, "request": self.request}, arrays)
        self.saved += 1
        self.start(t_sim)


def write(path, header: dict, arrays: dict):
    """One .npz: the header as JSON bytes under "__header__", then the arrays."""
    blob = np.frombuffer(json.dumps({"format": FORMAT, **header}).encode(), dtype=np.uint8)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, __header__=blob, **arrays)


def read(path) -> tuple[dict, dict]:
    """(header, arrays) of a checkpoint; OutputError (one line) for anything damaged."""
    path = Path(path)
    if not path.is_file():
        raise OutputError(f"{path}: no checkpoint here; --resume takes the --out folder of a "
                          "run that was interrupted")
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        header = json.loads(arrays.pop("__header__").tobytes().decode())
    except Exception as e:  # noqa: BLE001 - zip, zlib, JSON and numpy errors alike
        raise OutputError(f"{path}: the checkpoint is damaged ({type(e).__name__}: {e}); "
                          "run again without --resume") from None
    if header.get("format") != FORMAT:
        raise OutputError(f"{path}: checkpoint format {header.get('format')!r}, this Interplay "
                          f"reads {FORMAT}; run again without --resume")
    return header, arrays


# --- flattening the scheduler's state into arrays ---------------------------------------------
def put(arrays: dict, prefix: str, snap: dict):
    for k, v in snap.items():
        arrays[f"{prefix}/{k}"] = np.asarray(v)


def take(arrays: dict, prefix: str) -> dict:
    n = len(prefix) + 1
    return {k[n:]: v for k, v in arrays.items() if k.startswith(prefix + "/")
            and "/" not in k[n:]}


def put_log(arrays, prefix, log):
    put(arrays, prefix, {"t": log.t, "force": log.force, "torque": log.torque,
                         "active": log.active, "peak": log.peak, "n": np.array(log._n)})
    if log.standin is not None:
        put_log(arrays, prefix + "/standin", log.standin)


def take_log(arrays, prefix, log):
    from .forcelog import ForceLog
    a = take(arrays, prefix)
    log.t, log.force, log.torque = a["t"].copy(), a["force"].copy(), a["torque"].copy()
    log.active, log.peak, log._n = a["active"].copy(), a["peak"].copy(), int(a["n"])
    if f"{prefix}/standin/t" in arrays:
        log.standin = ForceLog(log.name, log.primary, log.primary, "stand-in",
                               log.primary_mass)
        take_log(arrays, prefix + "/standin", log.standin)


def put_frames(arrays, prefix, fr: dict):
    arrays[f"{prefix}/t"] = np.asarray(fr["t"], dtype=float)
    if fr["data"]:
        for key in fr["data"][0]:
            arrays[f"{prefix}/{key}"] = np.stack([d[key] for d in fr["data"]])


def take_frames(arrays, prefix) -> dict:
    a = take(arrays, prefix)
    t = a.pop("t")
    data = [{k: v[i].copy() for k, v in a.items()} for i in range(len(t))]
    return {"t": [float(x) for x in t], "data": data}
