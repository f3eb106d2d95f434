"""The case loader: every validation rule, and error messages naming file, case, field, reason."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.core.model import Kind
from crosscheck.core.schema import json_schema_text
from tests.conftest import ROOT

GOOD_SPHERE = """
[[case]]
id = "{id}"
description = "two spheres"
kind = "sphere"
dim = 3
tags = [{tags}]
a = {{ center = [0.0, 0.0, 0.0], radius = {ra} }}
b = {{ center = [{bx}, 0.0, 0.0], radius = 0.5 }}
"""

GOOD_RESPONSE = """
[[case]]
id = "resp"
description = "head-on"
kind = "sphere_response"
dim = 2
tags = [{tags}]
restitution = {e}
a = {{ center = [0.0, 0.0], radius = 0.5, mass = {ma}, velocity = [1.0, 0.0] }}
b = {{ center = [1.0, 0.0], radius = 0.5, mass = 1.0, velocity = [{vb}, 0.0] }}
"""

Write = Callable[..., Path]


def sphere_text(id: str = "s1", tags: str = "", ra: str = "0.5", bx: str = "1.0") -> str:
    return GOOD_SPHERE.format(id=id, tags=tags, ra=ra, bx=bx)


def response_text(tags: str = "", e: str = "1.0", ma: str = "1.0", vb: str = "-1.0") -> str:
    return GOOD_RESPONSE.format(tags=tags, e=e, ma=ma, vb=vb)


def only_error(path: Path) -> str:
    result = load_paths([path])
    assert result.cases == []
    assert len(result.errors) == 1, result.errors
    message = result.errors[0].message
    assert message.startswith(str(path)), message
    return message


def test_shipped_suite_is_valid() -> None:
    result = load_paths([ROOT / "cases"])
    assert result.errors == []
    assert result.blocks >= 150


def test_shipped_suite_covers_every_kind_and_dim() -> None:
    covered = {(c.kind, c.dim) for c in load_paths([ROOT / "cases"]).cases}
    assert covered == {(str(k), d) for k in Kind for d in (2, 3)}


def test_good_case_loads(write_toml: Write) -> None:
    result = load_paths([write_toml(sphere_text())])
    assert result.errors == []
    assert result.cases[0].id == "s1"
    assert result.cases[0].source.endswith("cases.toml")


@pytest.mark.parametrize(("ra", "field", "reason"), [
    ("nan", "a.radius", "must be finite"),
    ("inf", "a.radius", "must be finite"),
    ("-0.5", "a.radius", "must be >= 0"),
    ('"0.5"', "a.radius", "must be a number, got '0.5'"),
    ("true", "a.radius", "must be a number, got True"),
])
def test_bad_radius(write_toml: Write, ra: str, field: str, reason: str) -> None:
    message = only_error(write_toml(sphere_text(ra=ra)))
    assert "case 's1'" in message
    assert f"field {field}:" in message
    assert reason in message


def test_non_finite_centre(write_toml: Write) -> None:
    message = only_error(write_toml(sphere_text(bx="-inf")))
    assert "field b.center[0]: must be finite" in message


@pytest.mark.parametrize(("ma", "reason"), [("0.0", "must be > 0"), ("-1.0", "must be > 0"),
                                            ("nan", "must be finite")])
def test_bad_mass(write_toml: Write, ma: str, reason: str) -> None:
    message = only_error(write_toml(response_text(ma=ma)))
    assert "case 'resp'" in message and "field a.mass:" in message and reason in message


def test_restitution_out_of_range(write_toml: Write) -> None:
    message = only_error(write_toml(response_text(e="1.5")))
    assert "field restitution: must be in [0, 1]" in message


@pytest.mark.parametrize("text", [
    sphere_text(ra="nan"), sphere_text(ra="-1.0"), sphere_text(bx="inf"),
    response_text(ma="0.0"), response_text(ma="-1.0"), response_text(e="2.0"),
])
def test_bad_input_tag_waives_value_rules(write_toml: Write, text: str) -> None:
    tagged = text.replace("tags = []", 'tags = ["bad-input"]')
    result = load_paths([write_toml(tagged)])
    assert result.errors == []
    assert result.blocks == 1


def test_bad_input_tag_does_not_waive_vector_length(write_toml: Write) -> None:
    text = sphere_text(tags='"bad-input"').replace("[1.0, 0.0, 0.0]", "[1.0, 0.0]")
    message = only_error(write_toml(text))
    assert "field b.center: expected 3 components for dim = 3, got 2" in message


def test_wrong_vector_length(write_toml: Write) -> None:
    text = response_text().replace("velocity = [1.0, 0.0]", "velocity = [1.0, 0.0, 0.0]")
    assert "field a.velocity: expected 2 components" in only_error(write_toml(text))


def test_unknown_kind(write_toml: Write) -> None:
    message = only_error(write_toml(sphere_text().replace('"sphere"', '"capsule"')))
    assert "field kind:" in message and "capsule" in message


def test_missing_field(write_toml: Write) -> None:
    text = "\n".join(line for line in sphere_text().splitlines() if not line.startswith("b ="))
    message = only_error(write_toml(text))
    assert "field b: missing: this field is required" in message


def test_unknown_key(write_toml: Write) -> None:
    message = only_error(write_toml(sphere_text() + 'colour = "red"\n'))
    assert "field colour: unknown key 'colour'" in message


def test_unknown_body_key(write_toml: Write) -> None:
    text = sphere_text().replace("radius = 0.5 }", "radius = 0.5, r = 1 }", 1)
    assert "field a.r: unknown key 'r'" in only_error(write_toml(text))


def test_wrong_dim(write_toml: Write) -> None:
    assert "field dim:" in only_error(write_toml(sphere_text().replace("dim = 3", "dim = 4")))


def test_bad_id(write_toml: Write) -> None:
    message = only_error(write_toml(sphere_text(id="Has Space")))
    assert "case 'Has Space'" in message and "field id:" in message


def test_broken_toml(write_toml: Write) -> None:
    message = only_error(write_toml(sphere_text() + "[[case]\n"))
    assert "TOML syntax error" in message


def test_file_without_cases(write_toml: Write) -> None:
    path = write_toml("title = 'x'\n")
    messages = [e.message for e in load_paths([path]).errors]
    assert messages == [f"{path}: field title: unknown top-level key (expected only [[case]] "
                        "and [[cover]])",
                        f"{path}: field case: no [[case]] or [[cover]] blocks in file"]


def test_duplicate_ids_across_files(write_toml: Write) -> None:
    first = write_toml(sphere_text(), "a.toml")
    second = write_toml(sphere_text(), "b.toml")
    result = load_paths([first, second])
    assert result.blocks == 2 and len(result.cases) == 2  # the first and its swapped twin
    (error,) = result.errors
    assert error.file == str(second) and error.field == "id"
    assert f"first defined in {first}" in error.reason


def test_one_bad_block_does_not_stop_the_others(write_toml: Write) -> None:
    result = load_paths([write_toml(sphere_text("good") + sphere_text("bad", ra="-1.0"))])
    assert [c.id for c in result.cases] == ["good", "good.swapped"]
    assert len(result.errors) == 1 and result.errors[0].case_id == "'bad'"


def test_expect_must_agree_with_oracle(write_toml: Write) -> None:
    touching = sphere_text() + "expect = { hit = true }\n"
    message = only_error(write_toml(touching))
    assert "field expect.hit: pinned True but the exact oracle says False" in message
    right = sphere_text() + "expect = { hit = false, distance = 0.0 }\n"
    assert load_paths([write_toml(right, "ok.toml")]).errors == []


def test_published_schema_is_current() -> None:
    assert (ROOT / "cases" / "schema.json").read_text() == json_schema_text()


def test_negative_half_width(write_toml: Write) -> None:
    text = """
