"""The gallery: one module per scene, each registering its ``SceneSpec`` as ``SPEC``."""
from __future__ import annotations

import importlib

from ..errors import SceneError

#: the scene modules, loaded on demand (a scene's module imports its systems)
MODULES = ("basketball", "bungee", "diver", "flags", "kites", "leaves", "mat", "owl_creek",
           "pond", "puddle", "runner", "stunt_kite", "swing", "trampoline")


def spec(name: str):
    """The SceneSpec of the scene called ``name`` (or named by its module: stunt_kite for
    stunt-kite); SceneError listing the known scenes."""
    for module in MODULES:
        if name in (module, module.replace("_", "-")):
            return importlib.import_module(f"{__name__}.{module}").SPEC
    raise SceneError(f"unknown scene {name!r}; known scenes: {', '.join(sorted(MODULES))}")


def all_specs() -> list:
    """Every registered scene's SceneSpec, by name."""
    return [spec(name) for name in sorted(MODULES)]
