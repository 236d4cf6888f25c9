"""Interplay: secondary motion by coupling separate physically based simulations.

A Scene holds systems (rigid bodies, spring-mass networks, ...) joined by interactions, each
coupled two-way, one-way or hybrid. ``import interplay`` is cheap: the names below load their
modules (and Numba) on first use.
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

_EXPORTS = {
    "Scene": "scene",
    "Result": "result",
    "Track": "coupling.track",
    "System": "systems.base",
    "RigidBody": "systems.rigid",
    "Sphere": "systems.rigid",
    "SphereParams": "systems.rigid",
    "SpringNetwork": "systems.springmass",
    "Springs": "systems.springmass",
    "StaticPlane": "systems.static",
    "Interaction": "interactions.base",
    "StandIn": "interactions.base",
    "ContactParams": "interactions.contact",
    "SphereCordContact": "interactions.contact",
    "SpherePlaneContact": "interactions.contact",
    "DampingField": "interactions.standins",
    "DampingFieldParams": "interactions.standins",
    "InterplayError": "errors",
    "ParameterError": "errors",
    "SceneError": "errors",
    "StabilityError": "errors",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module 'interplay' has no attribute {name!r}")
