"""Times of impact (:mod:`crosscheck.truth.toi`): the exact truth, the float64 bound and the
categories of engines' answers, from declared conventions."""

from __future__ import annotations

import math
from typing import Any

from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation, Status, Undefined
from crosscheck.core.schema import CASE_ADAPTER, ToiCase
from crosscheck.truth import oracle, toi
from crosscheck.truth.score import judge
from tests.conftest import ROOT

SUITE = [c for c in load_paths([ROOT / "cases"]).cases if isinstance(c, ToiCase)]


def crossing(**changes: object) -> ToiCase:
    block = {"id": "t", "description": "d", "kind": "sphere_toi", "dim": 2, "duration": 1.0,
             "a": {"center": [-1.0123456789, 0.0], "radius": 0.05,
                   "velocity": [2.0246913578, 0.0]},
             "b": {"center": [1.0123456789, 0.0], "radius": 0.05,
                   "velocity": [-2.0246913578, 0.0]}} | changes
    case = CASE_ADAPTER.validate_python(block)
    assert isinstance(case, ToiCase)
    return case


def float64_root(case: ToiCase) -> float:
    """A plain float64 solver: the first root of |dp + dv t|^2 = R^2, cancellation-free."""
    dp = [y - x for x, y in zip(case.a.center, case.b.center, strict=True)]
    dv = [y - x for x, y in zip(case.a.velocity, case.b.velocity, strict=True)]
    radius = case.a.radius + case.b.radius
    a = sum(v * v for v in dv)
    b = sum(p * v for p, v in zip(dp, dv, strict=True))
    c = sum(p * p for p in dp) - radius * radius
    if c <= 0:
        return 0.0
    return c / (-b + math.sqrt(max(0.0, b * b - a * c)))


def test_a_float64_solver_stays_within_the_time_bound_on_the_suite() -> None:
    hits = [c for c in SUITE if oracle.truth(c).hit is True]
    assert len(hits) > 40
    for case in hits:
        truth = oracle.truth(case)
        assert isinstance(truth.toi, float)
        verdict = judge(case, Conventions(), "toi", float64_root(case), truth)
        assert verdict.status is Status.AGREE, (case.id, verdict)


def test_the_time_bound_is_tight_enough_to_catch_a_step_late_answer() -> None:
    case = crossing()
    truth = oracle.truth(case)
    assert isinstance(truth.toi, float)
    late = judge(case, Conventions(), "toi", truth.toi + 1e-9, truth)
    assert late.status is Status.DISAGREE and late.tolerance < 1e-12


def test_the_discrete_baseline_misses_a_crossing_and_says_it_fell_between_samples() -> None:
    case = crossing()
    sampled = oracle.textbook(case)
    assert sampled.hit is False
    verdict = judge(case, Conventions(toi_samples=2), "hit", sampled.hit,
                    oracle.truth(case), sampled)
    assert verdict.status is Status.DISAGREE and verdict.category == Category.TIMESTEP
    assert "falls between them" in verdict.reason


def test_a_declared_target_overlap_explains_a_later_time_as_convention() -> None:
    case = crossing()
    truth = oracle.truth(case)
    assert isinstance(truth.toi, float)
    closing = 2 * 2.0246913578  # |vb - va|
    overlap = 0.015  # an engine that stops at 1.5 cm of overlap reports this much later
    later = truth.toi + overlap / closing
    engine = Observation(hit=True, toi=later, normal=(1.0, 0.0))
    declared = Conventions(toi_target=-overlap, toi_tolerance=1e-3)
    verdict = judge(case, declared, "toi", later, truth, engine)
    assert verdict.status is Status.DISAGREE and verdict.category == Category.CONVENTION
    undeclared = judge(case, Conventions(), "toi", later, truth, engine)
    assert undeclared.category == Category.ERROR


def test_no_contact_where_the_pair_crosses_is_an_error_without_a_declared_rule() -> None:
    case = crossing()
    none = Undefined("no contact")
    engine = Observation(hit=False, toi=none, normal=none)
    for quantity in ("hit", "toi", "normal"):
        verdict = judge(case, Conventions(), quantity, engine.get(quantity),
                        oracle.truth(case), engine)
        assert verdict.status is Status.DISAGREE and verdict.category == Category.ERROR
        assert "reported no contact" in verdict.reason


