"""The JSON text of a quantity's value, as the ``value`` and ``truth`` columns hold it.

Results format 4 writes strict JSON (RFC 8259), which any JSON reader accepts:

- ``null`` where there is no value: the engine gives no such quantity (the
  row's status is ``skip``, ``crash`` or ``timeout``), or the value is
  undefined (status ``undefined``, the reason says why);
- ``true`` / ``false`` for a hit verdict;
- a number, or a list of numbers, written so that it reads back to the same
  double (Python's shortest round-trip ``repr``);
- a number that is not finite as the JSON *string* ``"NaN"``, ``"Infinity"``
  or ``"-Infinity"``: strict JSON has no such numbers, and the row must still
  show that the engine returned one.  Python's ``float()`` reads all three.

Formats 1 to 3 wrote ``""`` (no value), the bare token ``undefined`` and bare
``NaN`` / ``Infinity``; :func:`upgrade` turns such a text into format 4 and
:func:`decode` reads both.

>>> encode((0.1, -0.0, float("nan"))), encode(True), encode(None), encode(float("-inf"))
('[0.1, -0.0, "NaN"]', 'true', 'null', '"-Infinity"')
>>> decode('[0.1, -0.0, "NaN"]')[2] != decode('[0.1, -0.0, "NaN"]')[2]
True
>>> upgrade("undefined"), upgrade(""), upgrade("[1.0, NaN]"), upgrade("0.25")
('null', 'null', '[1.0, "NaN"]', '0.25')
"""

from __future__ import annotations

import json
import math
from typing import Any

from crosscheck.core.model import Undefined, Value

NON_FINITE = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}
"""The JSON strings that stand for a number that is not finite, and their floats."""

_OLD_TOKENS = ("NaN", "Infinity")


def encode(value: Value | None) -> str:
    """Strict JSON text of a value (floats round-trip exactly); ``null`` when there is none."""
    if value is None or isinstance(value, Undefined):
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return _number(value)
    return _array(value)


def _array(value: tuple[Any, ...]) -> str:
    """A vector, or a tuple of vectors (a scene's bodies), as a JSON list of lists."""
    return "[" + ", ".join(_number(x) if isinstance(x, float) else _array(x)
                           for x in value) + "]"


def _number(x: float) -> str:
    """A float's text, without ``json.dumps``' per-call overhead (this runs per record)."""
    if math.isfinite(x):
        return float.__repr__(x)
    return '"NaN"' if x != x else ('"Infinity"' if x > 0 else '"-Infinity"')


def decode(text: object) -> Any:
    """The value of a ``value``/``truth`` text of any format: None, a bool, a float or a list.

    >>> decode("null") is None, decode("undefined") is None, decode("") is None
    (True, True, True)
    >>> decode('"Infinity"'), decode("[1.0, Infinity]")
    (inf, [1.0, inf])
    """
    if not isinstance(text, str) or text in ("", "undefined"):
        return None
    return _numbers(json.loads(text))


def _numbers(value: Any) -> Any:
    if isinstance(value, str):
        return NON_FINITE.get(value, value)
    if isinstance(value, list):
        return [_numbers(x) for x in value]
    if isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value


def upgrade(text: object) -> str:
    """A ``value``/``truth`` text of format 1 to 3 as format 4 writes it (format 4: unchanged)."""
    if not isinstance(text, str) or text in ("", "undefined"):
        return "null"
    if not any(token in text for token in _OLD_TOKENS) or '"' in text:
        return text
    return text_of(decode(text))


def text_of(value: Any) -> str:
    """:func:`encode` of a value as :func:`decode` gives it (lists for vectors).

    >>> text_of([-0.6, float("nan")]), text_of(None)
    ('[-0.6, "NaN"]', 'null')
    """
    return encode(_tupled(value))


def _tupled(value: Any) -> Any:
    return tuple(_tupled(x) for x in value) if isinstance(value, list) else value
