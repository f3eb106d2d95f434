"""A cache of loaded case files, so that a run does not re-validate files that did not change.

Loading the suite (parse TOML, validate with pydantic, check against the oracle, expand
sweeps, 2-D twins and swaps) costs about half a second each run.
:func:`crosscheck.cases.load.load_paths` keeps, per case file, the cases that file expands
to, under a key that is the SHA-256 of

- the file's bytes and its path as given (the path is each case's ``source``);
- :data:`CODE`: the source of every module loading depends on (``crosscheck/cases``,
  ``crosscheck/core``, ``crosscheck/truth``, ``reference_impl``), the crosscheck version,
  the pydantic and Python versions and :data:`FORMAT`.

So a changed file, schema, loader, oracle or library version is a new key and the file is
validated again.  Only a file that loaded without a single error is stored: an error is
never cached, it is found again each time.  An entry is a pickle behind its own SHA-256;
one that is truncated, corrupt, unreadable or not a list of cases is ignored (and
overwritten by the fresh load), never a crash and never a wrong case.  Writes go to a
temporary file renamed into place, so concurrent runs never see half an entry; a folder
that cannot be written only costs the speed-up.

Where: ``$CROSSCHECK_CACHE`` if set, else ``$XDG_CACHE_HOME/crosscheck/cases``
(``~/.cache/crosscheck/cases``).  ``CROSSCHECK_NO_CACHE=1`` turns it off; so does
``load_paths(..., cache=False)``.  Deleting the folder is always safe.  Entries are
pickles: like any cache, the folder must be your own.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import platform
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pydantic

import crosscheck
from crosscheck.core.schema import (
    AabbCase,
    AnyCase,
    ResponseCase,
    SceneCase,
    SphereCase,
    ToiCase,
)

FORMAT = 1
"""The layout of an entry; bump it when :class:`Entry` changes."""
PACKAGES = ("crosscheck/cases", "crosscheck/core", "crosscheck/truth", "reference_impl")
"""The source folders whose code decides what a case file loads to."""
ROOT = Path(__file__).resolve().parents[2]
CASE_TYPES = (AabbCase, SphereCase, ResponseCase, SceneCase, ToiCase)
LIMIT = 2000
"""Most entries kept (a hit refreshes nothing: an entry's age is its write time)."""


@dataclass(frozen=True, slots=True)
class Entry:
    """What one error-free case file loaded to: its block count and its expanded cases."""

    blocks: int
    cases: list[AnyCase]


@cache
def code_hash() -> str:
    """The hash of everything but the file that decides what a file loads to."""
    digest = hashlib.sha256(f"{FORMAT} {crosscheck.__version__} {pydantic.VERSION} "
                            f"{platform.python_implementation()} {sys.version}".encode())
    for folder in PACKAGES:
        for source in sorted((ROOT / folder).glob("*.py")):
            digest.update(source.name.encode() + b"\0" + source.read_bytes() + b"\0")
    return digest.hexdigest()


def folder() -> Path | None:
    """The cache folder, or None when caching is turned off."""
    if os.environ.get("CROSSCHECK_NO_CACHE", "") not in ("", "0"):
        return None
    if os.environ.get("CROSSCHECK_CACHE"):
        return Path(os.environ["CROSSCHECK_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "crosscheck" / "cases"


def key(path: Path, data: bytes) -> str:
    """The entry name of case file ``path`` holding ``data``."""
    digest = hashlib.sha256(code_hash().encode() + b"\0" + str(path).encode() + b"\0")
    digest.update(data)
    return digest.hexdigest()


def get(where: Path, name: str) -> Entry | None:
    """The stored entry ``name``, or None if it is missing or not exactly what was stored."""
    try:
        raw = (where / f"{name}.pickle").read_bytes()
    except OSError:
        return None
    check, payload = raw[:32], raw[32:]
    if len(raw) <= 32 or hashlib.sha256(payload).digest() != check:
        return None
    try:
        entry = pickle.loads(payload)
    except Exception:  # a payload of an older class layout: load the file afresh
        return None
    if not (isinstance(entry, Entry) and isinstance(entry.cases, list)
            and all(isinstance(c, CASE_TYPES) for c in entry.cases)):
        return None
    return entry


def put(where: Path, name: str, blocks: int, cases: Sequence[AnyCase]) -> None:
    """Store an error-free file's cases; a folder that cannot be written is skipped."""
    payload = pickle.dumps(Entry(blocks, list(cases)), protocol=pickle.HIGHEST_PROTOCOL)
    try:
        where.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=where, suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(hashlib.sha256(payload).digest() + payload)
        os.replace(temporary, where / f"{name}.pickle")
        _prune(where)
    except OSError:
        Path(temporary).unlink(missing_ok=True)


def _prune(where: Path) -> None:
    """Keep the folder bounded: past :data:`LIMIT` entries, drop the older half."""
    stored = list(where.glob("*.pickle"))
    if len(stored) > LIMIT:
        stored.sort(key=lambda p: p.stat().st_mtime)
        for old in stored[:len(stored) // 2]:
            old.unlink(missing_ok=True)
