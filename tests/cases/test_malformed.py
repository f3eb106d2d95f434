"""Hundreds of malformed case files: each gives errors naming file, case and field; none crashes.

Hypothesis starts from a valid case of each kind and breaks it in one of many
ways (each guaranteed invalid): broken TOML, wrong types, missing fields,
vectors of the wrong length, NaN and inf (also as strings), huge numbers,
unknown keys, bad ids (unicode, upper case, spaces), unknown kinds and
dimensions, and duplicate ids across files.
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from crosscheck.cases.load import load_paths
from crosscheck.cases.writer import literal as inline

BASES: dict[str, dict[str, Any]] = {
    "aabb": {"a": {"center": [0.0, 0.0, 0.0], "half": [0.5, 0.5, 0.5]},
             "b": {"center": [1.0, 0.0, 0.0], "half": [0.5, 0.5, 0.5]}},
    "sphere": {"a": {"center": [0.0, 0.0, 0.0], "radius": 0.5},
               "b": {"center": [1.0, 0.0, 0.0], "radius": 0.5}},
    "sphere_response": {
        "a": {"center": [0.0, 0.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0, 0.0]},
        "b": {"center": [1.0, 0.0, 0.0], "radius": 0.5, "mass": 1.0,
              "velocity": [-1.0, 0.0, 0.0]}},
}
NUMBER_PATHS = {"aabb": ["half"], "sphere": ["radius"], "sphere_response": ["radius", "mass"]}
BAD_VALUES = ['"0.5"', "true", "[0.5]", "{ x = 1 }", '"nan"', '"inf"', "nan", "inf", "-inf",
              "1e400", "-1e400", "1" + "0" * 400, '""']
BAD_IDS = ['"Upper"', '"with space"', '"ümlaut"', '"日本"', '"-leading"', '""', "7", '"a/b"']


def render(fields: dict[str, str]) -> str:
    return "[[case]]\n" + "".join(f"{k} = {v}\n" for k, v in fields.items())


def valid_fields(kind: str, case_id: str = "ok-1") -> dict[str, str]:
    base = BASES[kind]
    return {"id": f'"{case_id}"', "description": '"a case"', "kind": f'"{kind}"', "dim": "3",
            "a": inline(base["a"]), "b": inline(base["b"])}


@st.composite
def broken(draw: st.DrawFn) -> tuple[str, str]:
    """A case file text that is invalid in one drawn way, and the way."""
    kind = draw(st.sampled_from(sorted(BASES)))
    fields, body = valid_fields(kind), dict(BASES[kind]["a"])
    way = draw(st.sampled_from(["missing", "type", "length", "unknown", "id", "kind", "dim",
                                "negative", "syntax", "body-unknown"]))
    if way == "missing":
        del fields[draw(st.sampled_from(sorted(fields)))]
    elif way == "type":
        key = draw(st.sampled_from(["center", *NUMBER_PATHS[kind]]))
        fields["a"] = inline(body).replace(f"{key} = {_lit(body[key])}",
                                           f"{key} = {draw(st.sampled_from(BAD_VALUES))}")
    elif way == "length":
        n = draw(st.sampled_from([0, 1, 2, 4, 7]))
        fields["b"] = inline(dict(BASES[kind]["b"], center=[1.0] * n))
    elif way == "unknown":
        extra = draw(st.sampled_from(["colour", "Kind", "radius", "half", "mass", "velocity"]))
        fields[extra] = "1"
    elif way == "body-unknown":
        fields["a"] = inline(body)[:-2] + ", spin = 2.0 }"
    elif way == "id":
        fields["id"] = draw(st.sampled_from(BAD_IDS))
    elif way == "kind":
        fields["kind"] = draw(st.sampled_from(['"box"', '"AABB"', '"capsule"', '""', "3"]))
    elif way == "dim":
        fields["dim"] = draw(st.sampled_from(["1", "4", "0", "-3", '"3"', "3.0", "true"]))
    elif way == "negative":
        key = draw(st.sampled_from(NUMBER_PATHS[kind]))
        value = body[key]
        body[key] = [-1.0 for _ in value] if isinstance(value, list) else -draw(
            st.floats(min_value=1e-300, max_value=1e300))
        fields["a"] = inline(body)
    text = render(fields)
    if way == "syntax":
        cut = draw(st.integers(min_value=1, max_value=len(fields["b"]) - 2))
        text = render({k: v for k, v in fields.items() if k != "b"}) + "b = " + fields["b"][:cut]
    return text, way


def _lit(value: Any) -> str:
    return inline({"x": value})[6:-2]


def load_text(text: str, files: int = 1) -> tuple[list[str], list[Any], list[Path]]:
    folder = Path(tempfile.mkdtemp())
    paths = []
    for i in range(files):
        paths.append(folder / f"f{i}.toml")
        paths[-1].write_text(text, encoding="utf-8")
    result = load_paths(paths)
    return [e.message for e in result.errors], result.errors, paths


@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(broken())
def test_every_malformed_case_is_rejected_with_file_case_and_field(drawn: tuple[str, str]) -> None:
    text, way = drawn
    messages, errors, (path,) = load_text(text)
    assert errors, f"silently accepted ({way}):\n{text}"
    for message, error in zip(messages, errors, strict=True):
        assert re.match(rf"{re.escape(str(path))}(:\d+)?: ", message), message
        if way == "syntax":
            assert "TOML syntax error" in message
        else:
            assert error.case_id and error.field and error.reason, message


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(sorted(BASES)), st.from_regex(r"[a-z0-9][a-z0-9.\-]{0,20}", fullmatch=True))
def test_duplicate_ids_across_files_are_rejected(kind: str, case_id: str) -> None:
    messages, errors, paths = load_text(render(valid_fields(kind, case_id)), files=2)
    assert [e.field for e in errors] == ["id"]
    assert messages[0].startswith(f"{paths[1]}: case {case_id!r}: field id: duplicate id")
    assert str(paths[0]) in messages[0]
