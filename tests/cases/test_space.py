"""The configuration space: placing cases in cells, and building a case for every cell."""

from __future__ import annotations

import random
from typing import Any

import pytest

from crosscheck.cases.realize import DEFAULTS, realize
from crosscheck.cases.space import SPACES, classify, gap_level, relative_gap, space_of
from crosscheck.core.model import Kind
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from tests.conftest import ROOT


def case(**fields: Any) -> AnyCase:
    return CASE_ADAPTER.validate_python({"id": "c", "description": "d", **fields})


def boxes(a: list[float], b: list[float], ha: list[float] | None = None,
          hb: list[float] | None = None) -> AnyCase:
    one = [1.0] * len(a)
    return case(kind="aabb", dim=len(a), a={"center": a, "half": ha or one},
                b={"center": b, "half": hb or one})


def spheres(a: list[float], b: list[float], ra: float = 0.5, rb: float = 0.5) -> AnyCase:
    return case(kind="sphere", dim=len(a), a={"center": a, "radius": ra},
                b={"center": b, "radius": rb})


def test_plain_separated_boxes_on_y_are_placed_by_their_geometry() -> None:
    cell = classify(boxes([0, 0, 0], [0, 22, 0]))  # gap 20 on touching 2: relative gap 10
    assert cell == {"direction": "+y", "gap": "+10", "size_ratio": "1", "aspect": "1",
                    "scale": "1", "offset": "0"}


@pytest.mark.parametrize(("b", "direction"), [
    ([0, 0, -3], "-z"), ([2, 2, 0], "diag-2"), ([-2, 2, 2], "diag-3"), ([2, 3, 6], "oblique"),
    ([1, 2, 0], "oblique")])
def test_direction_levels(b: list[float], direction: str) -> None:
    assert classify(spheres([0, 0, 0], b))["direction"] == direction


def test_coincident_centres_have_no_direction() -> None:
    assert "direction" not in classify(spheres([1, 1], [1, 1]))


@pytest.mark.parametrize(("g", "level"), [
    (0.0, "0"), (2.0 ** -52, "+ulp"), (-(2.0 ** -52), "-ulp"), (1e-13, "+1e-12"),
    (-0.29, "-1e-1"), (-0.3, "deep"), (-1.0, "deep"), (2.0, "+1"), (4.0, "+10"), (4.0e2, "+1e3"),
    (1e9, "+1e3")])
def test_gap_levels(g: float, level: str) -> None:
    assert gap_level(g, space_of(Kind.AABB, 3).dimension("gap").levels) == level  # type: ignore[union-attr]


def test_relative_gap_is_exact_for_boxes_and_touching_counts_as_zero() -> None:
    assert relative_gap(boxes([0, 0], [2, 1.5])) == 0.0  # touching on x, overlapping on y
    assert relative_gap(boxes([0, 0], [0, 2 + 2 ** -51])) == 2.0 ** -52
    assert classify(spheres([0, 0], [3, 4], 2.5, 2.5))["gap"] == "0"  # a 3-4-5 contact


def test_size_aspect_scale_and_offset() -> None:
    cell = classify(boxes([1e12, 0, 1e12], [1e12 + 3, 0, 1e12], [1e-4, 1e-4, 1.0],
                          [1e-4, 1e-4, 1e-4]))
    assert (cell["size_ratio"], cell["aspect"], cell["scale"]) == ("1e3", "1e4", "1")
    assert (cell["offset"], cell["offset_axis"]) == ("1e12", "many")