def test_toi_and_normal_have_no_value_without_a_contact() -> None:
    miss = crossing(b={"center": [1.0, 0.2], "radius": 0.05, "velocity": [-2.0, 0.0]})
    truth = oracle.truth(miss)
    assert truth.hit is False and isinstance(truth.toi, Undefined)
    verdict = judge(miss, Conventions(), "toi", 0.5, truth)
    assert verdict.status is Status.UNDEFINED


def test_a_normal_right_for_the_engines_own_time_takes_that_times_category() -> None:
    oblique = crossing(b={"center": [1.0, 0.06], "radius": 0.05, "velocity": [-2.0, 0.0]})
    truth = oracle.truth(oblique)
    assert isinstance(truth.toi, float)
    later = truth.toi + 0.001
    motion = toi.Motion.of(oblique)
    d = motion.at(later)
    length = math.hypot(*d)
    normal = (d[0] / length, d[1] / length)
    engine = Observation(hit=True, toi=later, normal=normal)
    declared = Conventions(toi_target=motion.gap(later), toi_tolerance=1e-6)
    verdict = judge(oblique, declared, "normal", normal, truth, engine)
    assert verdict.category == Category.CONVENTION
    assert "normal right for the engine's time" in verdict.reason


def test_a_query_that_starts_inside_its_target_separation_reports_zero_by_its_rule() -> None:
    tiny = crossing(a={"center": [-0.001, 0.0], "radius": 1e-4, "velocity": [0.002, 0.0]},
                    b={"center": [0.001, 0.0], "radius": 1e-4, "velocity": [-0.002, 0.0]})
    truth = oracle.truth(tiny)
    engine = Observation(hit=True, toi=0.0, normal=(1.0, 0.0))
    slop = Conventions(toi_target=-0.015, toi_tolerance=0.00125, toi_min_centre_distance=0.005)
    verdict = judge(tiny, slop, "toi", 0.0, truth, engine)
    assert verdict.category == Category.CONVENTION and "at the start" in verdict.reason
    assert judge(tiny, Conventions(), "toi", 0.0, truth, engine).category == Category.ERROR


def test_a_normal_that_is_not_a_unit_vector_is_an_error_whatever_its_direction() -> None:
    case = crossing()
    verdict = judge(case, Conventions(), "normal", (1.0000109, 0.0), oracle.truth(case))
    assert verdict.category == Category.ERROR and "not a unit vector" in verdict.reason


def test_a_declared_time_tolerance_explains_a_solver_that_stops_short() -> None:
    graze = crossing(b={"center": [1.0, 0.1], "radius": 0.05, "velocity": [-2.0, 0.0]},
                     a={"center": [-1.0, 0.0], "radius": 0.05, "velocity": [2.0, 0.0]})
    truth = oracle.truth(graze)
    assert truth.toi == 0.5
    early = 0.49985
    engine = Observation(hit=True, toi=early, normal=(0.0, 1.0))
    stops = Conventions(toi_time_tolerance=1e-4)
    assert judge(graze, stops, "toi", early, truth, engine).category == Category.TOLERANCE
    assert judge(graze, Conventions(), "toi", early, truth, engine).category == Category.ERROR


def test_a_declared_rule_is_named_before_the_precision_that_would_also_cover_it() -> None:
    graze = crossing(a={"center": [-1.0, 0.0], "radius": 0.05, "velocity": [2.0, 0.0]},
                     b={"center": [1.0, 0.1], "radius": 0.05, "velocity": [-2.0, 0.0]})
    none = Undefined("no contact")
    engine = Observation(hit=False, toi=none, normal=none)
    sampled = judge(graze, Conventions(toi_samples=2), "hit", False, oracle.truth(graze), engine)
    assert sampled.category == Category.TIMESTEP  # between its samples, not "only a touch"
    end = crossing(duration=0.75, a={"center": [-1.0, 0.0], "radius": 0.25, "velocity": [1.0, 0.0]},
                   b={"center": [1.0, 0.0], "radius": 0.25, "velocity": [-1.0, 0.0]})
    excluded = judge(end, Conventions(toi_end_excluded=True), "hit", False, oracle.truth(end),
                     engine)
    assert excluded.category == Category.CONVENTION and "interval's end" in excluded.reason


