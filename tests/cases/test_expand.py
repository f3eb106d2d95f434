"""Sweep expansion, A/B swapping, and the mirror property of swapped cases."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from crosscheck.cases.expand import (
    TWIN_TAG,
    SweepError,
    TwinError,
    expand,
    flattened,
    swapped,
    values_of,
)
from crosscheck.cases.load import load_paths
from crosscheck.core.model import Observation, Undefined
from crosscheck.core.schema import AnyCase, LinSpace, LogSpace, Plane, SceneCase
from crosscheck.truth import oracle
from tests.conftest import ROOT, aabb, response, sphere

Write = Callable[..., Path]


def test_value_specs() -> None:
    assert values_of([0.5, -1]) == [0.5, -1.0]
    assert values_of(LogSpace(logspace=(0, 3, 4))) == [1.0, 10.0, 100.0, 1000.0]
    assert values_of(LinSpace(linspace=(0, 1, 3))) == [0.0, 0.5, 1.0]


def test_gap_and_overlap_move_b_along_the_line_of_centres() -> None:
    case = sphere(0.0, 1.0, sweep={"gap": [0.5], "overlap": [0.25]})
    (point,) = expand(case)
    assert point.id == "s.gap=0.5,overlap=0.25"
    assert point.b.center == (0.75, 0.0, 0.0)  # gap then overlap from the touching distance
    assert "sweep" in point.tags and point.sweep is None
    assert point.description == "d [gap = 0.5, overlap = 0.25]"


def test_box_gap_uses_the_half_widths_on_the_axis() -> None:
    case = aabb([0.0, 0.0], [1.0, 2.0], [0.0, 5.0], [1.0, 1.0], sweep={"gap": [0.5]})
    assert expand(case)[0].b.center == (0.0, 4.5)  # (2 + 1) * 1.5 along +y


def test_scale_offset_and_cartesian_product_order() -> None:
    case = sphere(0.0, 1.0, sweep={"scale": [2.0, 3.0], "offset": {"logspace": [0, 1, 2]}})
    points = expand(case)
    assert [p.id for p in points] == ["s.scale=2,offset=1", "s.scale=2,offset=10",
                                      "s.scale=3,offset=1", "s.scale=3,offset=10"]
    last = points[-1]
    assert last.a.center == (10.0, 10.0, 10.0) and last.b.center == (13.0, 10.0, 10.0)
    assert last.a.radius == 1.5


def test_mass_ratio_and_speed_for_responses_only() -> None:
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0],
                    sweep={"mass_ratio": [1e12], "speed": [0.1]})
    (point,) = expand(case)
    assert point.b.mass == 1e12 and point.a.velocity == (0.1, 0.0)
    with pytest.raises(SweepError) as info:
        expand(sphere(0.0, 1.0, sweep={"mass_ratio": [2.0]}))
    assert info.value.field == "sweep.mass_ratio"


def test_bad_sweeps_are_errors_naming_the_field(write_toml: Write) -> None:
    text = """
[[case]]
id = "diag"
description = "box gap on a diagonal"
kind = "aabb"
dim = 2
a = { center = [0.0, 0.0], half = [1.0, 1.0] }
b = { center = [2.0, 2.0], half = [1.0, 1.0] }
sweep = { gap = [0.1] }
"""
    (error,) = load_paths([write_toml(text)]).errors
    assert error.message.endswith("case 'diag': field sweep.direction: "
                                  "a box gap must be along one axis")
    broken = text.replace("gap = [0.1]", "gap = { logspace = [0, 1] }")
    (error,) = load_paths([write_toml(broken, "b.toml")]).errors
    assert "field sweep.gap" in error.message


def test_loader_expands_sweeps_and_adds_swaps(write_toml: Write) -> None:
    text = """
[[case]]
id = "gaps"
description = "gap sweep"
kind = "sphere"
dim = 3
a = { center = [0.0, 0.0, 0.0], radius = 0.5 }
b = { center = [1.0, 0.0, 0.0], radius = 0.5 }
sweep = { gap = { logspace = [-15, -1, 15] } }