def test_response_angle_and_toi_duration() -> None:
    head_on = case(kind="sphere_response", dim=2, restitution=0.5,
                   a={"center": [0, 0], "radius": 0.5, "mass": 1.0, "velocity": [1, 0]},
                   b={"center": [1, 0], "radius": 0.5, "mass": 1e6, "velocity": [0, 0]})
    assert {k: classify(head_on)[k] for k in ("angle", "mass_ratio", "restitution")} == {
        "angle": "0", "mass_ratio": "1e6", "restitution": "0.5"}
    sixty = head_on.model_copy(update={"a": head_on.a.model_copy(update={  # type: ignore[union-attr]
        "velocity": (0.5, 0.8660254037844386)})})
    assert classify(sixty)["angle"] == "60"
    toi = case(kind="sphere_toi", dim=2, duration=1000.0,
               a={"center": [0, 0], "radius": 0.5, "velocity": [1e-3, 0]},
               b={"center": [3, 0], "radius": 0.5, "velocity": [0, 0]})
    assert {k: classify(toi)[k] for k in ("duration", "speed", "gap")} == {
        "duration": "1e3", "speed": "1e-3", "gap": "+1"}


def test_scenes_and_non_finite_cases_have_no_cell() -> None:
    scene = case(kind="sphere_scene", dim=2, duration=1.0, bodies=[
        {"center": [0, 0], "radius": 0.5, "mass": 1.0, "velocity": [1, 0]},
        {"center": [2, 0], "radius": 0.5, "mass": 1.0, "velocity": [0, 0]}])
    assert classify(scene) == {}
    assert classify(spheres([0, 0], [float("nan"), 0])) == {}


def one_level_cells() -> list[tuple[Kind, int, str, str]]:
    """Every level of every dimension of every space, the others at their defaults."""
    return [(space.kind, space.dim, d.name, level) for space in SPACES.values()
            for d in space.dimensions for level in d.levels]


UNREACHABLE = {("direction", "diag-2"), ("direction", "diag-3")}
"""Spheres touch exactly on no diagonal of irrational length (the default gap is 0)."""


@pytest.mark.parametrize(("kind", "dim", "name", "level"), one_level_cells())
def test_every_level_is_realised_where_it_asks(kind: Kind, dim: int, name: str,
                                               level: str) -> None:
    space = SPACES[kind, dim]
    cell = {name: level} | ({"offset": "1"} if name == "offset_axis" else {})
    made = case(**realize(space, cell, random.Random(7)))
    got = classify(made)
    if kind is Kind.SPHERE and (name, level) in UNREACHABLE:  # at the default gap 0
        assert got[name] == level and got["gap"] in ("-ulp", "+ulp")
        return
    want = {n: v for n, v in (DEFAULTS | cell).items() if n in space.names}
    if want.get("offset") == "0":
        want.pop("offset_axis")
    if kind is Kind.SPHERE_TOI and "gap" not in cell:
        want["gap"] = "+1"
    assert got == want


def test_jittered_levels_stay_in_their_cell() -> None:
    rng = random.Random(3)
    space = SPACES[Kind.SPHERE, 3]
    for _ in range(200):
        cell = {d.name: rng.choice(d.levels) for d in space.dimensions}
        cell |= {"offset": "0", "gap": rng.choice(["-1e-3", "+1e-6", "+1", "+1e3", "deep"])}
        del cell["offset_axis"]
        got = classify(case(**realize(space, cell, random.Random(rng.random()), jitter=True)))
        assert {k: got.get(k) for k in ("gap", "scale", "size_ratio")} == {
            k: cell[k] for k in ("gap", "scale", "size_ratio")}


def test_the_docs_page_lists_every_dimension_and_level() -> None:
    text = (ROOT / "docs" / "coverage.md").read_text(encoding="utf-8")
    for space in SPACES.values():
        for d in space.dimensions:
            row = f"| `{d.name}` |"
            assert row in text, d.name
            assert f"`{', '.join(d.levels)}`" in text, (d.name, d.levels)


def test_responses_are_always_in_contact() -> None:
    rng = random.Random(5)
    for dim in (2, 3):
        space = SPACES[Kind.SPHERE_RESPONSE, dim]
        for _ in range(150):
            cell = {d.name: rng.choice(d.levels) for d in space.dimensions}
            made = case(**realize(space, cell, random.Random(rng.random())))
            gap = relative_gap(made)
            assert gap is not None and gap <= 0, (cell, gap)
