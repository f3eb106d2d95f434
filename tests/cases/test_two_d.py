"""2-D twins: every 3-D sweep and float trap with a 2-D meaning also runs in 2-D.

A 2-D engine (pymunk, Box2D) skips every 3-D case, so a probe that exists only
in 3-D leaves it without a verdict.  These tests read the loaded suite (no list of
ids): a 3-D case "has a 2-D meaning" when :func:`plane_of` finds a coordinate plane
in which the same bodies give the same exact answer.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.cases.expand import PLANES, TWIN_TAG
from crosscheck.cases.load import load_paths, plane_of
from crosscheck.core.model import Undefined, quantities_of
from crosscheck.core.schema import TWIN_SUFFIX, AnyCase, SceneCase, SphereCase
from crosscheck.report import stability
from crosscheck.truth import oracle
from tests.conftest import ROOT

Write = Any
LOADER_TAGS = {"sweep", "swapped", "dynamics", TWIN_TAG}
"""Tags the loader adds (they say how a case was made, not what it probes)."""
TWINNED_FAMILIES = {"float_traps"}
"""Families whose every planar 3-D case needs its own twin: a float trap is its exact numbers."""


@pytest.fixture(scope="module")
def suite() -> list[AnyCase]:
    result = load_paths([ROOT / "cases"])
    assert result.errors == []
    return result.cases


def family(case: AnyCase) -> str:
    """The case's family: its file's stem, as the report groups cases."""
    return Path(case.source).stem


def originals(suite: list[AnyCase]) -> Iterator[AnyCase]:
    """The 3-D two-body cases that are not A/B-swapped twins."""
    return (c for c in suite if c.dim == 3 and not isinstance(c, SceneCase) and not c.twin_of)


def twinned(suite: list[AnyCase]) -> set[str]:
    return {c.from_3d for c in suite if c.from_3d}


def test_every_3d_sweep_with_a_2d_meaning_has_its_twin(suite: list[AnyCase]) -> None:
    points = [c for c in originals(suite) if c.coords]
    assert len({c.origin for c in points}) >= 9  # gap, overlap, scale, offset, mass, speed
    missing = sorted({c.origin for c in points if plane_of(c) and c.id not in twinned(suite)})
    assert missing == []


def test_every_float_trap_with_a_2d_meaning_has_its_twin(suite: list[AnyCase]) -> None:
    traps = [c for c in originals(suite) if family(c) in TWINNED_FAMILIES]
    assert traps
    missing = [c.id for c in traps if plane_of(c) and c.id not in twinned(suite)]
    assert missing == []


def test_every_probe_of_a_family_in_3d_is_probed_in_2d(suite: list[AnyCase]) -> None:
    """Each family x kind x tag with a planar 3-D case has a 2-D case too."""
    def probes(cases: Iterator[AnyCase]) -> set[tuple[str, str, str]]:
        return {(family(c), c.kind, tag) for c in cases for tag in set(c.tags) - LOADER_TAGS}
    in_3d = probes(c for c in originals(suite) if plane_of(c))
    in_2d = probes(c for c in suite if c.dim == 2)
    assert sorted(in_3d - in_2d) == []


def test_every_sweep_axis_of_each_kind_runs_in_2d(suite: list[AnyCase]) -> None:
    def axes(dim: int) -> set[tuple[str, str]]:
        return {(c.kind, param) for c in suite if c.dim == dim and not isinstance(c, SceneCase)
                for param in c.coords}
    assert axes(3) and axes(3) <= axes(2)


def in_plane(value: object, axis: int) -> object:
    """A 3-D answer as its 2-D twin must give it: vectors lose ``axis`` (which must be 0)."""
    if isinstance(value, tuple):
        assert value[axis] == 0, value
        return tuple(x for i, x in enumerate(value) if i != axis)
    return value


def test_twins_have_the_exact_answer_of_their_3d_case(suite: list[AnyCase]) -> None:
    by_id = {c.id: c for c in suite}
    twins = [c for c in suite if c.from_3d]
    assert len(twins) >= 150
    for twin in twins:
        original = by_id[twin.from_3d]
        assert (original.dim, twin.dim, twin.kind, twin.coords) == (3, 2, original.kind,
                                                                     original.coords)
        assert TWIN_TAG in twin.tags and original.twin_2d is not None
        if original.bad_input:
            continue
        axis = PLANES[original.twin_2d]
        want, got = oracle.truth(original), oracle.truth(twin)
        for quantity in quantities_of(original.kind_enum):
            a, b = want.get(quantity), got.get(quantity)
            if isinstance(a, Undefined) or isinstance(b, Undefined):
                assert isinstance(a, Undefined) and isinstance(b, Undefined), (twin.id, quantity)
            else:
                assert in_plane(a, axis) == b, (twin.id, quantity, a, b)


def test_twin_ids_add_2d_to_the_block_and_leave_the_3d_cases_alone(write_toml: Write) -> None:
    block = """