[[case]]
id = "box"
description = "negative half-width"
kind = "aabb"
dim = 2
a = { center = [0.0, 0.0], half = [1.0, -0.25] }
b = { center = [1.0, 0.0], half = [1.0, 1.0] }
"""
    message = only_error(write_toml(text))
    assert "case 'box': field a.half[1]: must be >= 0, got -0.25" in message
    tagged = text.replace('kind = "aabb"', 'kind = "aabb"\ntags = ["bad-input"]')
    assert load_paths([write_toml(tagged, "tagged.toml")]).errors == []


def test_messages_give_the_line_and_a_did_you_mean(write_toml: Write) -> None:
    text = sphere_text().replace("radius = 0.5 }", "radiu = 0.5 }", 1)
    result = load_paths([write_toml(text)])
    message = next(e.message for e in result.errors if e.field == "a.radiu")  # and a.radius
    line = next(i for i, row in enumerate(text.splitlines(), 1) if "radiu =" in row)
    assert f".toml:{line}: case 's1': field a" in message
    assert "did you mean 'radius'?" in message
    wrong_kind = only_error(write_toml(sphere_text().replace('kind = "sphere"', 'kind = "spere"')))
    assert "kind must be one of aabb, sphere, sphere_response, sphere_scene, sphere_toi, " \
           "not 'spere' " \
           "(did you mean 'sphere'?)" in wrong_kind


def test_a_value_outside_a_list_of_choices_names_the_choices(write_toml: Write) -> None:
    text = sphere_text().replace('dim = 3', 'dim = 3\ntwin_2d = "xyz"')
    message = only_error(write_toml(text))
    assert "field twin_2d: must be 'xy', 'xz' or 'yz' (got 'xyz')" in message
