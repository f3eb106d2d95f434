"""The one TOML writer: ``[[case]]`` blocks that load back into the very same cases.

New cases (:mod:`crosscheck.cases.newcase`) and fuzz findings
(:mod:`crosscheck.studies.fuzz.findings`) are both written through it.

Floats are written with ``repr`` (through tomli_w), the shortest text that
parses back to the same binary double, so a written case round-trips exactly.
Bodies are inline tables, as in the hand-written files under ``cases/``.

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> case = CASE_ADAPTER.validate_python({
...     "id": "s", "description": 'say "hi"', "kind": "sphere", "dim": 2,
...     "a": {"center": [0.1, 0.2], "radius": 0.5}, "b": {"center": [1.0, 0.0], "radius": 0.5}})
>>> print(case_block(case))
[[case]]
id = "s"
description = "say \\"hi\\""
kind = "sphere"
dim = 2
tags = []
a = { center = [0.1, 0.2], radius = 0.5 }
b = { center = [1.0, 0.0], radius = 0.5 }
<BLANKLINE>
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import tomli_w

from crosscheck.core.schema import LOADER_FIELDS, AnyCase

KEY_ORDER = ("id", "description", "kind", "dim", "tags", "tolerance", "a", "b", "expect",
             "restitution")
"""The order of keys in a written block (the order of the shipped case files)."""

SCHEMA_LINE = "#:schema ./schema.json"


def literal(value: Any) -> str:
    """A TOML literal on one line: tables inline, arrays flat, scalars as tomli_w writes them.

    >>> literal({"center": (0.30000000000000004, -0.0), "radius": 1e-300})
    '{ center = [0.30000000000000004, -0.0], radius = 1e-300 }'
    """
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{key} = {literal(v)}" for key, v in value.items()) + " }"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(literal(v) for v in value) + "]"
    return tomli_w.dumps({"v": value})[len("v = "):].rstrip("\n")


def case_block(case: AnyCase, **overrides: Any) -> str:
    """One ``[[case]]`` block for ``case``, with some fields replaced (e.g. ``description``).

    Fields outside :data:`KEY_ORDER` are written only when they differ from their default.
    """
    data = case.model_dump(exclude_none=True, exclude=set(LOADER_FIELDS)) | overrides
    fields = type(case).model_fields
    extra = [key for key in data if key not in KEY_ORDER  # newer optional fields, if set
             and data[key] != fields[key].get_default(call_default_factory=True)]
    keys = [key for key in KEY_ORDER if key in data] + extra
    lines = ["[[case]]", *(f"{key} = {literal(data[key])}" for key in keys)]
    return "\n".join(lines) + "\n"


def case_file(blocks: Sequence[str], header: str = "") -> str:
    """A whole case file: the schema line, a comment header, then the blocks."""
    head = [SCHEMA_LINE, *(f"# {line}".rstrip() for line in header.splitlines())]
    return "\n".join(head) + "\n\n" + "\n".join(blocks)
