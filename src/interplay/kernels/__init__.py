"""Numba kernels: pure functions over NumPy arrays, no Python objects. Hot loops live here only.

Their machine code is cached on disk (``cache=True``) in a folder named after a hash of every
kernel module's source, ``interplay-<hash>`` under ``$NUMBA_CACHE_DIR`` or this package's
``__pycache__``. Numba checks a cached function against its own file only, and a caller's
cached code has its callees' compiled in, so after an edit of a kernel another module calls
(the contact law, the spring forces) the callers would keep running the old callee; with the
folder keyed by all of them, any kernel edit starts a fresh cache (the folders of older sources
in ``__pycache__`` are removed). Every kernel module is imported here, while Numba's cache
folder is set to that one, and the setting is put back after, so other libraries' cached
functions are not moved.
"""
from __future__ import annotations

import hashlib
import importlib
import os
import pkgutil
import shutil
from pathlib import Path

from numba.core import config

_HERE = Path(__file__).resolve().parent
_MODULES = sorted(m.name for m in pkgutil.iter_modules([str(_HERE)]))


def _source_hash(here: Path = _HERE) -> str:
    """A short hash of the source (names and bytes) of every kernel module in ``here``."""
    h = hashlib.sha1()
    for f in sorted(here.glob("*.py")):
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def _cache_folder() -> Path:
    """The cache folder of these sources; the stale folders beside it in our own __pycache__
    go (a user's NUMBA_CACHE_DIR may be shared by other checkouts: left alone)."""
    user = os.environ.get("NUMBA_CACHE_DIR")
    base = Path(user) if user else _HERE / "__pycache__"
    folder = base / f"interplay-{_source_hash()}"
    if not user and base.is_dir() and not folder.exists():
        for old in base.glob("interplay-*"):
            shutil.rmtree(old, ignore_errors=True)
        for old in (*base.glob("*.nbi"), *base.glob("*.nbc")):  # Numba's own in-tree layout
            old.unlink(missing_ok=True)
    return folder


def _import_all():
    saved = config.CACHE_DIR
    config.CACHE_DIR = str(_cache_folder())
    try:
        for name in _MODULES:
            importlib.import_module(f"{__name__}.{name}")
    finally:
        config.CACHE_DIR = saved


_import_all()
