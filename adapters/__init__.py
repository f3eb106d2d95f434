"""The adapter registry: an explicit, listable table of engine adapters.

Each entry names a module and a class; the module is imported only when the
adapter is asked for, so a missing engine shows as unavailable instead of an
ImportError at start-up.  Adding an engine means adding one module here and
one line to :data:`REGISTRY`.
"""

from __future__ import annotations

import importlib

from crosscheck.core.contract import Adapter

REGISTRY: dict[str, tuple[str, str]] = {
    "reference": ("adapters.reference", "ReferenceF64"),
    "reference-f32": ("adapters.reference", "ReferenceF32"),
    "fcl": ("adapters.fcl_engine", "Fcl"),
    "pybullet": ("adapters.pybullet_engine", "PyBulletTuned"),
    "pybullet-default": ("adapters.pybullet_engine", "PyBulletDefault"),
    "pymunk": ("adapters.pymunk_engine", "PymunkTuned"),
    "pymunk-default": ("adapters.pymunk_engine", "PymunkDefault"),
}


class UnknownEngine(KeyError):
    """Raised for an engine name that is not in the registry."""


def names() -> list[str]:
    """Every registered adapter name, in registry order."""
    return list(REGISTRY)


def get(name: str) -> Adapter:
    """Instantiate the adapter called ``name``."""
    try:
        module_name, class_name = REGISTRY[name]
    except KeyError:
        raise UnknownEngine(f"unknown engine {name!r}; known: {', '.join(REGISTRY)}") from None
    cls: type[Adapter] = getattr(importlib.import_module(module_name), class_name)
    return cls()