TOUCHING_AT_START: dict[str, Any] = {  # touching exactly at t = 0 along (4, -8, -1) / 9
    "dim": 3, "duration": 1.0,
    "a": {"center": [0.0, 0.0, 0.0], "radius": 1.0,
          "velocity": [0.2222222222222222, -0.4444444444444444, -0.05555555555555555]},
    "b": {"center": [0.8888888888888857, -1.7777777777777715, -0.22222222222222143],
          "radius": 0.9999999999999929,
          "velocity": [-0.2222222222222222, 0.4444444444444444, 0.05555555555555555]}}


def test_a_pair_touching_at_the_start_may_round_apart_within_the_time_bound() -> None:
    case = crossing(**TOUCHING_AT_START)
    truth = oracle.truth(case)
    assert truth.toi == 0.0 and float64_root(case) > 0  # float64 reads the pair apart
    assert judge(case, Conventions(), "toi", float64_root(case), truth).status is Status.AGREE
    assert judge(case, Conventions(), "toi", 1e-9, truth).status is Status.DISAGREE


def test_a_sampling_engine_that_reads_a_touch_at_its_first_sample_as_apart_is_timestep(
        ) -> None:
    case = crossing(**TOUCHING_AT_START)
    truth = oracle.truth(case)
    sampled = Conventions(toi_samples=2)  # the two ends, as the reference variants
    observed = Observation(hit=True, toi=1.0, normal=truth.normal)
    verdict = judge(case, sampled, "toi", 1.0, truth, observed)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TIMESTEP)
    clearly = crossing(**TOUCHING_AT_START | {"b": TOUCHING_AT_START["b"] | {"radius": 1.5}})
    verdict = judge(clearly, sampled, "toi", 1.0, oracle.truth(clearly),
                    Observation(hit=True, toi=1.0, normal=truth.normal))
    assert verdict.category is Category.ERROR  # overlapping by 0.5 at t = 0: not rounding


# --- the samples of a sampling query --------------------------------------------------------


def head_on(duration: float, speed: float, radius: float = 0.5, offset: float = 0.0
            ) -> ToiCase:
    """Centres at ``offset -+ 1`` on x closing at ``2 speed``; radii ``radius``."""
    return crossing(duration=duration,
                    a={"center": [offset - 1.0, 0.0], "radius": radius, "velocity": [speed, 0.0]},
                    b={"center": [offset + 1.0, 0.0], "radius": radius,
                       "velocity": [-speed, 0.0]})


def test_a_reported_sample_is_found_exactly_as_the_engine_rounds_it() -> None:
    """FCL's naive solver reports ``t = i / 9`` of the interval, scaled: ``(i / 9) T``.  On
    ``T = 1e6`` sample 5 is an ulp above ``T * 5 / 9``, which read as an earlier sample that
    already overlaps would make the engine's own first sample an ``error``."""
    case = head_on(duration=1e6, speed=1e-6)  # touching at t = 5e5, between samples 4 and 5
    truth = oracle.truth(case)
    assert truth.toi == 5e5
    reported = (5 / 9) * case.duration
    assert case.duration * 5 / 9 < reported  # the two roundings differ here
    naive = Conventions(toi_samples=10)
    engine = Observation(hit=True, toi=reported, normal=(1.0, 0.0))
    verdict = judge(case, naive, "toi", reported, truth, engine)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TIMESTEP), \
        verdict.reason
    assert reported in toi.sample_times(case, naive)


def test_the_two_ends_are_the_textbook_discrete_tests_own_samples() -> None:
    for duration in (1e6, 0.75, 1e-3, 1000.0 / 3.0):
        case = head_on(duration=duration, speed=1.0)
        assert toi.sample_times(case, Conventions(toi_samples=2)) == [0.0, duration]
    late = head_on(duration=1.0, speed=0.75)  # touching at 2/3: the end sample overlaps
    sampled = oracle.sampled_impact(late)
    assert sampled.toi == 1.0
    verdict = judge(late, Conventions(toi_samples=2), "toi", sampled.toi, oracle.truth(late),
                    sampled)
    assert verdict.category == Category.TIMESTEP


# --- normals of a float32 engine ------------------------------------------------------------


