"""A run's output folder as one unit: a run id, staging, a manifest published last, a lock,
and the clean-up of what a killed run left.

Every output of a run is written into ``OUT/.staging-<run id>/`` first; the run id is inside
summary.json, scene.json and tracks.npz, and the manifest lists every file with its size and
SHA-256 (which binds the video, USD, OBJ and plots, whose formats carry no id of ours, to the
run). Publishing then:

1. writes ``manifest.json`` as ``"complete": false`` naming the new run and the old one;
2. moves the old run's files into ``OUT/.trash-<id>/``;
3. moves the staged files into OUT;
4. replaces ``manifest.json`` by the staged, complete one (the commit point); removes trash
   and staging.

Killed at any moment, OUT holds the previous complete run, or the files of one run (old or
new) under a manifest that says it is incomplete; never files of two runs under a complete
manifest. The next run in OUT (``claim``) finishes an interrupted publication when its staged
files are all there, and removes stale staging, trash and ``.part`` temporaries.
"""
from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import uuid
from pathlib import Path

from ..errors import OutputError
from ..io.atomic import atomic_path

MANIFEST = "manifest.json"
CHECKPOINT = "checkpoint.npz"
#: names a run writes at the top of OUT (what a folder without a manifest may hold)
KNOWN = ("summary.json", "tracks.npz", "scene.json", "run.usdc", "run.usda", "obj",
         "preview.mp4", "report.html")


def new_run_id() -> str:
    return uuid.uuid4().hex[:16]


class Lock:
    """An exclusive lock on OUT (``OUT/.lock``, flock: released by the kernel when the
    process dies, so a killed run never leaves it held)."""

    def __init__(self, out: Path):
        self.path = Path(out) / ".lock"
        self.fd = None

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self.fd)
            raise OutputError(f"{self.path.parent}: another interplay run is writing here; wait "
                              "for it or choose another --out") from None
        return self

    def __exit__(self, *exc):
        os.close(self.fd)


def sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def listing(root: Path) -> dict:
    """{relative path: {"bytes", "sha256"}} of every file under root (folders walked)."""
    out = {}
    for p in sorted(root.rglob("*")):
        rel = p.relative_to(root)
        if p.is_file() and not any(part.startswith(".") for part in rel.parts):
            out[rel.as_posix()] = {"bytes": p.stat().st_size, "sha256": sha256(p)}
    return out


def read_manifest(out: Path) -> dict | None:
    """The folder's manifest, None if it has none; OutputError if it is damaged."""
    p = Path(out) / MANIFEST
    if not p.exists():
        return None
    try:
        doc = json.loads(p.read_text())
        if not isinstance(doc, dict) or not isinstance(doc.get("run_id"), str):
            raise ValueError("no run_id")
        return doc
    except (ValueError, OSError) as e:
        raise OutputError(f"{p}: damaged manifest ({e}); run the scene again") from None


def _top(entries) -> list:
    return sorted({e.split("/")[0] for e in entries})


def publish(out: Path, staging: Path, run_id: str, request: dict | None = None):
    """Make the staged run OUT's run (steps 1-4 of the module docstring)."""
    files = listing(staging)
    doc = {"run_id": run_id, "complete": True, "request": request or {}, "files": files}
    with atomic_path(staging / ".manifest.json") as tmp:
        tmp.write_text(json.dumps(doc, indent=1))
    _finish(out, staging, run_id)


def _mark(out: Path, run_id: str, phase: str, previous):
    with atomic_path(out / MANIFEST) as tmp:
        tmp.write_text(json.dumps({"run_id": run_id, "complete": False, "publishing": phase,
                                   "previous": previous}))


def _finish(out: Path, staging: Path, run_id: str):
    try:
        mark = read_manifest(out)
    except OutputError:
        mark = None
    if mark is not None and mark.get("run_id") == run_id and mark.get("publishing"):
        phase, previous = mark["publishing"], mark.get("previous")
    else:  # 1: the folder says, from here on, that it holds no complete run
        previous = ({"run_id": mark["run_id"], "files": mark.get("files", {})}
                    if mark is not None and mark.get("complete") else None)
        phase = "clearing"
        _mark(out, run_id, phase, previous)
    if phase == "clearing":  # 2: the old run's files out of the way
        trash = out / f".trash-{run_id}"
        trash.mkdir(exist_ok=True)
        names = set(_top(previous["files"])) if previous else set(KNOWN)
        names |= {e.name for e in staging.iterdir() if not e.name.startswith(".")}
        for name in sorted(names):
            if (out / name).exists() or (out / name).is_symlink():
                os.replace(out / name, trash / name)
        _mark(out, run_id, "placing", previous)
    for entry in sorted(staging.iterdir()):  # 3: the new run's files in
        if not entry.name.startswith("."):
            os.replace(entry, out / entry.name)
    os.replace(staging / ".manifest.json", out / MANIFEST)  # 4: the commit point
    shutil.rmtree(out / f".trash-{run_id}", ignore_errors=True)
    shutil.rmtree(staging, ignore_errors=True)


def claim(out: Path) -> None:
    """Before a run writes into OUT (holding its Lock): finish a publication a killed run
    left half done (its staged files are always complete by then), and remove stale
    staging, trash and .part temporaries."""
    out = Path(out)
    try:
        doc = read_manifest(out)
    except OutputError:
        doc = None
    if doc is not None and doc.get("publishing"):
        staging = out / f".staging-{doc['run_id']}"
        if (staging / ".manifest.json").is_file():
            _finish(out, staging, doc["run_id"])
    for p in list(out.glob(".staging-*")) + list(out.glob(".trash-*")):
        shutil.rmtree(p, ignore_errors=True)
    for p in list(out.rglob(".*.part")):
        p.unlink(missing_ok=True)


def verify(out: Path) -> dict:
    """The manifest of a complete run in OUT whose files are all present with their sizes;
    OutputError (one line) for an incomplete or mixed folder. A folder with no manifest
    (written before manifests existed) returns {}."""
    out = Path(out)
    doc = read_manifest(out)
    if doc is None:
        return {}
    if not doc.get("complete"):
        raise OutputError(f"{out}: the run {doc['run_id']} was interrupted while its outputs "
                          "were being published; run the scene again (or any run into this "
                          "folder finishes the publication)")
    for rel, info in doc.get("files", {}).items():
        p = out / rel
        if not p.is_file() or p.stat().st_size != info.get("bytes"):
            raise OutputError(f"{out}: {rel} is missing or is not the file of run "
                              f"{doc['run_id']}; run the scene again")
    return doc
