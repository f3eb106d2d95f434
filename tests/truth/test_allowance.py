"""One allowance rule for every quantity: what acts on which quantity, and the positional term
of responses, so that the same rounding reads alike in detection and in responses."""

from __future__ import annotations

import math

from crosscheck.core.contract import FEATURES, Conventions
from crosscheck.core.model import Category, Observation, Status
from crosscheck.core.schema import ResponseCase
from crosscheck.truth import oracle
from crosscheck.truth.allowance import allowance
from crosscheck.truth.score import judge
from tests.conftest import aabb, response, sphere

FLOAT32 = Conventions(rtol=2.0**-21)
FLOAT64 = Conventions(rtol=2.0**-50)


def collapsed(pa: list[float], va: list[float], pb: list[float], vb: list[float],
              line: tuple[float, float]) -> Observation:
    """Equal unit masses, elastic: the textbook's response along ``line`` instead of the line
    of centres (what an engine computes once rounding moved its centres)."""
    closing = sum((x - y) * n for x, y, n in zip(va, vb, line, strict=True))
    return Observation(v1=tuple(x - closing * n for x, n in zip(va, line, strict=True)),
                       v2=tuple(y + closing * n for y, n in zip(vb, line, strict=True)))


def test_a_float32_collapse_at_1e8_reads_alike_in_detection_and_in_responses() -> None:
    # 3-4-5 neighbours at 1e8: float32's spacing there is 8, so the centres may land anywhere
    # within it; a distance read across them and a response along a wrong line are both
    # within what the declared precision does to the case's numbers.
    big = 1e8
    gap = sphere(big, big + 5.0, ra=2.0, rb=2.0)  # a gap of 1 that float32 cannot hold
    moved = judge(gap, FLOAT32, "distance", -4.0, oracle.truth(gap))
    case = response([big, big], [1.0, 0.0], [big + 3.0, big + 4.0], [0.0, -1.0])
    wrong = collapsed([big, big], [1.0, 0.0], [big + 3.0, big + 4.0], [0.0, -1.0], (1.0, 0.0))
    turned = judge(case, FLOAT32, "v1", wrong.v1, oracle.truth(case), wrong)
    assert (moved.category, turned.category) == (Category.TOLERANCE, Category.TOLERANCE)
    assert "centres' rounding" in turned.reason
    # float64 holds those centres: the same wrong line is an error there, as the distance is
    assert judge(case, FLOAT64, "v1", wrong.v1, oracle.truth(case), wrong).category == (
        Category.ERROR)
    assert judge(gap, FLOAT64, "distance", -4.0, oracle.truth(gap)).category == Category.ERROR


def test_the_positional_term_follows_the_line_of_centres_and_vanishes_near_the_origin() -> None:
    near = response([0.0, 0.0], [1.0, 0.0], [3.0, 4.0], [0.0, -1.0])
    assert isinstance(near, ResponseCase)
    allowed = allowance(near, FLOAT32, "v1")
    # centres off by 2^-21 x 4 tilt a line 5 long by 2 x 2^-21 x 4 / 5 at most
    assert math.isclose(allowed.positional, 2 * math.sqrt(2) * (2 * 2.0**-21 * 4 / 5))
    assert allowed.total == allowed.rtol * allowed.size + allowed.positional


def test_a_verdict_threshold_acts_on_the_verdict_alone() -> None:
    # a prediction distance of 0.02 makes pairs 0.01 apart contact: it explains the verdict,
    # never a distance or a normal, and no reason of theirs cites it
    prediction = Conventions(rtol=2.0**-21, verdict_margins=dict.fromkeys(FEATURES, 0.02))
    case = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.01, 0.0, 0.0], [0.5, 0.5, 0.5])
    truth = oracle.truth(case)
    hit = judge(case, prediction, "hit", True, truth)
    assert hit.category == Category.TOLERANCE and "verdict margin 0.02 at a face" in hit.reason
    distance = judge(case, prediction, "distance", 0.0, truth)
    normal = judge(case, prediction, "normal", (0.0, 1.0, 0.0), truth)
    for verdict in (distance, normal):
        assert verdict.category == Category.ERROR and "margin" not in verdict.reason
    # without verdict margins, the length margins act on the verdict too (FCL, PyBullet)
    both = Conventions(margins=dict.fromkeys(FEATURES, 0.02))
    assert judge(case, both, "distance", 0.0, truth).category == Category.TOLERANCE
    assert judge(case, both, "hit", True, truth).category == Category.TOLERANCE


def test_a_response_precision_widens_velocities_not_the_positional_term() -> None:
    # a contact model solved to a measured precision (response_rtol) on float64 positions
    far = response([1e8, 1e8], [1.0, 0.0], [1e8 + 3.0, 1e8 + 4.0], [0.0, -1.0])
    assert isinstance(far, ResponseCase)
    stiff = Conventions(rtol=2.0**-50, response_rtol=1e-4)
    allowed = allowance(far, stiff, "v2")
    assert allowed.rtol == 1e-4 and allowed.positional < 1e-6
    truth = oracle.truth(far)
    assert isinstance(truth.v2, tuple)
    off = (truth.v2[0] + 5e-5, truth.v2[1])
    verdict = judge(far, stiff, "v2", off, truth, Observation(v1=truth.v1, v2=off))
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)
    assert judge(far, FLOAT64, "v2", off, truth).category == Category.ERROR
