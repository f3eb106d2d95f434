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
pickles: like any cache, the folder must be your own.  The mechanics (folder, key, entries
checked by their SHA-256, pruning) are :mod:`crosscheck.core.disk_cache`, shared with the
scene truths' cache.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from crosscheck.core import disk_cache
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
CASE_TYPES = (AabbCase, SphereCase, ResponseCase, SceneCase, ToiCase)
LIMIT = 2000
"""Most entries kept (a hit refreshes nothing: an entry's age is its write time)."""


@dataclass(frozen=True, slots=True)
class Entry:
    """What one error-free case file loaded to: its block count and its expanded cases."""

    blocks: int
    cases: list[AnyCase]


def code_hash() -> str:
    """The hash of everything but the file that decides what a file loads to."""
    return disk_cache.code_hash(PACKAGES, FORMAT)


def folder() -> Path | None:
    """The cache folder, or None when caching is turned off."""
    return disk_cache.folder()


def key(path: Path, data: bytes) -> str:
    """The entry name of case file ``path`` holding ``data``."""
    return disk_cache.key(code_hash(), str(path).encode(), data)


def _valid(entry: object) -> bool:
    return (isinstance(entry, Entry) and isinstance(entry.cases, list)
            and all(isinstance(c, CASE_TYPES) for c in entry.cases))


def get(where: Path, name: str) -> Entry | None:
    """The stored entry ``name``, or None if it is missing or not exactly what was stored."""
    entry = disk_cache.get(where, name, _valid)
    return entry if isinstance(entry, Entry) else None


def put(where: Path, name: str, blocks: int, cases: Sequence[AnyCase]) -> None:
    """Store an error-free file's cases; a folder that cannot be written is skipped."""
    disk_cache.put(where, name, Entry(blocks, list(cases)), LIMIT)
