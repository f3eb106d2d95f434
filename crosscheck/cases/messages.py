"""Validation messages in plain words: what pydantic found, said as a case author reads it.

Each problem names the field and says what is wrong without pydantic's
vocabulary; an unknown key or kind gets a "did you mean" from the names the
schema knows.

>>> plain({"type": "extra_forbidden", "loc": ("a", "radiu"), "msg": "", "input": 0.5})
("unknown key 'radiu' (did you mean 'radius'?)", 'a.radiu')
>>> plain({"type": "float_type", "loc": ("b", "radius"), "msg": "", "input": True})
('must be a number, got True', 'b.radius')
"""

from __future__ import annotations

import difflib
from typing import Any

from pydantic import BaseModel

from crosscheck.core import schema
from crosscheck.core.model import Kind

KINDS = tuple(kind.value for kind in Kind)


def _field_names() -> set[str]:
    models: list[type[BaseModel]] = [
        schema.AabbCase, schema.SphereCase, schema.ResponseCase, schema.SceneCase,
        schema.ToiCase, schema.AabbBody, schema.SphereBody, schema.MovingSphere,
        schema.SweptSphere, schema.Tolerance, schema.Expect,
        schema.Sweep, schema.Steps, schema.SceneGenerator]
    return {name for model in models for name in model.model_fields} - set(schema.LOADER_FIELDS)


KNOWN = frozenset(_field_names())


def did_you_mean(word: str, choices: frozenset[str] | tuple[str, ...]) -> str:
    """`` (did you mean 'x'?)`` for the closest known name, or nothing."""
    close = difflib.get_close_matches(word, sorted(choices), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


_WORDS = {
    "missing": "missing: this field is required",
    "float_type": "must be a number", "int_type": "must be a whole number",
    "bool_type": "must be true or false", "string_type": "must be text",
    "tuple_type": "must be a list of numbers", "list_type": "must be a list",
    "too_short": "must not be empty", "dict_type": "must be a table { ... }",
}


def _where(loc: tuple[Any, ...]) -> str:
    parts = [p for p in loc if p not in KINDS]
    parts = [p for i, p in enumerate(parts) if i == 0 or p != parts[i - 1]]  # union tags
    return ".".join(str(p) for p in parts)


def plain(err: dict[str, Any]) -> tuple[str, str]:
    """``(reason, field)`` of one pydantic error, in plain words."""
    kind, got, where = err["type"], err.get("input"), _where(tuple(err["loc"]))
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        tag = got.get("kind") if isinstance(got, dict) else None
        shown = f", not {tag!r}{did_you_mean(str(tag), KINDS)}" if tag is not None else ""
        return f"kind must be one of {', '.join(KINDS)}{shown}", "kind"
    if kind == "extra_forbidden":
        name = str(err["loc"][-1])
        return f"unknown key '{name}'{did_you_mean(name, KNOWN)}", where
    if kind == "string_pattern_mismatch":
        return (f"must be lowercase letters, digits and . _ , = + - (starting with a letter "
                f"or digit), got {got!r}"), where
    if kind in _WORDS:
        shown = "" if kind == "missing" or isinstance(got, dict) else f", got {got!r}"
        return _WORDS[kind] + shown, where
    message = str(err["msg"]).removeprefix("Value error, ").removeprefix("Input should be ")
    message = f"must be {message}" if kind == "literal_error" else message
    shown = "" if isinstance(got, dict) or repr(got) in message else f" (got {got!r})"
    return f"{message}{shown}", where
