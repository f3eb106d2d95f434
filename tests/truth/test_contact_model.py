"""Declared soft contact and friction explain a response only when the impulse fits them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation, Status
from crosscheck.truth import oracle
from crosscheck.truth.contact_model import explain
from crosscheck.truth.score import judge
from tests.conftest import response

HEAD_ON = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0])  # (pa, va, pb, vb)
OBLIQUE = response([0.0, 0.0], [1.0, 0.0], [0.8, 0.6], [0.0, 0.0])
SOFT = Conventions(restitution_model="soft")
FRICTION = Conventions(friction=0.5)


def bounce(case: object, e: float, tangential: float = 0.0) -> Observation:
    """Equal unit masses: the impulse along the line of centres for restitution e, plus a
    tangential impulse; momentum kept exactly."""
    a, b = case.a, case.b  # type: ignore[attr-defined]
    line = [y - x for x, y in zip(a.center, b.center, strict=True)]
    length = math.hypot(*line)
    n = [x / length for x in line]
    t = [-n[1], n[0]]
    closing = sum((va - vb) * k for va, vb, k in zip(a.velocity, b.velocity, n, strict=True))
    jn = (1 + e) * closing / 2  # unit masses: reduced mass 1/2
    j = [jn * k + tangential * s for k, s in zip(n, t, strict=True)]
    return Observation(v1=tuple(v - x for v, x in zip(a.velocity, j, strict=True)),
                       v2=tuple(v + x for v, x in zip(b.velocity, j, strict=True)))


def test_a_soft_bounce_with_momentum_kept_is_the_declared_convention() -> None:
    why = explain(HEAD_ON, SOFT, bounce(HEAD_ON, 0.14), 1e-9)
    assert "e' = 0.14" in why and "e = 1" in why and "momentum kept" in why


@pytest.mark.parametrize("e", [1.2, -0.3])
def test_a_bounce_no_soft_contact_gives_is_not_explained(e: float) -> None:
    assert explain(HEAD_ON, SOFT, bounce(HEAD_ON, e), 1e-9) == ""


def test_lost_momentum_is_never_explained() -> None:
    seen = bounce(HEAD_ON, 0.14)
    assert seen.v1 is not None and seen.v2 is not None
    lossy = Observation(v1=seen.v1, v2=(seen.v2[0] * 0.5, seen.v2[1]))
    assert explain(HEAD_ON, SOFT, lossy, 1e-9) == ""


def test_friction_within_mu_times_the_normal_impulse_is_explained_beyond_it_not() -> None:
    closing = 0.8  # A's velocity (1, 0) along the line (0.8, 0.6)
    normal = (1 + 1.0) * closing / 2
    inside = explain(OBLIQUE, FRICTION, bounce(OBLIQUE, 1.0, 0.4 * normal), 1e-9)
    assert "friction 0.5 (declared)" in inside
    assert explain(OBLIQUE, FRICTION, bounce(OBLIQUE, 1.0, 0.6 * normal), 1e-9) == ""
    assert explain(OBLIQUE, Conventions(), bounce(OBLIQUE, 1.0, 0.4 * normal), 1e-9) == ""
    assert explain(OBLIQUE, SOFT, bounce(OBLIQUE, 1.0, 0.4 * normal), 1e-9) == ""


def test_the_judge_files_a_soft_bounce_under_convention_with_its_numbers() -> None:
    truth = oracle.truth(HEAD_ON)
    seen = bounce(HEAD_ON, 0.14)
    for quantity in ("v1", "v2"):
        verdict = judge(HEAD_ON, SOFT, quantity, seen.get(quantity), truth, seen)
        assert verdict.status is Status.DISAGREE and verdict.category == Category.CONVENTION
        assert "e' = 0.14" in verdict.reason
        plain = judge(HEAD_ON, Conventions(), quantity, seen.get(quantity), truth, seen)
        assert plain.category == Category.ERROR


def test_friction_is_judged_from_what_float32_can_record() -> None:
    # B is 1e10 times heavier: its velocity change (1e-10) is below float32's ulp of 1, so a
    # float32 engine reports B's velocity unchanged.  The impulse is read from A, the light
    # body, whose change float32 records: the declared friction still explains it.
    heavy = response([0.0, 0.0], [1.0, 0.5], [3.0, 4.0], [0.0, -1.0], ma=1.0, mb=1e10)
    line, tangent = (0.6, 0.8), (-0.8, 0.6)
    closing = (1.0 - 0.0) * line[0] + (0.5 + 1.0) * line[1]  # approach along the line
    normal = 2.0 * closing  # elastic, B immovable in effect: A's change along the line
    slip = 0.1 * normal  # within friction 0.2 x the normal impulse
    v1 = tuple(float(np.float32(v - normal * n - slip * t))
               for v, n, t in zip((1.0, 0.5), line, tangent, strict=True))
    v2 = tuple(float(np.float32(v + (normal * n + slip * t) / 1e10))
               for v, n, t in zip((0.0, -1.0), line, tangent, strict=True))
    assert v2[1] == -1.0  # float32 cannot hold B's change along y
    seen = Observation(v1=v1, v2=v2)
    f32 = Conventions(friction=0.2, rtol=2.0**-21)
    for quantity in ("v1", "v2"):
        verdict = judge(heavy, f32, quantity, seen.get(quantity), oracle.truth(heavy), seen)
        assert verdict.category == Category.CONVENTION, verdict.reason
        assert "friction 0.2 (declared)" in verdict.reason
    lossy = Observation(v1=(v1[0] + 0.5, v1[1]), v2=v2)  # momentum lost: never explained
    assert explain(heavy, f32, lossy, 2.0**-21 * 1.0) == ""
