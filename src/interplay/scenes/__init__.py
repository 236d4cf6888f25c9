"""The gallery: one module per scene, each with ``build(**params) -> Scene``."""
from __future__ import annotations

import importlib

from ..errors import SceneError

#: scene name -> (module, one-line description)
REGISTRY = {
    "basketball": ("basketball", "a basketball falls through a spring-mass net (two-way, "
                                 "one-way or hybrid)"),
    "bungee": ("bungee", "a figure leaps off a bridge on a spring-mass bungee cord (two-way)"),
    "flags": ("flags", "flags of cotton, nylon and canvas on poles in a gusty wind (one-way)"),
    "leaves": ("leaves", "a passing bicyclist's wake stirs up leaves that settle again (one-way)"),
    "pond": ("pond", "balls of different densities float, bob and sink in a pond (two-way)"),
    "puddle": ("puddle", "a keyframed foot steps in a shallow puddle and splashes it (one-way)"),
}


def load(name: str):
    """The scene module for ``name``; SceneError listing the known scenes otherwise."""
    if name not in REGISTRY:
        raise SceneError(f"unknown scene {name!r}; known scenes: {', '.join(sorted(REGISTRY))}")
    return importlib.import_module(f"{__name__}.{REGISTRY[name][0]}")
