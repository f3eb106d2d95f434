"""Scoring: errors, tolerances, statuses and categories of disagreements."""

from __future__ import annotations

import math
import sys

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import FEATURES, Conventions
from crosscheck.core.model import Category, Observation, Status, Undefined
from crosscheck.core.values import encode
from crosscheck.truth import oracle
from crosscheck.truth.bounds import bound, error_of
from crosscheck.truth.categories import touch_feature
from crosscheck.truth.score import judge
from tests.conftest import ROOT, aabb, response, sphere

TEXTBOOK = Conventions()
SUITE = {case.id: case for case in load_paths([ROOT / "cases"]).cases}


def _rotated(normal: tuple[float, ...], angle: float) -> tuple[float, ...]:
    """``normal`` turned by ``angle`` towards an axis perpendicular to it (3-D)."""
    x, y, z = normal
    side = (y, -x, 0.0) if abs(z) < 0.9 else (0.0, z, -y)
    length = math.hypot(*side)
    perp = tuple(c / length for c in side)
    return tuple(math.cos(angle) * n + math.sin(angle) * p for n, p in zip(normal, perp,
                                                                           strict=True))


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


def test_no_truth_is_invented_where_the_case_has_none() -> None:
    case = SUITE["resp-2d-coincident-centres"]
    truth = oracle.truth(case)
    assert isinstance(truth.v1, Undefined)
    moved = Observation(v1=(0.5, 0.0), v2=(-0.5, 0.0), resolved_at=((-0.1, 0.0), (0.1, 0.0)))
    for quantity in ("v1", "v2"):
        verdict = judge(case, adapters.get("pymunk").conventions, quantity,
                        moved.get(quantity), truth, moved)
        assert verdict.status is Status.UNDEFINED


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


def test_a_box_margin_is_never_applied_to_spheres() -> None:
    pybullet = adapters.get("pybullet").conventions
    assert pybullet.margin_for("sphere") == 0.0 and pybullet.margin_for("face") > 0
    case = sphere(0.0, 1.001)  # apart by 1e-3: a sphere verdict wrong by 1e-3 is an error
    truth = oracle.truth(case)
    verdict = judge(case, pybullet, "hit", True, truth)
    assert verdict.category == Category.ERROR and "margin" not in verdict.reason
    boxes = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.001, 0.0, 0.0], [0.5, 0.5, 0.5])
    within = judge(boxes, pybullet, "hit", True, oracle.truth(boxes))
    assert within.category == Category.TOLERANCE and "margin 0.002 at a face" in within.reason


def test_a_normal_across_the_gap_tilts_by_the_margin_over_the_gap() -> None:
    case = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [2.0, 2.0, 2.0], [0.5, 0.5, 0.5])
    truth = oracle.truth(case)  # gap sqrt(3) = 1.73, centres 3.46 apart
    assert isinstance(truth.normal, tuple) and isinstance(truth.distance, float)
    engine = Conventions(margins={"corner": 0.002})
    allowed = 0.002 / truth.distance  # what a 0.002 length error does across the gap
    tilted = _rotated(truth.normal, 0.8 * allowed)  # beyond 0.002 / 3.46 (the old rule)
    verdict = judge(case, engine, "normal", tilted, truth)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)
    beyond = judge(case, engine, "normal", _rotated(truth.normal, 1.5 * allowed), truth)
    assert beyond.category == Category.ERROR


def test_an_undefined_answer_is_a_convention_only_under_a_declared_rule() -> None:
    case = sphere(1e9, 1e9 + 1.5)  # float32 cannot tell these centres apart
    truth = oracle.truth(case)
    declared = Conventions(rtol=2.0**-21, no_value=("float32-textbook",))
    verdict = judge(case, declared, "normal", Undefined("coincident centres"), truth)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)
    assert "'float32-textbook'" in verdict.reason and "coincident centres" in verdict.reason
    # the same precision without the rule: no value is an error, however wide the allowance
    wide = Conventions(rtol=2.0**-21, margins=dict.fromkeys(FEATURES, 10.0))
    undeclared = judge(case, wide, "normal", Undefined("coincident centres"), truth)
    assert undeclared.category == Category.ERROR and "no declared convention" in undeclared.reason
    near = sphere(0.0, 2.0)  # float32 tells these apart: the rule does not fire
    far = judge(near, declared, "normal", Undefined("x"), oracle.truth(near))
    assert far.category == Category.ERROR


def test_a_missing_value_is_never_within_a_margin() -> None:
    # a prediction distance or any margin never explains an answer that has no value
    boxes = aabb([0.0, 0.0, 0.0], [1e-6] * 3, [2e-6 - 2e-12, 0.0, 0.0], [1e-6] * 3)
    margin = Conventions(margins=dict.fromkeys(FEATURES, 0.02), rtol=2.0**-21)
    none = Undefined("no contact point")
    for quantity in ("distance", "normal"):
        verdict = judge(boxes, margin, quantity, none, oracle.truth(boxes))
        assert verdict.category == Category.ERROR, quantity


def test_an_answer_with_no_finite_value_never_agrees() -> None:
    # a normal across a subnormal gap may point anywhere (its bound is pi), but it must point
    case = SUITE["aabb-3d-subnormal-gap"]
    truth = oracle.truth(case)
    assert bound(case, "normal", truth.distance) >= math.pi  # type: ignore[arg-type]
    for value in (Undefined("NaN normal"), (math.nan, math.nan, math.nan)):
        verdict = judge(case, TEXTBOOK, "normal", value, truth)
        assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.ERROR)
    assert judge(case, TEXTBOOK, "normal", (0.0, 1.0, 0.0), truth).status is Status.AGREE


def test_one_failed_query_gets_one_category_and_one_reason() -> None:
    case = SUITE["aabb-3d-subnormal-gap"]
    truth = oracle.truth(case)
    failed = Observation(hit=True, distance=-sys.float_info.max,
                         normal=Undefined("no finite normal (nan, nan, nan)"))
    wide = Conventions(margins=dict.fromkeys(FEATURES, 1e-6), rtol=2e-10)
    verdicts = [judge(case, wide, q, failed.get(q), truth, failed) for q in ("distance", "normal")]
    assert {v.category for v in verdicts} == {Category.ERROR}
    assert all("-1.8e+308" in v.reason and "no finite normal" in v.reason for v in verdicts)


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


def test_a_normal_is_a_unit_vector_to_the_engines_own_precision() -> None:
    """A float32 engine's normal 5e-6 longer than 1, in the right direction, is judged by its
    direction; a float64 engine's is not a unit vector; 1.01 is none for either."""
    case = sphere(0.0, 0.75, dim=3)  # overlapping by 0.25: the normal is +x
    truth = oracle.truth(case)
    float32, float64 = Conventions(rtol=2.0**-21), Conventions(rtol=2.0**-52)
    long = (1.0 + 5e-6, 0.0, 0.0)
    seen = Observation(hit=True, distance=-0.25, normal=long)
    judged = judge(case, float32, "normal", long, truth, seen)
    assert judged.status is Status.DISAGREE  # not a unit vector to float64: never agree
    assert judged.category == Category.TOLERANCE, judged.reason
    assert "judged by its direction" in judged.reason and "(rtol 4.77e-07)" in judged.reason
    for conv in (float64, TEXTBOOK):
        verdict = judge(case, conv, "normal", long, truth, seen)
        assert verdict.category == Category.ERROR and "not a unit vector" in verdict.reason
    for conv in (float32, float64):
        far = judge(case, conv, "normal", (1.01, 0.0, 0.0), truth, seen)
        assert far.category == Category.ERROR and "length 1.01" in far.reason


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