[[case]]
id = "g"
description = "gap sweep in the yz plane"
kind = "sphere"
dim = 3
{twin}
a = {{ center = [7.0, 0.0, 0.0], radius = 0.5 }}
b = {{ center = [7.0, 0.0, 1.0], radius = 0.5 }}
sweep = {{ gap = [0.5, 1e-3], direction = [0.0, 0.0, 2.0] }}
"""
    plain = load_paths([write_toml(block.format(twin=""), "plain.toml")]).cases
    result = load_paths([write_toml(block.format(twin='twin_2d = "yz"'))])
    assert result.errors == []
    by_id = {c.id: c for c in result.cases}
    for case in plain:  # the 3-D cases are as they were without twin_2d
        with_twin = by_id[case.id].model_dump(exclude={"twin_2d"})
        assert with_twin == case.model_dump(exclude={"twin_2d"})
    twins = [c for c in result.cases if isinstance(c, SphereCase) and c.dim == 2]
    assert [c.id for c in twins] == ["g.2d.gap=0.5", "g.2d.gap=0.5.swapped",
                                     "g.2d.gap=0.001", "g.2d.gap=0.001.swapped"]
    assert [c.from_3d for c in twins] == ["g.gap=0.5", "g.gap=0.5.swapped",
                                          "g.gap=0.001", "g.gap=0.001.swapped"]
    assert {c.origin for c in twins} == {f"g{TWIN_SUFFIX}"}
    assert twins[0].b.center == (0.0, 1.5) and twins[1].a.center == (0.0, 1.5)


BOX = """
[[case]]
id = "t"
description = "a 3-D case with a 2-D twin"
kind = "{kind}"
dim = {dim}
twin_2d = "xy"
a = {{ center = {ca}, {size_a} }}
b = {{ center = {cb}, {size_b} }}
"""


@pytest.mark.parametrize(("fields", "reason"), [
    ({"cb": "[1.0, 0.0, 0.5]"}, "b.center[2] = 0.5 differ"),
    ({"size_a": "half = [1.0, 1.0, 0.125]", "size_b": "half = [1.0, 1.0, 0.125]",
      "cb": "[1.5, 0.0, 0.0]"}, "dropping the z axis changes the exact distance"),
    ({"dim": "2", "ca": "[0.0, 0.0]", "cb": "[1.0, 0.0]", "size_a": "half = [1.0, 1.0]",
      "size_b": "half = [1.0, 1.0]"}, "a 2-D twin is made from a 3-D case"),
    ({"kind": "sphere_response", "size_a": "radius = 0.5, mass = 1.0, velocity = [1.0, 0.0, 0.0]",
      "size_b": "radius = 0.5, mass = 1.0, velocity = [0.0, 0.0, -1.0]"},
     "b.velocity[2] is -1.0, not 0"),
])
def test_a_twin_that_is_not_the_same_contact_is_an_error(write_toml: Write,
                                                         fields: dict[str, str],
                                                         reason: str) -> None:
    values = {"kind": "aabb", "dim": "3", "ca": "[0.0, 0.0, 0.0]", "cb": "[1.0, 0.0, 0.0]",
              "size_a": "half = [1.0, 1.0, 1.0]", "size_b": "half = [1.0, 1.0, 1.0]"} | fields
    result = load_paths([write_toml(BOX.format(**values))])
    assert result.errors and {e.field for e in result.errors} == {"twin_2d"}, result.errors
    assert any(reason in e.reason for e in result.errors), result.errors
    assert all(c.dim == 3 for c in result.cases)


def test_a_scene_has_no_twin(write_toml: Write) -> None:
    text = """
