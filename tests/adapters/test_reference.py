"""The reference adapters run the textbook formula as an engine, scored like one."""

from __future__ import annotations

import adapters
from crosscheck.core.model import Category, Status
from crosscheck.core.schema import AnyCase
from crosscheck.truth import oracle
from crosscheck.truth.score import judge
from tests.conftest import aabb, sphere


def verdict(engine: str, case: AnyCase, quantity: str = "hit") -> tuple[Status, str]:
    adapter = adapters.get(engine)
    obs = adapter.query(adapter.prepare(case))
    truth = oracle.truth(case)
    v = judge(case, adapter.conventions, quantity, obs.get(quantity), truth)
    return v.status, v.category


def test_float64_textbook_flips_known_box_trap_within_rounding() -> None:
    case = aabb([0.0, 0.0, 0.0], [0.8, 1.0, 1.0], [1.2000000000000002, 0.0, 0.0], [0.4, 1.0, 1.0])
    assert verdict("reference", case) == (Status.DISAGREE, Category.TOLERANCE)


def test_float64_textbook_flips_known_sphere_trap_within_rounding() -> None:
    case = sphere(0.75, 2.05, ra=0.6, rb=0.7)
    assert verdict("reference", case) == (Status.DISAGREE, Category.TOLERANCE)


def test_float32_loses_an_overlap_that_float64_keeps() -> None:
    case = sphere(0.0, 1.0 - 2.0**-40)  # rounds to exactly touching in float32
    assert verdict("reference", case)[0] is Status.AGREE
    assert verdict("reference-f32", case)[0] is Status.DISAGREE


def test_registry_lists_reference_adapters() -> None:
    assert {"reference", "reference-f32"} <= set(adapters.names())
    f32, f64 = adapters.get("reference-f32"), adapters.get("reference")
    assert f32.conventions.rtol > f64.conventions.rtol


def test_no_normal_where_the_formula_in_its_precision_has_none_is_its_declared_rule() -> None:
    # 1e9 and 1e9 + 1.5 are one float32 number: the float32 formula's centres coincide, and
    # by its own rule it gives no normal; float64 keeps them apart and gives one
    case = sphere(1e9, 1e9 + 1.5)
    assert verdict("reference-f32", case, "normal") == (Status.DISAGREE, Category.CONVENTION)
    assert verdict("reference", case, "normal")[0] is Status.AGREE
    f32 = adapters.get("reference-f32")
    obs = f32.observe(case)
    reason = judge(case, f32.conventions, "normal", obs.normal, oracle.truth(case)).reason
    assert "'float32-textbook'" in reason and "coincident centres" in reason
    assert adapters.get("reference").conventions.no_value == ("float64-textbook",)
