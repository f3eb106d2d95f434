"""The declared conventions behind a ``convention`` row, read back from its case alone.

A row stores its category and reason, not the convention that fired; :func:`behind` names
it from the kind's rules and the case.  The property below checks that against the rules
themselves: with one convention declared, any row they make a ``convention`` rests on it.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from crosscheck.core.conventions import NATURES, Conventions, Nature, nature_of
from crosscheck.core.model import Category, Observation
from crosscheck.core.schema import AnyCase, ResponseCase
from crosscheck.truth import categories, oracle, scene_rules, toi
from crosscheck.truth.bounds import failed
from crosscheck.truth.convention_fields import behind, nature
from crosscheck.truth.score import judge
from tests.conftest import aabb, response, sphere

coord = st.floats(-2.0, 2.0, allow_nan=False).map(lambda x: round(x, 2))
ONE_EACH = [  # one convention declared otherwise than the textbook, as adapters declare them
    Conventions(touching={"sphere": True}), Conventions(touching={"edge": False}),
    Conventions(negative_extents="absolute"), Conventions(zero_mass="static"),
    Conventions(resolves_separating=False), Conventions(restitution_threshold=1.0),
    Conventions(max_speed=0.5, max_speed_at="step"), Conventions(restitution_model="soft"),
    Conventions(friction=0.5), Conventions(no_value=("float64-textbook",)),
]


@st.composite
def cases(draw: st.DrawFn) -> AnyCase:
    kind = draw(st.sampled_from(["aabb", "sphere", "response"]))
    ca, cb = draw(st.tuples(coord, coord, coord)), draw(st.tuples(coord, coord, coord))
    if kind == "aabb":
        half = draw(st.sampled_from([0.5, -0.5, 1.0]))
        return aabb(list(ca), [half, 0.5, 0.5], list(cb), [0.5, 0.5, 0.5])
    if kind == "sphere":
        return sphere(ca[0], cb[0], ra=draw(st.sampled_from([0.5, -0.5])))
    va, vb = draw(st.tuples(coord, coord, coord)), draw(st.tuples(coord, coord, coord))
    mass = draw(st.sampled_from([0.0, 1.0, 3.0]))
    return response(list(ca), list(va), list(cb), list(vb), ma=mass)


def answers(case: AnyCase) -> list[Observation]:
    """The truth, and answers the declared rules can explain: no bounce (e = 0), each body's
    own velocities, no value at all, and every verdict flipped."""
    if not isinstance(case, ResponseCase):
        exact = oracle.truth(case)
        flipped = None if not isinstance(exact.hit, bool) else not exact.hit
        return [exact, Observation(hit=flipped, distance=float("nan"), normal=(0.0, 0.0, 1.0))]
    plastic = oracle.truth(case.model_copy(update={"restitution": 0.0}))
    return [oracle.truth(case), plastic,
            Observation(v1=case.a.velocity, v2=case.b.velocity),
            Observation(v1=(float("nan"),) * 3, v2=(float("nan"),) * 3)]


@settings(max_examples=300, deadline=None)
@given(cases(), st.sampled_from(ONE_EACH))
def test_a_convention_row_rests_on_the_one_convention_declared(case: AnyCase,
                                                               conv: Conventions) -> None:
    declared = next(name for name in NATURES if getattr(conv, name) != getattr(
        Conventions(), name))
    truth = oracle.truth(case)
    for observation in answers(case):
        for quantity in ("v1", "v2") if isinstance(case, ResponseCase) else (
                "hit", "distance", "normal"):
            value = observation.get(quantity)
            if value is None:
                continue
            verdict = judge(case, conv, quantity, value, truth, observation)
            if verdict.category == Category.CONVENTION:
                assert behind(case, conv, failed(value)) == (declared,), verdict.reason
                assert nature(case, conv, failed(value)) is nature_of(declared)


NAN = float("nan")
RARE = [  # rules the random cases above seldom meet: each case, convention and answer
    (response([0.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0], mb=0.0),
     Conventions(zero_mass="static"), Observation(v1=(-1.0, 0.0, 0.0), v2=(0.0, 0.0, 0.0)),
     "v1", "zero_mass"),
    (response([0.0, 0, 0], [3.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0]),
     Conventions(max_speed=2.0, max_speed_at="step"),
     Observation(v1=(0.0, 0, 0), v2=(2.0, 0.0, 0.0), resolved_at=((0.0, 0, 0), (1.0, 0, 0))),
     "v2", "max_speed"),
    (response([0.0, 0, 0], [1.0, 0, 0], [0.6, 0.8, 0], [0.0, 0, 0]), Conventions(friction=0.5),
     Observation(v1=(0.4, -0.3, 0.0), v2=(0.6, 0.3, 0.0)), "v2", "friction"),
    (sphere(1e9, 1e9 + 1.5), Conventions(no_value=("float32-textbook",)),
     Observation(hit=True, distance=0.5, normal=(NAN, NAN, NAN)), "normal", "no_value"),
]


@pytest.mark.parametrize(("case", "conv", "answer", "quantity", "declared"), RARE,
                         ids=[r[-1] for r in RARE])
def test_each_rule_names_its_convention(case: AnyCase, conv: Conventions, answer: Observation,
                                        quantity: str, declared: str) -> None:
    value = answer.get(quantity)
    assert value is not None
    verdict = judge(case, conv, quantity, value, oracle.truth(case), answer)
    assert verdict.category == Category.CONVENTION
    assert behind(case, conv, failed(value)) == (declared,)


def test_every_convention_a_rule_reads_has_a_declared_nature() -> None:
    read = {*categories.RESPONSE_CONVENTIONS, *categories.DETECTION_CONVENTIONS,
            *toi.CONVENTIONS, *scene_rules.CONVENTIONS}
    assert read <= set(NATURES)
    assert "notes" not in NATURES and "sources" not in NATURES


def test_what_a_row_rests_on_follows_from_its_case() -> None:
    engine = Conventions(zero_mass="static", resolves_separating=False,
                         restitution_threshold=0.2, damping=0.04)
    heavy_wall = response([0.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0], mb=0.0)
    apart = response([0.0, 0, 0], [-1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0])
    slow = response([0.0, 0, 0], [0.05, 0, 0], [1.0, 0, 0], [0.0, 0, 0])
    assert behind(heavy_wall, engine, no_value=False) == ("zero_mass",)
    assert nature(heavy_wall, engine, no_value=False) is Nature.DEFINITION
    assert behind(apart, engine, no_value=False) == ("resolves_separating",)
    assert behind(slow, engine, no_value=False) == ("restitution_threshold",)
    assert nature(slow, engine, no_value=False) is Nature.BEHAVIOUR
    assert nature(slow, engine, no_value=True) is Nature.DEFINITION  # a declared no-value rule
