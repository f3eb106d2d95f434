"""The coal adapters: pinned native behaviour of coal 3.0.3 and the translation.

Each conformance test pins what the engine was measured to do, with the engine fact named,
so that an upgrade that changes it fails here; correctness is judged against the exact
oracle and the declared conventions, never against an engine answer copied here.  NaN and
inf reach coal only in a subprocess (the adapter refuses them), and so does a first box
query with a skewed guess (the box inflation is a static fixed by the process's first call).
"""

from __future__ import annotations

import math
import random
import subprocess
import sys
from typing import Any

import pytest

coal = pytest.importorskip("coal")

import numpy as np  # noqa: E402

import adapters  # noqa: E402
from adapters.coal import (  # noqa: E402
    COLLISION_THRESHOLD,
    DEFAULT_TOLERANCE,
    TUNED_CAP,
    TUNED_FLOOR,
    CoalDefault,
    CoalTuned,
    magnitude,
    tuned_tolerance,
)
from crosscheck.core.contract import Adapter, Prepared  # noqa: E402
from crosscheck.core.geometry import norm  # noqa: E402
from crosscheck.core.model import Category, Status, Undefined  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AnyCase  # noqa: E402
from crosscheck.truth import oracle  # noqa: E402
from crosscheck.truth.categories import allowance  # noqa: E402
from crosscheck.truth.score import judge  # noqa: E402
from tests.adapters.random_pairs import random_box_pair  # noqa: E402
from tests.conftest import aabb, sphere  # noqa: E402

pytestmark = pytest.mark.engine

TUNED, DEFAULT = CoalTuned(), CoalDefault()
BOTH = pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=["coal", "coal-default"])
UNIT_BOX = [1.0, 1.0, 1.0]
ORIGIN = [0.0, 0.0, 0.0]


