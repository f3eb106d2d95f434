"""Loaders for results written before format 2, which had no ``origin``, ``coords`` or ``twin_of``.

Format 1 kept a case's sweep coordinates and its swapped-twin link only in
its id (``<block>.<param>=<value>[,...]`` and ``<id>.swapped``).  Reading
such a run back, :func:`links` recovers the three fields from the id, once,
here; nothing after this loader parses an id.

>>> links("sweep-x.gap=1e-09.swapped")
('sweep-x', {'gap': 1e-09}, 'sweep-x.gap=1e-09')
>>> links("scene.dt=0.001,iterations=4")
('scene', {'dt': 0.001, 'iterations': 4.0}, '')
>>> links("plain-case")
('', {}, '')
"""

from __future__ import annotations

import json
import re
from typing import Any

from crosscheck.cases.expand import PARAMETERS

_NAMES = "|".join((*PARAMETERS, "dt", "iterations"))
_POINT = re.compile(rf"^(?P<origin>.+)\.(?P<labels>(?:{_NAMES})=[^,=]+(?:,(?:{_NAMES})=[^,=]+)*)$")
SWAPPED = ".swapped"


def links(case_id: str) -> tuple[str, dict[str, float], str]:
    """``(origin, coords, twin_of)`` of a format-1 case id."""
    twin_of = case_id.removesuffix(SWAPPED) if case_id.endswith(SWAPPED) else ""
    match = _POINT.match(twin_of or case_id)
    if match is None:
        return "", {}, twin_of
    coords = {}
    for label in match["labels"].split(","):
        name, _, value = label.partition("=")
        coords[name] = float(value)
    return match["origin"], coords, twin_of


def case_fields(case: dict[str, Any]) -> dict[str, Any]:
    """A format-1 stored case with ``origin``, ``coords`` and ``twin_of`` filled in."""
    if "origin" in case:
        return case
    origin, coords, twin_of = links(str(case["id"]))
    return case | {"origin": origin, "coords": coords, "twin_of": twin_of}


def record_fields(row: dict[str, Any]) -> dict[str, Any]:
    """A format-1 results row with ``origin``, ``coords`` (JSON text) and ``twin_of`` filled in."""
    if "origin" in row:
        return row
    origin, coords, twin_of = links(str(row["case_id"]))
    return row | {"origin": origin, "coords": json.dumps(coords) if coords else "",
                  "twin_of": twin_of}
