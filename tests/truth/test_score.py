"""Scoring: errors, tolerances, statuses and categories of disagreements."""

from __future__ import annotations

import math

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation, Status, Undefined
from crosscheck.core.values import encode
from crosscheck.truth import oracle
from crosscheck.truth.bounds import bound, error_of
from crosscheck.truth.categories import touch_feature
from crosscheck.truth.score import judge
from tests.conftest import aabb, response, sphere

TEXTBOOK = Conventions()


def test_encode_round_trips_floats_exactly() -> None:
    x = 0.1 + 0.2
    assert float(encode(x)) == x
    assert encode((1.0, -0.5)) == "[1.0, -0.5]"
    assert encode(True) == "true"
    assert encode(None) == "null"
    assert encode(Undefined("x")) == "null"


def test_normal_error_is_an_angle() -> None:
    assert math.isclose(error_of("normal", (1.0, 0.0), (-1.0, 0.0)), math.pi)
    assert error_of("normal", (0.6, 0.8), (0.6, 0.8)) == 0.0


def test_exact_answer_agrees() -> None:
    case = sphere(0.0, 2.0)
    truth = oracle.truth(case)
    for q in ("hit", "distance", "normal"):
        assert judge(case, TEXTBOOK, q, truth.get(q), truth).status is Status.AGREE


def test_distance_bound_scales_with_the_magnitudes_combined_not_the_offset() -> None:
    small, big = sphere(0.0, 2.0), sphere(0.0, 2e6, ra=5e5, rb=5e5)
    assert math.isclose(bound(big, "distance"), 1e6 * bound(small, "distance"))  # M = 3, 3e6
    far = sphere(1e15, 1e15 + 2.0)  # the difference 2 is exact in float64
    assert bound(far, "distance") == bound(small, "distance")


def test_case_tolerance_overrides_default() -> None:
    case = sphere(0.0, 2.0, tolerance={"distance": 0.5})
    truth = oracle.truth(case)
    verdict = judge(case, TEXTBOOK, "distance", 1.4, truth)
    assert verdict.status is Status.AGREE and verdict.tolerance == 0.5


def test_absent_quantity_is_skip() -> None:
    case = sphere(0.0, 2.0)
    verdict = judge(case, TEXTBOOK, "normal", None, oracle.truth(case))
    assert verdict.status is Status.SKIP and "reported no normal" in verdict.reason


def test_undefined_truth_gives_undefined_status() -> None:
    case = sphere(0.0, 0.0)
    verdict = judge(case, TEXTBOOK, "normal", (1.0, 0.0, 0.0), oracle.truth(case))
    assert verdict.status is Status.UNDEFINED and "coincident" in verdict.reason


def test_engine_undefined_where_truth_defined_is_error() -> None:
    case = sphere(0.0, 2.0)
    verdict = judge(case, TEXTBOOK, "normal", Undefined("gave up"), oracle.truth(case))
    assert verdict.status is Status.DISAGREE and verdict.category == Category.ERROR


def test_touching_rule_difference_is_convention() -> None:
    case = sphere(0.0, 1.0)  # exactly touching: textbook says no collision
    truth = oracle.truth(case)
    engine = Conventions(touching={"sphere": True})
    verdict = judge(case, engine, "hit", True, truth)
    assert verdict.status is Status.DISAGREE and verdict.category == Category.CONVENTION
    boxes = aabb([0.0, 0.0], [0.5, 0.5], [1.0, 0.0], [0.5, 0.5])  # touching boxes do overlap
    box_verdict = judge(boxes, engine, "hit", False, oracle.truth(boxes))
    assert box_verdict.category == Category.ERROR


def test_within_margin_is_tolerance_beyond_is_error() -> None:
    case = sphere(0.0, 1.0005)  # gap 5e-4
    truth = oracle.truth(case)
    within = judge(case, Conventions(margins={"sphere": 1e-3}), "hit", True, truth)
    beyond = judge(case, Conventions(margins={"sphere": 1e-4}), "hit", True, truth)
    assert (within.category, beyond.category) == (Category.TOLERANCE, Category.ERROR)


def test_velocity_error_is_euclidean() -> None:
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0])
    truth = oracle.truth(case)
    assert truth == Observation(v1=(-1.0, 0.0), v2=(1.0, 0.0))
    verdict = judge(case, TEXTBOOK, "v1", (-1.0, 3e-3), truth)
    assert verdict.status is Status.DISAGREE and math.isclose(verdict.error, 3e-3)


def test_separating_and_slow_impacts_are_conventions_when_declared() -> None:
    engine = Conventions(resolves_separating=False, restitution_threshold=0.2)
    apart = response([0.0, 0.0], [-1.0, 0.0], [1.0, 0.0], [1.0, 0.0])
    slow = response([0.0, 0.0], [0.05, 0.0], [1.0, 0.0], [-0.05, 0.0])
    fast = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0])
    for case, category in [(apart, Category.CONVENTION), (slow, Category.CONVENTION),
                           (fast, Category.ERROR)]:
        verdict = judge(case, engine, "v1", (0.0, 0.0), oracle.truth(case))
        assert (verdict.status, verdict.category) == (Status.DISAGREE, category)
    assert judge(apart, TEXTBOOK, "v1", (0.0, 0.0), oracle.truth(apart)).category == Category.ERROR


def test_non_unit_normal_is_an_error() -> None:
    case = sphere(0.0, 2.0)
    verdict = judge(case, TEXTBOOK, "normal", (0.0, -0.0, 0.0), oracle.truth(case))
    assert verdict.status is Status.DISAGREE and "not a unit vector" in verdict.reason


def test_box_touch_features_and_per_feature_rules() -> None:
    face = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.0, 0.0, 0.0], [0.5, 0.5, 0.5])
    edge = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.0, 1.0, 0.0], [0.5, 0.5, 0.5])
    corner = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.0, 1.0, 1.0], [0.5, 0.5, 0.5])
    assert [touch_feature(c) for c in (face, edge, corner)] == ["face", "edge", "corner"]
    engine = Conventions(touching={"edge": False, "corner": False},
                         margins=dict.fromkeys(("face", "edge", "corner"), 1e-3))
    for case, category in [(face, Category.TOLERANCE), (edge, Category.CONVENTION),
                           (corner, Category.CONVENTION)]:
        verdict = judge(case, engine, "hit", False, oracle.truth(case))
        assert verdict.category == category, case
