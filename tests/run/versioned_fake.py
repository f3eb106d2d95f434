"""A fake engine whose answers depend on the version of a package it imports, for the version
matrix's tests (``tests/run/test_pinned.py``).

The package, ``crosscheck-fake-engine`` (module ``ccfake_engine``), is never on the package
index: the tests write one wheel per version into a folder and point pip at it
(``PIP_FIND_LINKS``, ``PIP_NO_INDEX``).  Its module holds ``OFFSET``, added to the exact
distance: 0 at version 1.0 (the engine agrees), 0.5 at 2.0 (it disagrees).
"""

from __future__ import annotations

import importlib
from importlib import metadata
from typing import Any, ClassVar

from crosscheck.core.contract import Adapter, Capability, Conventions, all_capabilities
from crosscheck.core.model import Kind, Observation
from crosscheck.core.schema import AnyCase
from crosscheck.truth import oracle

PACKAGE = "crosscheck-fake-engine"
MODULE = "ccfake_engine"


class VersionedFake(Adapter):
    """Exact answers, with the distance moved by the installed package's ``OFFSET``."""

    name: ClassVar[str] = "fake-versioned"
    engine: ClassVar[str] = "fake-versioned"
    package: ClassVar[str] = PACKAGE
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE)
    conventions: ClassVar[Conventions] = Conventions()

    def version(self) -> str:
        return metadata.version(PACKAGE)

    def available(self) -> str | None:
        try:
            importlib.import_module(MODULE)
        except ImportError as exc:
            return f"{MODULE} not importable: {exc}"
        return None

    def prepare(self, case: AnyCase) -> Any:
        return case

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        assert isinstance(truth.distance, float)
        offset = float(importlib.import_module(MODULE).OFFSET)
        return Observation(hit=truth.hit, distance=truth.distance + offset,
                           normal=truth.normal)