[[case]]
id = "sc"
description = "a 3-D scene"
kind = "sphere_scene"
dim = 3
twin_2d = "xy"
duration = 1.0
bodies = [
  { center = [0.0, 0.0, 0.0], radius = 0.5, mass = 1.0, velocity = [1.0, 0.0, 0.0] },
  { center = [2.0, 0.0, 0.0], radius = 0.5, mass = 1.0, velocity = [0.0, 0.0, 0.0] },
]
"""
    (error,) = load_paths([write_toml(text)]).errors
    assert error.field == "twin_2d" and "scenes have no 2-D twin" in error.reason


def sweep_rows(case: AnyCase, engine: str, status: Any) -> list[dict[str, Any]]:
    """Result rows of one sweep point: ``status(quantity, truth)`` gives each status."""
    truth = oracle.truth(case)
    return [{"case_id": case.id, "kind": case.kind, "dim": case.dim, "engine": engine,
             "quantity": q, "value": "0.0", "status": status(q, truth), "error": 0.0,
             "tolerance": 1e-9, "category": "", "origin": case.origin,
             "coords": json.dumps(case.coords), "twin_of": case.twin_of}
            for q in quantities_of(case.kind_enum)]


def test_a_2d_engine_has_a_verdict_on_every_stability_sweep(suite: list[AnyCase]) -> None:
    """A pymunk-like engine: 3-D skipped, no distance or normal for bodies that do not
    collide, every other answer right; beside it one that is right everywhere.  Every sweep
    family has a 2-D column, where the 2-D engine holds; its 3-D columns have no verdict."""
    def flat(quantity: str, truth: Any) -> str:
        missing = quantity in ("distance", "normal") and truth.hit is False
        return "skip" if missing else "agree"
    points = [c for c in suite if c.coords and not isinstance(c, SceneCase) and not c.twin_of]
    rows = [row for c in points for row in (
        sweep_rows(c, "flat", (lambda q, t: "skip") if c.dim == 3 else flat)
        + sweep_rows(c, "solid", lambda q, t: "agree"))]
    table = stability.thresholds(stability.sweep_points(pd.DataFrame(rows),
                                                        {c.id: c for c in suite}))
    shown = table[table["headline"]]
    columns = set(shown["column"])
    assert {f"{family}{TWIN_SUFFIX}" for family in shown.loc[shown["dim"] == 3, "family"]} <= set(
        shown["sweep"])  # every 3-D sweep has its 2-D twin's columns beside it
    for engine in ("flat", "solid"):
        cells = shown[shown["engine"] == engine]
        assert sorted(cells["column"]) == sorted(columns)  # one cell per column
    flat_2d = shown[(shown["engine"] == "flat") & (shown["dim"] == 2)]
    assert set(flat_2d["state"]) == {"none"}, flat_2d[flat_2d["state"] != "none"]
    assert set(shown.loc[(shown["engine"] == "flat") & (shown["dim"] == 3), "state"]) == {
        "unjudged"}
    assert set(shown.loc[shown["engine"] == "solid", "state"]) == {"none"}