[[case]]
id = "no-swap"
description = "opts out of swapping"
kind = "sphere"
dim = 2
swap = false
a = { center = [0.0, 0.0], radius = 0.5 }
b = { center = [2.0, 0.0], radius = 0.5 }
"""
    result = load_paths([write_toml(text)])
    assert result.errors == [] and result.blocks == 2
    ids = [c.id for c in result.cases]
    assert len(ids) == 15 * 2 + 1
    assert ids[:2] == ["gaps.gap=1e-15", "gaps.gap=1e-15.swapped"]
    assert ids[-1] == "no-swap"
    again = load_paths([write_toml(text, "again.toml")]).cases  # stable ids and inputs
    assert [(c.id, c.a, c.b) for c in again] == [(c.id, c.a, c.b) for c in result.cases]


def mirrored(obs: Observation) -> Observation:
    normal = obs.normal
    if isinstance(normal, tuple):
        normal = tuple(-x for x in normal)
    return Observation(hit=obs.hit, distance=obs.distance, normal=normal, v1=obs.v2, v2=obs.v1)


def test_swapped_twins_of_the_shipped_suite_mirror_exactly() -> None:
    cases = {c.id: c for c in load_paths([ROOT / "cases"]).cases}
    twins = [(cases[i.removesuffix(".swapped")], c) for i, c in cases.items()
             if i.endswith(".swapped")]
    assert len(twins) >= 100
    for original, twin in twins:
        if original.bad_input:
            continue
        want, got = mirrored(oracle.truth(original)), oracle.truth(twin)
        for quantity in ("hit", "distance", "normal", "v1", "v2"):
            a, b = want.get(quantity), got.get(quantity)
            assert a == b or (isinstance(a, Undefined) and isinstance(b, Undefined)), (
                original.id, quantity, a, b)


def test_flattened_drops_the_axis_its_plane_leaves_out() -> None:
    case = response([1.0, 2.0, 3.0], [4.0, 0.0, 5.0], [2.0, 2.0, 4.0], [0.0, 0.0, -1.0],
                    sweep={"speed": [2.0], "direction": [1.0, 0.0, 1.0]})
    flat = flattened(case, "xz")
    assert (flat.id, flat.dim, flat.twin_2d) == ("r.2d", 2, None)
    assert flat.a.center == (1.0, 3.0) and flat.b.velocity == (0.0, -1.0)
    assert flat.sweep is not None and flat.sweep.direction == (1.0, 1.0)
    assert flat.tags == (TWIN_TAG,) and flat.description == "d (2-D twin in the xz plane)"
    box = flattened(aabb([0.0, 5.0, 1.0], [1.0, 2.0, 3.0], [2.0, 5.0, 0.0], [1.0, 1.0, 1.0]),
                    "xz")
    assert (box.a.center, box.a.half, box.b.half) == ((0.0, 1.0), (1.0, 3.0), (1.0, 1.0))


@pytest.mark.parametrize(("case", "plane", "field"), [
    (sphere(0.0, 1.0), "yz", "a.center[0]"),  # the centres differ in x
    (response([0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]), "xy",
     "a.velocity[2]"),
    (sphere(0.0, 1.0, sweep={"gap": [0.1], "direction": [1.0, 0.0, 1.0]}), "xy",
     "sweep.direction[2]"),
    (sphere(0.0, 1.0, dim=2), "xy", "dim"),
])
def test_a_case_off_the_plane_has_no_twin(case: AnyCase, plane: Plane, field: str) -> None:
    assert not isinstance(case, SceneCase)
    with pytest.raises(TwinError) as info:
        flattened(case, plane)
    assert info.value.field == "twin_2d" and f"{plane} plane: {field} " in str(info.value)


def test_a_swapped_twin_links_to_the_swapped_3d_case() -> None:
    (point, twin) = expand(sphere(0.0, 1.0, twin_2d="xy"))
    assert (twin.id, twin.from_3d, point.from_3d) == ("s.2d", "s", "")
    assert swapped(twin).from_3d == "s.swapped" and swapped(point).from_3d == ""


def test_swap_exchanges_bodies_and_keeps_the_rest() -> None:
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], mb=3.0)
    twin = swapped(case)
    assert (twin.a, twin.b) == (case.b, case.a)
    assert twin.swap is False and twin.restitution == case.restitution
