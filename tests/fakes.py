"""Fake adapters with known behaviour: they live in the public kit,
:mod:`crosscheck.testing.fakes`; re-exported here for the tests that import ``tests.fakes``."""

from __future__ import annotations

from crosscheck.testing.fakes import (
    Aborts,
    AlwaysRight,
    BusyLoop,
    BusyLoopTwice,
    ClaimsResponse,
    Conforming,
    CrashesOnSpheresAt,
    DeclaresHangs,
    HangsOnDistance,
    HangsOnDistanceRestRaises,
    HitOnly,
    Hogs,
    Leaks,
    OffByOne,
    Raises,
    SleepsForever,
    SlowWithDeclaredHang,
    TouchingIsContact,
    Unavailable,
)

__all__ = [
    "Aborts",
    "AlwaysRight",
    "BusyLoop",
    "BusyLoopTwice",
    "ClaimsResponse",
    "Conforming",
    "CrashesOnSpheresAt",
    "DeclaresHangs",
    "HangsOnDistance",
    "HangsOnDistanceRestRaises",
    "HitOnly",
    "Hogs",
    "Leaks",
    "OffByOne",
    "Raises",
    "SleepsForever",
    "SlowWithDeclaredHang",
    "TouchingIsContact",
    "Unavailable",
]