def ball(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A sphere case (2-D or 3-D) with centres anywhere."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": len(ca),
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def tf(centre: list[float]) -> Any:
    return coal.Transform3s(np.eye(3), np.array(centre, dtype=np.float64))


def distance(a: Any, ca: list[float], b: Any, cb: list[float],
             tolerance: float | None = None) -> tuple[float, Any]:
    """coal's own signed distance and normal, as the adapter does not call it."""
    request = coal.DistanceRequest()
    if tolerance is not None:
        request.gjk_tolerance = request.epa_tolerance = tolerance
    result = coal.DistanceResult()
    value = coal.distance(a, tf(ca), b, tf(cb), request, result)
    return float(value), result.normal


def collides(a: Any, ca: list[float], b: Any, cb: list[float]) -> bool:
    result = coal.CollisionResult()
    coal.collide(a, tf(ca), b, tf(cb), coal.CollisionRequest(), result)
    return bool(result.isCollision())


def box(half: list[float]) -> Any:
    return coal.Box(*[2.0 * h for h in half])


def python(code: str) -> str:
    """What a fresh interpreter prints for ``code`` (a process of its own: see the docstring)."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout


def judged(adapter: Adapter, case: AnyCase, quantity: str) -> Any:
    obs = adapter.observe(case)
    return judge(case, adapter.conventions, quantity, obs.get(quantity), oracle.truth(case), obs)


# --- native behaviour (conformance) ----------------------------------------------------------

def test_box_takes_full_side_lengths() -> None:
    # Box(x, y, z) stores halfSide = side / 2 (geometric_shapes.h).  Box-sphere distance is
    # analytic: a point 3 from the centre of a box of side 2 is 2 away (half-lengths: 1).
    b = coal.Box(2.0, 4.0, 6.0)
    assert b.halfSide.tolist() == [1.0, 2.0, 3.0]
    assert distance(b, ORIGIN, coal.Sphere(0.0), [3.0, 0.0, 0.0])[0] == 2.0


def test_signed_distance_is_negative_in_collision_and_normal_points_a_to_b() -> None:
    # The opposite sign of python-fcl's penetration_depth: coal's Contact carries the
    # signed distance, and DistanceResult.normal points from o1 to o2 (collision_data.h).
    s = coal.Sphere(0.5)
    inside, n_in = distance(s, ORIGIN, s, [-0.75, 0.0, 0.0])
    apart, n_out = distance(s, ORIGIN, s, [-3.0, 0.0, 0.0])
    assert (inside, n_in.tolist()) == (-0.25, [-1.0, 0.0, 0.0])
    assert (apart, n_out.tolist()) == (2.0, [-1.0, 0.0, 0.0])
    result = coal.CollisionResult()
    coal.collide(s, tf(ORIGIN), s, tf([0.75, 0.0, 0.0]), coal.CollisionRequest(), result)
    assert result.getContact(0).penetration_depth == -0.25


def test_the_verdict_counts_gaps_up_to_an_absolute_threshold_of_1e_12() -> None:
    # collision_distance_threshold = Eigen dummy_precision (1e-12), not exposed in Python:
    # touching spheres collide, and so do spheres 2^-41 (4.5e-13) apart; 2^-39 (1.8e-12) not.
    s = coal.Sphere(0.5)
    assert not hasattr(coal.CollisionRequest(), "collision_distance_threshold")
    assert collides(s, ORIGIN, s, [1.0, 0.0, 0.0])
    assert collides(s, ORIGIN, s, [1.0 + 2.0**-41, 0.0, 0.0])
    assert not collides(s, ORIGIN, s, [1.0 + 2.0**-39, 0.0, 0.0])
    assert 2.0**-41 < COLLISION_THRESHOLD < 2.0**-39


def test_sphere_distances_are_analytic_and_coincident_centres_do_not_hang() -> None:
    # sphereSphereDistance: |cb - ca| - ra - rb; normal (1, 0, 0) for coincident centres.
    d, n = distance(coal.Sphere(2.5), ORIGIN, coal.Sphere(2.5), [3.0, 4.0, 0.0])
    assert (d, n.tolist()) == (0.0, [0.6, 0.8, 0.0])
    d, n = distance(coal.Sphere(1.0), [1.0, -2.0, 3.0], coal.Sphere(0.5), [1.0, -2.0, 3.0])
    assert (d, n.tolist()) == (-1.5, [1.0, 0.0, 0.0])


@pytest.mark.parametrize("ha, hb", [(1.0, 1.0), (1.0, 4.0), (4.0, 1.0)])
def test_boxes_are_inflated_by_1e_10_of_the_half_width_on_their_negative_sides(
        ha: float, hb: float) -> None:
    # getShapeSupport(Box): -(1 + 1e-10) x halfSide for a negative direction.  Face-touching
    # boxes overlap by 1e-10 of the half-width of the box whose negative side faces the other:
    # B's when B lies on +x, A's when B lies on -x.
    a, b = box([ha, 1.0, 1.0]), box([hb, 1.0, 1.0])
    right = distance(a, ORIGIN, b, [ha + hb, 0.0, 0.0])[0]
    left = distance(a, ORIGIN, b, [-(ha + hb), 0.0, 0.0])[0]
    assert right == pytest.approx(-1e-10 * hb, rel=1e-6)
    assert left == pytest.approx(-1e-10 * ha, rel=1e-6)
    assert collides(a, ORIGIN, b, [ha + hb, 2.0, 2.0])  # corner touch: collides too


def test_the_inflation_is_fixed_by_the_first_box_support_call_of_the_process() -> None:
    # The factor is a function-level static: a first support direction without a zero
    # component (a skewed cached guess) leaves boxes uninflated for the whole process.  The
    # adapter always uses the default guess (1, 0, 0), whose direction has zeros.
    code = ("import coal, numpy as np\n"
            "B = coal.Box(2.0, 2.0, 2.0)\n"
            "def d(cb, guess=None):\n"
            "    r = coal.DistanceRequest()\n"
            "    if guess is not None:\n"
            "        r.gjk_initial_guess = coal.GJKInitialGuess.CachedGuess\n"
            "        r.cached_gjk_guess = np.array(guess)\n"
            "    t = lambda c: coal.Transform3s(np.eye(3), np.array(c))\n"
            "    return coal.distance(B, t([0.0, 0.0, 0.0]), B, t(cb), r, coal.DistanceResult())\n"
            "d([3.0, 0.5, 0.25], guess=[1.0, 0.7, 0.3])\n"
            "print(repr(d([2.0, 0.0, 0.0])))\n")
    assert float(python(code)) == 0.0
    assert distance(box(UNIT_BOX), ORIGIN, box(UNIT_BOX), [2.0, 0.0, 0.0])[0] < 0.0


def test_gjk_tolerance_is_absolute_a_smaller_gap_reads_as_a_collision() -> None:
    # GJK declares a collision once its ray is shorter than gjk_tolerance (default 1e-6),
    # and EPA then finds no depth: distance 0.  With the tolerance at 1e-12 the gap shows.
    a, b = box(UNIT_BOX), box(UNIT_BOX)
    cb = [2.0 + 2.0**-24, 0.0, 0.0]  # a gap of 6e-8
    assert coal.DistanceRequest().gjk_tolerance == DEFAULT_TOLERANCE
    assert distance(a, ORIGIN, b, cb)[0] == 0.0 and collides(a, ORIGIN, b, cb)
    tight = distance(a, ORIGIN, b, cb, tolerance=1e-12)[0]
    assert tight == pytest.approx(2.0**-24 - 1e-10, abs=1e-12)


def test_tiny_boxes_fail_with_the_lowest_double_and_a_nan_normal() -> None:
    # Below a size of about 1e-7 the support function (direction components within 1e-12
    # of 0 pick the centre) and EPA break down: EPA's failure value, -DBL_MAX, NaN normal.
    k = 1e-9
    d, n = distance(box([k] * 3), ORIGIN, box([k] * 3), [2.0 * k, 0.0, 0.0],
                    tolerance=TUNED_FLOOR)
    assert d == -sys.float_info.max
    assert all(math.isnan(x) for x in n)


def test_non_finite_input_is_answered_wrongly_without_complaint() -> None:
    # Why the adapter refuses it: a NaN box collides at distance 0, a NaN sphere is apart.
    code = ("import coal, numpy as np\n"
            "t = lambda c: coal.Transform3s(np.eye(3), np.array(c))\n"
            "nan = float('nan')\n"
            "B, S = coal.Box(2.0, 2.0, 2.0), coal.Sphere(1.0)\n"
            "for a, ca, b in ((B, [nan, 0.0, 0.0], B), (S, [0.0, nan, 0.0], S)):\n"
            "    r = coal.CollisionResult()\n"
            "    coal.collide(a, t(ca), b, t([0.5, 0.0, 0.0]), coal.CollisionRequest(), r)\n"
            "    d = coal.distance(a, t(ca), b, t([0.5, 0.0, 0.0]), coal.DistanceRequest(),\n"
            "                      coal.DistanceResult())\n"
            "    print(r.isCollision(), d)\n")
    assert python(code).split("\n")[:2] == ["True 0.0", "False nan"]


def test_functors_answer_as_the_free_functions() -> None:
    a, b = box([1.0, 0.5, 0.25]), box([0.5, 0.5, 0.5])
    ta, tb = tf(ORIGIN), tf([1.2, 0.7, -0.3])
    free, functor = coal.DistanceResult(), coal.DistanceResult()
    d_free = coal.distance(a, ta, b, tb, coal.DistanceRequest(), free)
    d_functor = coal.ComputeDistance(a, b)(ta, tb, coal.DistanceRequest(), functor)
    assert (d_free, free.normal.tolist()) == (d_functor, functor.normal.tolist())


# --- translation -------------------------------------------------------------------------

@BOTH
def test_half_widths_become_full_side_lengths(adapter: Adapter) -> None:
    # Half-widths 1 apart by 2.5 along -x: gap 0.5, less the inflation of A's -x side (1e-10).
    obs = adapter.observe(aabb(ORIGIN, UNIT_BOX, [-2.5, 0.0, 0.0], UNIT_BOX))
    assert obs.hit is False and obs.normal == (-1.0, 0.0, 0.0)
    assert obs.distance == pytest.approx(0.5 - 1e-10, abs=1e-15)


@BOTH
@pytest.mark.parametrize("cb, sign", [([-0.75, 0.0, 0.0], -1.0), ([3.0, 0.0, 0.0], 1.0),
                                      ([0.0, 0.0, -3.0], -1.0)], ids=["overlap", "gap", "gap-z"])
def test_sphere_answers_are_signed_and_normal_points_a_to_b(
        adapter: Adapter, cb: list[float], sign: float) -> None:
    case = ball(ORIGIN, 0.5, cb, 0.5)
    obs, truth = adapter.observe(case), oracle.truth(case)
    assert (obs.hit, obs.distance) == (truth.hit, truth.distance)
    axis = next(i for i, x in enumerate(cb) if x)
    assert obs.normal == tuple(sign if i == axis else 0.0 for i in range(3))


@BOTH
def test_2d_answers_are_2d(adapter: Adapter) -> None:
    obs = adapter.observe(aabb([0.0, 0.0], [1.0, 1.0], [0.5, 3.0], [1.0, 1.0]))
    assert obs.hit is False and obs.normal == pytest.approx((0.0, 1.0), abs=1e-15)
    disc = adapter.observe(ball([0.0, 0.0], 2.5, [3.0, 4.0], 2.0))
    assert (disc.hit, disc.distance, disc.normal) == (False, 0.5, (0.6, 0.8))


@BOTH
def test_2d_boxes_never_meet_across_z(adapter: Adapter) -> None:
    # z half-width 2 x the largest half-width: coincident 2-D boxes overlap least along x or
    # y (2), never z (4): the oracle's depth.
    case = aabb([0.0, 0.0], [1.0, 1.0], [0.0, 0.25], [1.0, 1.0])
    obs = adapter.observe(case)
    assert isinstance(obs.distance, float) and isinstance(obs.normal, tuple)
    assert obs.distance == pytest.approx(-1.75, abs=1e-9)
    assert len(obs.normal) == 2 and obs.normal[1] == pytest.approx(1.0)


@BOTH
def test_a_failed_epa_gives_the_distance_as_is_and_an_undefined_normal(adapter: Adapter) -> None:
    k = 1e-9
    case = aabb(ORIGIN, [k] * 3, [2.0 * k, 0.0, 0.0], [k] * 3)
    obs = adapter.observe(case)
    assert obs.distance == -sys.float_info.max
    assert isinstance(obs.normal, Undefined) and "nan" in obs.normal.reason
    # one failure, one category and one reason: the distance and the normal alike
    for quantity in ("distance", "normal"):
        verdict = judged(adapter, case, quantity)
        assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.ERROR)
        assert "1.8e+308" in verdict.reason and "no finite normal" in verdict.reason


@BOTH
@pytest.mark.parametrize("case", [
    aabb([math.nan, 0.0, 0.0], UNIT_BOX, [0.5, 0.0, 0.0], UNIT_BOX, tags=["bad-input"]),
    aabb([0.0, 0.0], [1.0, math.inf], [0.5, 0.0], [1.0, 1.0], tags=["bad-input"]),
    sphere(0.0, 0.5, ra=math.nan, tags=["bad-input"]),
], ids=["nan-centre", "inf-half", "nan-radius"])
def test_non_finite_input_is_refused_as_undefined(adapter: Adapter, case: AnyCase) -> None:
    obs = adapter.observe(case)
    for value in (obs.hit, obs.distance, obs.normal):
        assert isinstance(value, Undefined) and "non-finite" in value.reason


@BOTH
@pytest.mark.parametrize("case", [
    sphere(0.0, 0.7, dim=2), sphere(0.0, 3.0), ball(ORIGIN, 1.0, [0.0, 0.0, 3.0], 1.0),
    aabb(ORIGIN, UNIT_BOX, [1.5, 0.5, -0.25], UNIT_BOX),
    aabb([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [1.0, 1.0]),
], ids=["disc-overlap", "sphere-gap", "sphere-gap-z", "box-overlap", "box-corner-2d"])
def test_query_is_repeatable(adapter: Adapter, case: AnyCase) -> None:
    prepared = adapter.prepare(case)
    try:
        first, second = adapter.query(prepared), adapter.query(prepared)
    finally:
        adapter.release(prepared)
    assert first == second


def test_tuned_tolerance_is_relative_floored_and_capped() -> None:
    small = aabb(ORIGIN, [0.25] * 3, [0.25, 0.0, 0.0], [0.25] * 3)
    big = aabb(ORIGIN, [1e6] * 3, [1e6, 0.0, 0.0], [1e6] * 3)
    huge = aabb(ORIGIN, [1e12] * 3, [0.0, 0.0, 0.0], [1e12] * 3)
    assert (magnitude(small), magnitude(big)) == (0.75, 3e6)
    assert (tuned_tolerance(small), tuned_tolerance(huge)) == (TUNED_FLOOR, TUNED_CAP)
    assert tuned_tolerance(big) == pytest.approx(3e-6)
    offset = aabb([1e15, 0.0, 0.0], UNIT_BOX, [1e15 + 2.0, 0.0, 0.0], UNIT_BOX)
    assert magnitude(offset) == 4.0  # GJK works on the relative transform


@pytest.mark.parametrize("adapter, want", [(TUNED, 1e-12 * 3.0), (DEFAULT, DEFAULT_TOLERANCE)],
                         ids=["coal", "coal-default"])
def test_each_variant_sets_its_tolerance_in_both_requests(adapter: Adapter, want: float) -> None:
    case = aabb(ORIGIN, UNIT_BOX, [1.0, 0.0, 0.0], UNIT_BOX)  # M = 3
    prepared = adapter.prepare(case)
    assert isinstance(prepared, Prepared)
    for request in (prepared.built["collision_request"], prepared.built["distance_request"]):
        assert request.gjk_tolerance == request.epa_tolerance == pytest.approx(want)


def test_tuned_variant_resolves_a_gap_the_default_reads_as_contact() -> None:
    # Oracle: apart by 6e-8.  Default: GJK's 1e-6 makes it a collision at distance 0, within
    # its declared margin; tuned: right within its declared allowance.
    case = aabb(ORIGIN, UNIT_BOX, [2.0 + 2.0**-24, 0.0, 0.0], UNIT_BOX)
    truth = oracle.truth(case)
    assert truth.hit is False
    assert DEFAULT.observe(case).hit is True
    verdict = judged(DEFAULT, case, "hit")
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)
    obs = TUNED.observe(case)
    assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
    assert obs.hit is False
    assert abs(obs.distance - truth.distance) <= allowance(case, TUNED.conventions,
                                                           "distance").total


@pytest.mark.parametrize("scale", [1e-2, 1.0, 1e3])
def test_tuned_boxes_are_right_within_the_declared_allowance(scale: float) -> None:
    # 100 seeded near-touching pairs: the distance within the declared allowance of the
    # oracle's, the verdict right unless the gap is inside it, the normal a unit vector.
    rng = random.Random(7)
    for _ in range(100):
        case = random_box_pair(rng, scale)
        obs, truth = TUNED.observe(case), oracle.truth(case)
        allowed = allowance(case, TUNED.conventions, "distance").total
        assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
        assert abs(obs.distance - truth.distance) <= allowed, case
        assert obs.hit == truth.hit or abs(truth.distance) <= allowed, case
        assert isinstance(obs.normal, tuple) and norm(obs.normal) == pytest.approx(1.0)


@BOTH
def test_negative_sizes_are_read_literally(adapter: Adapter) -> None:
    # negative_extents "": halfSide keeps its sign, a radius is used as given; the answers
    # are the literal textbook's, within the declared allowance.
    assert adapter.conventions.negative_extents == ""
    for case in (aabb([0.0, 0.0], [-1.0, 1.0], [0.5, 0.0], [1.0, 1.0]),
                 aabb(ORIGIN, [-1.0, 1.0, 1.0], [1.0, 0.0, 0.0], UNIT_BOX),
                 sphere(0.0, 0.75, ra=1.0, rb=-0.5)):
        obs, truth = adapter.observe(case), oracle.truth(case)
        allowed = allowance(case, adapter.conventions, "distance").total
        assert obs.hit == truth.hit and isinstance(obs.distance, float)
        assert isinstance(truth.distance, float) and abs(obs.distance - truth.distance) <= allowed


@BOTH
def test_declared_conventions_categorise_touching(adapter: Adapter) -> None:
    # Touching spheres collide: a convention.  Touching boxes collide, as the textbook says;
    # a face touch reads -1e-10 (the inflation): within rtol 2e-10 x the size, a tolerance.
    verdict = judged(adapter, sphere(0.0, 1.0), "hit")
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)
    for cb in ([2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [2.0, 2.0, 2.0]):  # face, edge, corner
        assert judged(adapter, aabb(ORIGIN, UNIT_BOX, cb, UNIT_BOX), "hit").status is Status.AGREE
    verdict = judged(adapter, aabb(ORIGIN, UNIT_BOX, [2.0, 0.0, 0.0], UNIT_BOX), "distance")
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)


def test_registry_availability_and_declarations() -> None:
    assert (type(adapters.get("coal")), type(adapters.get("coal-default"))) == (CoalTuned,
                                                                               CoalDefault)
    assert TUNED.available() is None and TUNED.version() == "3.0.3"
    for adapter, box_margin in ((TUNED, TUNED_FLOOR), (DEFAULT, DEFAULT_TOLERANCE)):
        conv = adapter.conventions
        assert conv.box_extents.startswith("full")
        assert all(conv.touching_is_contact(f) for f in ("sphere", "face", "edge", "corner"))
        # the collision threshold acts on the verdict alone; the GJK/EPA tolerance on both
        assert conv.verdict_margin_for("sphere") == COLLISION_THRESHOLD
        assert conv.verdict_margin_for("edge") == box_margin + COLLISION_THRESHOLD
        assert conv.margin_for("sphere") == 0.0 and conv.margin_for("edge") == box_margin
        assert conv.no_value == ()
        assert conv.rtol >= math.sqrt(3) * 1e-10
        assert (conv.time_step, conv.damping, conv.zero_mass) == (None, 0.0, "")
        assert adapter.known_hang(sphere(0.0, 0.0)) is None
