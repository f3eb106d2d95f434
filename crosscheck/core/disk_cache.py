"""The mechanics of the harness's disk caches: where they live, the key of an entry, and
entries that are either exactly what was stored or nothing.

Two caches use it: loaded case files (:mod:`crosscheck.cases.cache`) and the exact truths of
scenes (:mod:`crosscheck.truth.cache`).  Both live under one folder: ``$CROSSCHECK_CACHE``
if set, else ``$XDG_CACHE_HOME/crosscheck/cases`` (``~/.cache/crosscheck/cases``); the
truths in its ``truths/`` sub-folder.  ``CROSSCHECK_NO_CACHE=1`` turns both off; deleting
the folder is always safe.

- :func:`code_hash`: the SHA-256 of the source of the packages whose code decides an
  entry, with the crosscheck, pydantic and Python versions: a changed module is a new key;
- :func:`get`: an entry is a pickle behind its own SHA-256; one that is truncated, corrupt,
  unreadable, of an older class layout or rejected by the caller's check is None, never a
  crash and never a wrong value;
- :func:`put`: written to a temporary file renamed into place (concurrent runs never see
  half an entry); a folder that cannot be written only costs the speed-up; past ``limit``
  entries the older half is dropped.

Entries are pickles: like any cache, the folder must be your own.

>>> import tempfile
>>> where = Path(tempfile.mkdtemp())
>>> put(where, "k", [1, 2], limit=10)
>>> get(where, "k", lambda value: isinstance(value, list)), get(where, "nope", bool)
([1, 2], None)
"""

from __future__ import annotations

import hashlib
import os
import pickle
import platform
import sys
import tempfile
from collections.abc import Callable, Sequence
from functools import cache
from pathlib import Path
from typing import Any

import pydantic

import crosscheck

ROOT = Path(__file__).resolve().parents[2]
"""The checkout (the folder holding ``crosscheck/`` and ``reference_impl/``)."""


def folder(sub: str = "") -> Path | None:
    """The cache folder (``sub``: a sub-folder of it), or None when caching is turned off."""
    if os.environ.get("CROSSCHECK_NO_CACHE", "") not in ("", "0"):
        return None
    if os.environ.get("CROSSCHECK_CACHE"):
        base = Path(os.environ["CROSSCHECK_CACHE"])
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "crosscheck" \
            / "cases"
    return base / sub if sub else base


@cache
def code_hash(packages: tuple[str, ...], format_: int) -> str:
    """The hash of the code of ``packages`` (folders of the checkout) and the versions an
    entry of layout ``format_`` depends on."""
    digest = hashlib.sha256(f"{format_} {crosscheck.__version__} {pydantic.VERSION} "
                            f"{platform.python_implementation()} {sys.version}".encode())
    for package in packages:
        for source in sorted((ROOT / package).glob("*.py")):
            digest.update(source.name.encode() + b"\0" + source.read_bytes() + b"\0")
    return digest.hexdigest()


def key(code: str, *parts: bytes) -> str:
    """The entry name of ``parts`` under code hash ``code``."""
    digest = hashlib.sha256(code.encode())
    for part in parts:
        digest.update(b"\0" + part)
    return digest.hexdigest()


def get(where: Path, name: str, valid: Callable[[Any], bool]) -> Any | None:
    """The stored entry ``name`` if it is exactly what was stored and ``valid``; else None."""
    try:
        raw = (where / f"{name}.pickle").read_bytes()
    except OSError:
        return None
    check, payload = raw[:32], raw[32:]
    if len(raw) <= 32 or hashlib.sha256(payload).digest() != check:
        return None
    try:
        value = pickle.loads(payload)
    except Exception:  # a payload of an older class layout: compute it afresh
        return None
    return value if valid(value) else None


def put(where: Path, name: str, value: object, limit: int) -> None:
    """Store ``value`` as entry ``name``; a folder that cannot be written is skipped."""
    payload = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    try:
        where.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=where, suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(hashlib.sha256(payload).digest() + payload)
        os.replace(temporary, where / f"{name}.pickle")
        _prune(where, limit)
    except OSError:
        Path(temporary).unlink(missing_ok=True)


def _prune(where: Path, limit: int) -> None:
    """Keep the folder bounded: past ``limit`` entries, drop the older half."""
    stored: Sequence[Path] = list(where.glob("*.pickle"))
    if len(stored) > limit:
        stored = sorted(stored, key=lambda p: p.stat().st_mtime)
        for old in stored[:len(stored) // 2]:
            old.unlink(missing_ok=True)
