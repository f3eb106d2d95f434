"""Reasons never contradict the data of their own row (property test).

Random cases, random declared conventions and random engine answers near the
truth: whatever the verdict, its reason must agree with the numbers.
"""

from __future__ import annotations

import math
import re

from hypothesis import given, settings
from hypothesis import strategies as st

from crosscheck.core.contract import FEATURES, Conventions
from crosscheck.core.model import Category, Observation, Status
from crosscheck.core.schema import AnyCase, ResponseCase
from crosscheck.truth import oracle
from crosscheck.truth.categories import approach_speed, nearest_feature
from crosscheck.truth.score import Verdict, judge
from tests.conftest import aabb, response, sphere

coord = st.floats(-4.0, 4.0, allow_nan=False).map(lambda x: round(x, 3))
size = st.floats(0.05, 2.0, allow_nan=False).map(lambda x: round(x, 3))


@st.composite
def cases(draw: st.DrawFn) -> AnyCase:
    kind = draw(st.sampled_from(["aabb", "sphere", "response"]))
    ca, cb = draw(st.tuples(coord, coord, coord)), draw(st.tuples(coord, coord, coord))
    if kind == "aabb":
        return aabb(list(ca), [draw(size)] * 3, list(cb), [draw(size)] * 3)
    if kind == "sphere":
        return sphere(0.0, 0.0).model_copy(update={
            "a": sphere(0.0, 0.0).a.model_copy(update={"center": ca, "radius": draw(size)}),
            "b": sphere(0.0, 0.0).b.model_copy(update={"center": cb, "radius": draw(size)})})
    va, vb = draw(st.tuples(coord, coord, coord)), draw(st.tuples(coord, coord, coord))
    return response(list(ca), list(va), list(cb), list(vb))


conventions = st.builds(
    Conventions,
    touching=st.dictionaries(st.sampled_from(FEATURES), st.booleans()),
    margins=st.dictionaries(st.sampled_from(FEATURES), st.sampled_from([1e-3, 0.05, 0.5])),
    verdict_margins=st.none() | st.dictionaries(st.sampled_from(FEATURES),
                                                st.sampled_from([1e-3, 0.02, 0.5])),
    rtol=st.sampled_from([0.0, 2.0**-50, 2.0**-21, 1e-3]),
    restitution_threshold=st.sampled_from([0.0, 0.2, 1.0]),
    resolves_separating=st.booleans(),
    zero_mass=st.sampled_from(["", "static"]))


def _nudged(value: object, amount: float) -> object:
    if isinstance(value, bool):
        return not value if amount > 0.5 else value
    if isinstance(value, float):
        return value + amount
    if isinstance(value, tuple):
        moved = [x + amount * (i + 1) for i, x in enumerate(value)]
        length = math.sqrt(sum(x * x for x in moved)) or 1.0
        return tuple(x / length for x in moved) if len(value) == 3 else tuple(moved)
    return value


def _check(case: AnyCase, conv: Conventions, quantity: str, verdict: Verdict) -> None:
    reason = verdict.reason
    if verdict.status.neutral:
        assert verdict.category == "" and reason.startswith(("no defined value", "engine reported"))
        return
    if verdict.status is Status.AGREE:
        assert verdict.error <= verdict.tolerance and verdict.category == ""
        return
    assert verdict.status is Status.DISAGREE and verdict.category in set(Category)
    assert verdict.error > verdict.tolerance or math.isnan(verdict.error)
    if "already separating" in reason:
        assert isinstance(case, ResponseCase) and approach_speed(case) <= 0
    acting = conv.verdict_margin_for if quantity == "hit" else conv.margin_for
    for kind, amount, feature in re.findall(r"(verdict )?margin ([0-9.e+-]+) at a (\w+)",
                                            reason):
        assert (kind == "verdict ") == (quantity == "hit")  # only what acts on the quantity
        assert feature == nearest_feature(case) and acting(feature) > 0
        assert math.isclose(float(amount), acting(feature), rel_tol=1e-3)
    if "margin" in reason:
        assert acting(nearest_feature(case)) > 0 and quantity not in ("v1", "v2")
    for err, limit in re.findall(r"error ([0-9.e+-]+) within the engine's declared tolerance "
                                 r"([0-9.e+-]+)", reason):
        assert float(err) <= float(limit) * 1.001
    beyond = r"error ([0-9.e+-]+) beyond the agree bound [0-9.e+-]+ and "
    for err, limit in re.findall(beyond + r"the engine's declared tolerance ([0-9.e+-]+)",
                                 reason):  # a length or velocity bound the error exceeds
        assert quantity not in ("hit", "normal") and float(err) > float(limit) * 0.999
    for err, limit in re.findall(beyond + r"the tilt ([0-9.e+-]+) rad", reason):
        assert quantity == "normal" and float(err) > float(limit) * 0.999
    for gap, limit in re.findall(r"the \|gap\| ([0-9.e+-]+) beyond the engine's declared "
                                 r"tolerance ([0-9.e+-]+)", reason):
        assert quantity == "hit" and float(gap) >= float(limit) * 0.999
    if verdict.category == Category.TIMESTEP:
        assert isinstance(case, ResponseCase) and verdict.error_at_contact <= verdict.error


@settings(max_examples=400, deadline=None)
@given(cases(), conventions, st.sampled_from([0.0, 1e-12, 1e-4, 0.01, 0.3, 1.0]))
def test_reasons_never_contradict_their_row(case: AnyCase, conv: Conventions,
                                            amount: float) -> None:
    truth = oracle.truth(case)
    for quantity in ("v1", "v2") if isinstance(case, ResponseCase) else ("hit", "distance",
                                                                          "normal"):
        want = truth.get(quantity)
        value = _nudged(want, amount)
        verdict = judge(case, conv, quantity, value, truth, Observation())  # type: ignore[arg-type]
        _check(case, conv, quantity, verdict)