def test_a_float32_normal_is_a_unit_vector_to_float32_and_judged_by_its_direction() -> None:
    case = crossing()
    truth = oracle.truth(case)
    assert truth.normal == (1.0, 0.0) and isinstance(truth.toi, float)
    float32, float64 = Conventions(rtol=2.0**-21), Conventions(rtol=2.0**-52)
    long = (1.0 + 5e-6, 0.0)  # a float32 normal d / R, not renormalised (parry's)
    engine = Observation(hit=True, toi=truth.toi, normal=long)
    judged = judge(case, float32, "normal", long, truth, engine)
    assert judged.status is Status.DISAGREE  # not a float64 unit vector: never agree
    assert judged.category == Category.TOLERANCE, judged.reason
    assert "judged by its direction" in judged.reason and "rtol 4.77e-07" in judged.reason
    for conv in (float64, Conventions()):
        verdict = judge(case, conv, "normal", long, truth, engine)
        assert verdict.category == Category.ERROR and "not a unit vector" in verdict.reason
    assert toi.unit_allowance(case, float32, truth) < 0.01
    for conv in (float32, float64):
        far = judge(case, conv, "normal", (1.01, 0.0), truth, engine)
        assert far.category == Category.ERROR and "length 1.01" in far.reason


# --- answers without a value ----------------------------------------------------------------


def test_a_contact_without_a_normal_is_an_error_unless_a_declared_rule_gives_none() -> None:
    far = head_on(duration=1.0, speed=1.0, radius=0.05, offset=1e8)  # float32: one centre
    engine = oracle.textbook(far, "f32")  # the discrete test in float32, at t = 0
    assert engine.hit is True and engine.toi == 0.0 and isinstance(engine.normal, Undefined)
    truth = oracle.truth(far)
    float32 = Conventions(rtol=2.0**-21, toi_samples=2)
    verdict = judge(far, float32, "normal", engine.normal, truth, engine)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.ERROR)
    assert "no finite answer" in verdict.reason
    declared = Conventions(rtol=2.0**-21, toi_samples=2, no_value=("float32-textbook",))
    verdict = judge(far, declared, "normal", engine.normal, truth, engine)
    assert verdict.category == Category.CONVENTION and "'float32-textbook'" in verdict.reason


def test_a_normal_between_coincident_centres_is_a_convention_of_the_centre_line_rule() -> None:
    case = crossing()  # the centres pass through each other at t = 0.5, exactly
    assert toi.Motion.of(case).at(0.5) == (0.0, 0.0)
    none = Undefined("the centres coincide at the reported time")
    engine = Observation(hit=True, toi=0.5, normal=none)
    truth = oracle.truth(case)
    assert judge(case, Conventions(), "normal", none, truth, engine).category == Category.ERROR
    line = Conventions(no_value=("float64-centre-line",))
    verdict = judge(case, line, "normal", none, truth, engine)
    assert verdict.category == Category.CONVENTION and "t = 0.5" in verdict.reason
    apart = Observation(hit=True, toi=0.25, normal=none)  # 1.01 apart then: no rule
    assert judge(case, line, "normal", none, truth, apart).category == Category.ERROR


def test_no_time_for_a_miss_within_precision_is_not_a_tolerance() -> None:
    """A verdict within the engine's precision of touching is ``tolerance``; the time and
    normal it leaves without a value are not."""
    end = head_on(duration=0.75, speed=1.0, radius=0.25)  # touching at the end, t = 0.75
    assert oracle.truth(end).toi == 0.75
    none = Undefined("no contact in the interval")
    engine = Observation(hit=False, toi=none, normal=none)
    float32 = Conventions(rtol=2.0**-21)
    verdicts = {q: judge(end, float32, q, engine.get(q), oracle.truth(end), engine)
                for q in ("hit", "toi", "normal")}
    assert verdicts["hit"].category == Category.TOLERANCE
    for quantity in ("toi", "normal"):
        assert verdicts[quantity].category == Category.ERROR
        assert "a precision explains the verdict" in verdicts[quantity].reason
    excluded = Conventions(rtol=2.0**-21, toi_end_excluded=True)  # a declared rule still is
    assert judge(end, excluded, "toi", none, oracle.truth(end), engine).category == \
        Category.CONVENTION
