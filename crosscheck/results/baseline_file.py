"""The baseline file: what a run said, row by row, as JSON Lines that read well in a diff.

:mod:`crosscheck.results.baseline` judges runs against a baseline; this module holds its
values (:class:`Entry`, :class:`Baseline`) and its file.  The first line is a header, then
one entry per line, sorted by engine, case and quantity, each with its fields in
:data:`ENTRY_FIELDS` order; an error is written as ``repr`` writes the float (it reads back
exactly), ``null`` when the row has none (NaN) and ``"inf"`` when it is infinite (JSON has
no infinity).  ``docs/baselines-and-ci.md`` shows a file.

:func:`read_baseline` refuses a file it cannot trust with a :class:`BaselineError` naming the
file, the line and the reason: a line that is not JSON, a missing or unknown field, an
unknown status or format, a duplicate entry, a negative margin.

>>> import tempfile
>>> path = Path(tempfile.mkdtemp()) / "baseline.jsonl"
>>> entry = Entry("touch", "e", "distance", "disagree", "tolerance", 0.1 + 0.2)
>>> write_baseline(Baseline({entry.key: entry}, 0.5, 2.0, "reports/r1"), path)
>>> read_baseline(path).entries[("touch", "e", "distance")].error == 0.1 + 0.2
True
>>> _ = path.write_text(path.read_text().replace("disagree", "wrong"))
>>> read_baseline(path)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
crosscheck.results.baseline_file.BaselineError: ...jsonl, line 2: unknown status 'wrong' ...
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from crosscheck.core.model import Status

DEFAULT_MARGIN = 0.5
"""How far a disagreeing row's error may grow before it is a regression: up to the bound
(the baseline's error) x (1 + margin).  Room for the rounding of a new compiler or library
build, not for a new bug."""
DEFAULT_STALE_FACTOR = 2.0
"""How far an error may shrink before the entry is stale: below bound / factor.  2, as
Drake's characterization tests fail when an error gets better than half its published
bound: a bound kept far above the error would hide the next regression."""
FORMAT = 1
"""The version of the baseline file format (its header's ``format``)."""
KIND = "crosscheck-baseline"
HEADER_FIELDS = ("format", "kind", "source", "margin", "stale_factor")
ENTRY_FIELDS = ("engine", "case", "quantity", "status", "category", "error")
"""The fields of an entry line, in the order they are written."""

Key = tuple[str, str, str]
"""(case, engine, quantity)."""


class BaselineError(ValueError):
    """A baseline file that cannot be used: its message names the file, the line, the reason."""


@dataclass(frozen=True)
class Entry:
    """One case x engine x quantity as a run said it; ``error`` NaN where the row has none."""

    case: str
    engine: str
    quantity: str
    status: str
    category: str
    error: float

    @property
    def key(self) -> Key:
        return (self.case, self.engine, self.quantity)


@dataclass(frozen=True)
class Baseline:
    """Every entry of a run by key, the margin and stale factor to judge with, and the run
    it was made from (``source``)."""

    entries: dict[Key, Entry]
    margin: float
    stale_factor: float
    source: str

    @property
    def engines(self) -> set[str]:
        return {engine for _, engine, _ in self.entries}


def settings_problem(margin: float, stale_factor: float) -> str | None:
    """Why these cannot judge (a margin must be finite and >= 0, a factor finite and >= 1)."""
    if not (math.isfinite(margin) and margin >= 0):
        return f"the margin must be a finite number >= 0, not {margin!r}"
    if not (math.isfinite(stale_factor) and stale_factor >= 1):
        return f"the stale factor must be a finite number >= 1, not {stale_factor!r}"
    return None


def _error_json(error: float) -> float | str | None:
    """An error as the file holds it: a float (repr, exact), null for NaN, "inf"."""
    if math.isnan(error):
        return None
    return error if math.isfinite(error) else ("inf" if error > 0 else "-inf")


def write_baseline(baseline: Baseline, path: Path) -> None:
    """Write ``baseline`` to ``path`` (whole or not at all): the header, then the entries
    sorted by engine, case and quantity, their fields in :data:`ENTRY_FIELDS` order."""
    header = {"format": FORMAT, "kind": KIND, "source": baseline.source,
              "margin": baseline.margin, "stale_factor": baseline.stale_factor}
    entries = sorted(baseline.entries.values(), key=lambda e: (e.engine, e.case, e.quantity))
    lines = [json.dumps(header)] + [json.dumps(
        {"engine": e.engine, "case": e.case, "quantity": e.quantity, "status": e.status,
         "category": e.category, "error": _error_json(e.error)}) for e in entries]
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("".join(line + "\n" for line in lines), encoding="utf-8")
    os.replace(tmp, path)


def read_baseline(path: Path) -> Baseline:
    """The baseline in ``path``; :class:`BaselineError` names the file, line and reason."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise BaselineError(f"{path}: cannot read it: {exc}") from exc
    lines = [(n, line) for n, line in enumerate(text.splitlines(), 1) if line.strip()]
    if not lines:
        raise BaselineError(f"{path}, line 1: empty: a baseline starts with its header "
                            f"(make one with crosscheck baseline)")
    header = _parsed(path, *lines[0])
    problem = _header_problem(header)
    if problem:
        raise BaselineError(f"{path}, line {lines[0][0]}: {problem}")
    entries: dict[Key, Entry] = {}
    first: dict[Key, int] = {}
    for n, line in lines[1:]:
        entry = _entry(path, n, _parsed(path, n, line))
        if entry.key in entries:
            raise BaselineError(f"{path}, line {n}: duplicate entry for case {entry.case!r} on "
                                f"{entry.engine!r}, quantity {entry.quantity!r} (first on "
                                f"line {first[entry.key]})")
        entries[entry.key], first[entry.key] = entry, n
    return Baseline(entries, float(header["margin"]), float(header["stale_factor"]),
                    header["source"])


def _parsed(path: Path, n: int, line: str) -> dict[str, Any]:
    def refuse(token: str) -> None:
        raise ValueError(f"{token} is not JSON (write an infinite error as \"inf\")")

    try:
        value = json.loads(line, parse_constant=refuse)
    except ValueError as exc:  # json.JSONDecodeError too
        raise BaselineError(f"{path}, line {n}: not a JSON line: {exc}") from None
    if not isinstance(value, dict):
        raise BaselineError(f"{path}, line {n}: not a JSON object")
    return value


def _fields_problem(data: dict[str, Any], names: Iterable[str]) -> str | None:
    names = tuple(names)
    missing = [name for name in names if name not in data]
    unknown = [name for name in data if name not in names]
    if missing:
        return f"missing field {', '.join(missing)}"
    return f"unknown field {', '.join(unknown)}" if unknown else None


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _header_problem(header: dict[str, Any]) -> str | None:
    if header.get("kind") != KIND:
        return f"not a baseline header (its kind must be {KIND!r}): make one with " \
               "crosscheck baseline"
    if header.get("format") != FORMAT or isinstance(header.get("format"), bool):
        return f"unknown format {header.get('format')!r} (this crosscheck reads format {FORMAT})"
    problem = _fields_problem(header, HEADER_FIELDS)
    if problem:
        return problem
    if not isinstance(header["source"], str):
        return "source must be a string"
    if not (_number(header["margin"]) and _number(header["stale_factor"])):
        return "margin and stale_factor must be numbers"
    return settings_problem(float(header["margin"]), float(header["stale_factor"]))


def _entry(path: Path, n: int, data: dict[str, Any]) -> Entry:
    problem = _fields_problem(data, ENTRY_FIELDS)
    strings = ("engine", "case", "quantity", "status", "category")
    if not problem and not all(isinstance(data[name], str) for name in strings):
        problem = f"{', '.join(strings)} must be strings"
    elif not problem and not all(data[name] for name in ("engine", "case", "quantity")):
        problem = "engine, case and quantity must not be empty"
    elif not problem and data["status"] not in {str(s) for s in Status}:
        problem = (f"unknown status {data['status']!r} (one of "
                   f"{', '.join(str(s) for s in Status)})")
    error = data.get("error")
    if not problem and not (_number(error) or error is None or error in ("inf", "-inf")):
        problem = f"error must be a number, null or \"inf\", not {error!r}"
    if problem:
        raise BaselineError(f"{path}, line {n}: {problem}")
    return Entry(data["case"], data["engine"], data["quantity"], data["status"],
                 data["category"], math.nan if error is None else float(error))
