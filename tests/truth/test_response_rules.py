"""The declared response rules beyond the single impulse: a speed cap acting where the engine
says it acts, and a contact that falls between two steps of an engine that samples them."""

from __future__ import annotations

from typing import cast

import pytest

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec
from crosscheck.core.model import Category, Observation, Status
from crosscheck.core.schema import ResponseCase
from crosscheck.truth import oracle
from crosscheck.truth.score import Verdict, judge
from tests.conftest import response as pair


def response(pa: list[float], va: list[float], pb: list[float], vb: list[float],
             **extra: float) -> ResponseCase:
    return cast(ResponseCase, pair(pa, va, pb, vb, **extra))

AT_START = ((0.0, 0.0), (1.0, 0.0))
"""``resolved_at`` of a contact met in the first step (touching unit-diameter spheres)."""
STEP_CAP = Conventions(rtol=2.0**-21, max_speed=120.0, max_speed_at="step")
BOUNCE_CAP = Conventions(rtol=2.0**-21, max_speed=400.0, max_speed_at="before restitution")


def fast(speed: float, e: float = 1.0, mb: float = 1.0) -> ResponseCase:
    """A head-on impact: A at ``speed`` onto B at rest, touching at the start."""
    return response([0.0, 0.0], [speed, 0.0], [1.0, 0.0], [0.0, 0.0], mb=mb, restitution=e)


def judged(case: ResponseCase, conv: Conventions, v1: Vec, v2: Vec,
           at: tuple[Vec, Vec] | None = AT_START) -> list[Verdict]:
    seen = Observation(v1=v1, v2=v2, resolved_at=at)
    truth = oracle.truth(case)
    return [judge(case, conv, q, seen.get(q), truth, seen) for q in ("v1", "v2")]


def test_a_cap_at_the_end_of_the_step_clips_the_textbook_response() -> None:
    # Box2D: solved with the case's speeds in the first step, then each velocity clipped
    first, second = judged(fast(1000.0), STEP_CAP, (0.0, 0.0), (120.0, 0.0))
    assert first.status is Status.AGREE
    assert second.category == Category.CONVENTION
    assert "speed cap 120" in second.reason
    # an answer the cap does not give is not explained by it
    _, wrong = judged(fast(1000.0), STEP_CAP, (0.0, 0.0), (100.0, 0.0))
    assert wrong.category == Category.ERROR


def test_a_cap_before_the_bounce_clips_the_plastic_response_only() -> None:
    # Rapier: the plastic solve gives both 500, capped to 400; the bounce then adds -+500
    first, second = judged(fast(1000.0), BOUNCE_CAP, (-100.0, 0.0), (900.0, 0.0))
    assert {first.category, second.category} == {Category.CONVENTION}
    # the same answer is not what a cap at the end of the step gives
    step = Conventions(rtol=2.0**-21, max_speed=400.0, max_speed_at="step")
    assert judged(fast(1000.0), step, (-100.0, 0.0), (900.0, 0.0))[1].category == (
        Category.ERROR)


def test_free_steps_before_the_contact_cap_the_approach() -> None:
    # met after free steps (resolved_at elsewhere): the approach was capped before the contact
    case = response([0.0, 0.0], [1000.0, 0.0], [3.0, 0.0], [0.0, 0.0])
    later = ((2.0, 0.0), (3.0, 0.0))
    _, second = judged(case, STEP_CAP, (0.0, 0.0), (120.0, 0.0), later)
    assert second.category == Category.CONVENTION


@pytest.mark.parametrize("conv", [Conventions(), Conventions(rtol=2.0**-21)])
def test_no_cap_declared_no_cap_explained(conv: Conventions) -> None:
    assert judged(fast(1000.0), conv, (0.0, 0.0), (120.0, 0.0))[1].category == Category.ERROR


SAMPLED = Conventions(rtol=2.0**-50, time_step=0.002, sampled_contacts=True)


def test_a_contact_between_two_step_starts_gets_no_force() -> None:
    # touching at the start (no force below the margin 0), sliding apart before the next step
    # starts: an engine that samples contacts sees none, and the velocities stay
    graze = response([0.0, 0.0], [2.0**-10, 1.0], [1.0, 0.0], [0.0, -1.0])
    own = (graze.a.velocity, graze.b.velocity)
    verdicts = judged(graze, SAMPLED, own[0], own[1], None)
    assert {v.category for v in verdicts} == {Category.TIMESTEP}
    assert all("no step of 0.002 s starts in between" in v.reason
               for v in verdicts)
    # not sampled: no such rule; a force that was applied: not this rule either
    assert judged(graze, Conventions(time_step=0.002), own[0], own[1], None)[0].category == (
        Category.ERROR)
    pushed = judged(graze, SAMPLED, (0.0, 1.0), (2.0**-10, -1.0), None)
    assert pushed[0].status is Status.AGREE


def test_a_contact_a_step_start_falls_into_is_seen() -> None:
    # head-on at 1 m/s: the overlap lasts far longer than a step; an engine that answers
    # with the bodies' own velocities missed nothing the rule could excuse
    slow = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0])
    verdicts = judged(slow, SAMPLED, (1.0, 0.0), (0.0, 0.0), None)
    assert {v.category for v in verdicts} == {Category.ERROR}
