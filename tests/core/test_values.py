"""The value/truth columns are strict JSON (format 4), and older texts upgrade to it."""

from __future__ import annotations

import json
import math

import pytest

from crosscheck.core.model import Undefined
from crosscheck.core.values import decode, encode, upgrade


def strict(text: str) -> object:
    """Parse as strict JSON: any NaN/Infinity/undefined token raises."""
    def refuse(token: str) -> float:
        raise ValueError(f"not strict JSON: {token}")
    return json.loads(text, parse_constant=refuse)


VALUES = [True, False, 0.1 + 0.2, -0.0, 1e300, 5e-324, math.nan, math.inf, -math.inf,
          (0.6, 0.8), (math.nan, 1.0, -math.inf), ((1.0, 2.0, 3.0), (math.inf, 0.0, -1.5)),
          None, Undefined("coincident centres")]


@pytest.mark.parametrize("value", VALUES, ids=repr)
def test_every_value_is_strict_json_and_reads_back_exactly(value: object) -> None:
    text = encode(value)  # type: ignore[arg-type]
    strict(text)
    back = decode(text)
    if value is None or isinstance(value, Undefined):
        assert text == "null" and back is None
        return
    assert _same(back, value)


def _same(got: object, want: object) -> bool:
    if isinstance(want, tuple):
        return isinstance(got, list) and len(got) == len(want) and all(
            _same(g, w) for g, w in zip(got, want, strict=True))
    if isinstance(want, float):
        return isinstance(got, float) and ((got == want and math.copysign(1, got) ==
                                           math.copysign(1, want)) or (got != got and want != want))
    return got == want


@pytest.mark.parametrize(("old", "new"), [
    ("", "null"), ("undefined", "null"), ("NaN", '"NaN"'), ("-Infinity", '"-Infinity"'),
    ("[0.5, NaN, Infinity]", '[0.5, "NaN", "Infinity"]'),
    ("[[1.0, NaN], [2.0, 3.0]]", '[[1.0, "NaN"], [2.0, 3.0]]'),
    ("true", "true"), ("0.1", "0.1"), ('[1.0, "NaN"]', '[1.0, "NaN"]')])
def test_older_formats_upgrade_to_strict_json(old: str, new: str) -> None:
    assert upgrade(old) == new
    strict(upgrade(old))
    assert upgrade(upgrade(old)) == upgrade(old)
