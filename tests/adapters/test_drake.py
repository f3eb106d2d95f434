"""The Drake adapter: pinned native behaviour of Drake 1.51.1 and the translation.

Each conformance test pins what the engine was measured to do, with the documented fact
named (adapters/drake/__init__.py cites the sources), so that an upgrade that changes it fails
here; correctness is judged against the exact oracle and the declared conventions, never
against an engine answer copied here.
"""

from __future__ import annotations

import math
import random
from typing import Any

import pytest

pytest.importorskip("pydrake")

import numpy as np
from pydrake.geometry import Box, Sphere

import adapters
from adapters.drake import (
    CLAIMS,
    DISTANCE_TOLERANCE,
    OSCULATION,
    Drake,
    refusal,
)
from adapters.drake import calls as drake_calls
from crosscheck.core.contract import Prepared
from crosscheck.core.geometry import norm
from crosscheck.core.model import Category, Kind, Status
from crosscheck.core.schema import CASE_ADAPTER, AabbCase, AnyCase, PairCase
from crosscheck.truth import oracle
from crosscheck.truth.categories import allowance
from crosscheck.truth.score import judge
from tests.adapters.random_pairs import random_box_pair
from tests.conftest import aabb, sphere

pytestmark = pytest.mark.engine

DRAKE = Drake()
ORIGIN = [0.0, 0.0, 0.0]
UNIT = [1.0, 1.0, 1.0]


def ball(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A 3-D sphere case with centres anywhere."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": 3,
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def native(case: PairCase) -> dict[str, Any]:
    """Drake's own answers for ``case`` through the calls module: the signed-distance pair
    and the penetration pairs, with whether Drake's ``id_A`` is the case's A."""
    inputs = DRAKE.call(case).inputs
    built = (drake_calls.boxes(**inputs) if isinstance(case, AabbCase)
             else drake_calls.spheres(**inputs))
    try:
        query = built["scene"].get_query_output_port().Eval(built["context"])
        (pair,) = query.ComputeSignedDistancePairwiseClosestPoints()
        return {"pair": pair, "a_first": pair.id_A == built["ids"][0],
                "penetrations": query.ComputePointPairPenetration()}
    finally:
        drake_calls.release(built)


def judged(case: AnyCase, quantity: str) -> Any:
    obs = DRAKE.observe(case)
    return judge(case, DRAKE.conventions, quantity, obs.get(quantity), oracle.truth(case), obs)


def unit(rng: random.Random) -> list[float]:
    while True:
        v = [rng.gauss(0.0, 1.0) for _ in range(3)]
        length = math.sqrt(sum(x * x for x in v))
        if length > 1e-3:
            return [x / length for x in v]


# --- native behaviour (conformance) ----------------------------------------------------------

def test_box_takes_full_widths() -> None:
    # Box(width, depth, height): the dimensions along x, y, z (shape_specification.h).
    b = Box(2.0, 4.0, 6.0)
    assert (b.width(), b.depth(), b.height()) == (2.0, 4.0, 6.0)
    # half-widths 1 and a centre 3 apart along y: the gap is 1 (full width 2 per box)
    obs = DRAKE.observe(aabb(ORIGIN, UNIT, [0.0, 3.0, 0.0], UNIT))
    assert (obs.hit, obs.distance) == (False, 1.0)


def test_nhat_points_from_b_to_a() -> None:
    # SignedDistancePair::nhat_BA_W "point[s] outward from B's surface" toward A.
    seen = native(ball([0.0, 0.0, 0.0], 0.5, [3.0, 0.0, 0.0], 0.5))
    pair = seen["pair"]
    from_b_to_a = -1.0 if seen["a_first"] else 1.0  # A at x = 0, B at x = 3
    assert np.allclose(pair.nhat_BA_W, [from_b_to_a, 0.0, 0.0])
    assert pair.distance == 2.0


def test_signed_distance_is_negative_overlapping_and_the_sphere_depth_is_its_negation() -> None:
    # phi <= 0 "can be interpreted as the negative penetration depth" (query_object.h); for a
    # sphere pair both queries compute r_A - phi_B(c_A), so the depth negates the distance.
    for cb, ra, rb in (([0.75, 0.1, -0.2], 0.5, 0.5), ([0.3, 0.2, 0.1], 1.25, 0.7)):
        seen = native(ball(ORIGIN, ra, cb, rb))
        (penetration,) = seen["penetrations"]
        assert seen["pair"].distance < 0
        assert penetration.depth == -seen["pair"].distance


def test_touching_spheres_penetrate_at_depth_zero_touching_boxes_do_not() -> None:
    # Spheres: reported when depth >= 0; boxes (FCL collide): dropped when depth <= DBL_EPSILON
    # (penetration_as_point_pair_callback.cc).
    (touch,) = native(ball(ORIGIN, 0.25, [0.6, 0.8, 0.0], 0.75))["penetrations"]
    assert touch.depth == 0.0
    for cb in ([2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [2.0, 2.0, 2.0]):  # face, edge, corner
        seen = native(aabb(ORIGIN, UNIT, cb, UNIT))
        assert seen["penetrations"] == [] and seen["pair"].distance == 0.0


@pytest.mark.parametrize("half", [1.0, 0.5])
def test_a_box_overlap_of_dbl_epsilon_is_no_penetration(half: float) -> None:
    # "within an epsilon of osculation": depth <= std::numeric_limits<double>::epsilon().
    h = [half] * 3
    at = 2.0 * half
    assert native(aabb(ORIGIN, h, [at - OSCULATION, 0.1, 0.2], h))["penetrations"] == []
    assert len(native(aabb(ORIGIN, h, [at - 2 * OSCULATION, 0.1, 0.2], h))["penetrations"]) == 1


def test_invalid_sizes_are_refused_by_drake_as_documented() -> None:
    # "@throws std::exception if any measure is not finite positive" / "if radius is not
    # finite *non-negative*" (shape_specification.h); pydrake raises it as SystemExit.
    for make in (lambda: Box(0.0, 1.0, 1.0), lambda: Box(-1.0, 1.0, 1.0),
                 lambda: Box(math.inf, 1.0, 1.0), lambda: Sphere(-0.5),
                 lambda: Sphere(math.nan)):
        with pytest.raises(SystemExit, match="Failure at"):
            make()
    assert Sphere(0.0).radius() == 0.0  # "a zero radius is considered valid"


def test_non_finite_centres_make_drake_raise() -> None:
    # SceneGraph's pose check (scene_graph.cc): a RuntimeError, an error row as a user gets.
    for centre in ([math.nan, 0.0, 0.0], [0.0, -math.inf, 0.0]):
        with pytest.raises(RuntimeError, match="non-finite value"):
            DRAKE.observe(ball(centre, 1.0, [0.5, 0.0, 0.0], 1.0))


def test_a_failed_drake_demand_is_a_runtime_error_not_an_exit() -> None:
    # A DRAKE_DEMAND in the box-box gradient at touching (distance_to_shape_touching.cc)
    # fails on this case of the suite (cases/cover.toml); pydrake's SystemExit would end the
    # worker, the calls module raises it as RuntimeError.
    case = aabb([1048576.0, 1048576.0, 1048576.0000009537],
                [9.313225746154785e-10, 9.313225746154785e-10, 7.275957614183426e-12],
                [1048576.0, 1048576.0, 1048576.0],
                [9.5367431640625e-07, 7.450580596923828e-09, 9.5367431640625e-07])
    with pytest.raises(RuntimeError, match="Drake's internal check failed"):
        DRAKE.observe(case)


# --- translation ---------------------------------------------------------------------------

@pytest.mark.parametrize("case", [
    aabb(ORIGIN, UNIT, [0.0, 0.0, 0.0], [0.0, 1.0, 1.0]),
    aabb(ORIGIN, [-1.0, 1.0, 1.0], [1.0, 0.0, 0.0], UNIT),
    aabb(ORIGIN, UNIT, [1.0, 0.0, 0.0], [1.0, math.inf, 1.0]),
    sphere(0.0, 0.75, ra=1.0, rb=-0.5),
    sphere(0.0, 0.75, ra=math.nan),
], ids=["zero-half", "negative-half", "inf-half", "negative-radius", "nan-radius"])
def test_documented_invalid_sizes_are_refused(case: AnyCase) -> None:
    assert isinstance(case, PairCase) and refusal(case)
    with pytest.raises(ValueError, match="Drake documents"):
        DRAKE.prepare(case)


def test_a_zero_radius_is_passed() -> None:
    case = sphere(0.0, 1.5, ra=0.0, rb=0.5)
    obs, truth = DRAKE.observe(case), oracle.truth(case)
    assert (obs.hit, obs.distance) == (truth.hit, truth.distance)


@pytest.mark.parametrize("scale", [1e-2, 1.0, 1e2])
def test_spheres_agree_with_the_oracle_in_every_direction(scale: float) -> None:
    # 100 seeded pairs per scale: random directions, radii and gaps (overlaps, near touches,
    # separations): distance within the declared allowance, the verdict right unless the
    # pair touches within it, the normal judged agree or tolerance.
    rng = random.Random(11)
    for _ in range(100):
        ra, rb = rng.uniform(0.1, 2.0) * scale, rng.uniform(0.1, 2.0) * scale
        gap = (ra + rb) * rng.choice([-0.5, -1e-3, -1e-9, 1e-9, 1e-3, 0.5, 3.0])
        ca = [rng.uniform(-1.0, 1.0) * scale for _ in range(3)]
        cb = [c + (ra + rb + gap) * u for c, u in zip(ca, unit(rng), strict=True)]
        case = ball(ca, ra, cb, rb)
        obs, truth = DRAKE.observe(case), oracle.truth(case)
        allowed = allowance(case, DRAKE.conventions, "distance").total
        assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
        assert abs(obs.distance - truth.distance) <= allowed, case
        assert obs.hit == truth.hit or abs(truth.distance) <= allowed, case
        assert judged(case, "normal").category is not Category.ERROR, case


@pytest.mark.parametrize("scale", [1e-2, 1.0, 1e2])
def test_boxes_agree_with_the_oracle_within_the_declared_allowance(scale: float) -> None:
    rng = random.Random(7)
    for _ in range(100):
        case = random_box_pair(rng, scale)
        obs, truth = DRAKE.observe(case), oracle.truth(case)
        allowed = allowance(case, DRAKE.conventions, "distance").total
        assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
        assert abs(obs.distance - truth.distance) <= allowed, case
        assert obs.hit == truth.hit or abs(truth.distance) <= allowed, case
        assert isinstance(obs.normal, tuple) and norm(obs.normal) == pytest.approx(1.0)
        for quantity in ("hit", "distance"):
            assert judged(case, quantity).category is not Category.ERROR, (case, quantity)
        normal = judged(case, "normal")
        assert (normal.category is not Category.ERROR
                or normal.reason.startswith("engine normal is not a unit vector")), case


def test_box_normals_are_not_always_unit_vectors() -> None:
    # A box-box normal away from touching is (p_WCa - p_WCb) / distance
    # (distance_to_shape_callback.cc): with GJK's witness points it is not always of unit
    # length, though SignedDistancePair documents nhat_BA_W as "always unit length".  An
    # engine fault (error rows), pinned: its direction is right, its length is not.
    rng = random.Random(7)
    lengths = []
    for _ in range(100):
        case = random_box_pair(rng, 1.0)
        obs, truth = DRAKE.observe(case), oracle.truth(case)
        assert isinstance(obs.normal, tuple)
        lengths.append(norm(obs.normal))
        if isinstance(truth.normal, tuple):
            direction = tuple(x / norm(obs.normal) for x in obs.normal)
            assert direction == pytest.approx(truth.normal, abs=1e-6), case
    assert max(abs(length - 1.0) for length in lengths) > 1e-12


@pytest.mark.parametrize("cb", [[2.5, 0.0, 0.0], [-2.5, 0.0, 0.0], [0.0, 2.5, 0.0],
                                [0.0, -2.5, 0.0], [0.0, 0.0, 2.5], [0.0, 0.0, -2.5],
                                [1.5, 0.2, 0.1], [0.1, -0.3, -1.25]])
def test_box_normals_point_from_a_to_b_as_the_oracle(cb: list[float]) -> None:
    case = aabb(ORIGIN, UNIT, cb, UNIT)
    obs, truth = DRAKE.observe(case), oracle.truth(case)
    assert isinstance(obs.normal, tuple) and isinstance(truth.normal, tuple)
    assert obs.normal == pytest.approx(truth.normal, abs=1e-12)
    assert (obs.hit, obs.distance) == (truth.hit, truth.distance)


def test_declared_conventions_categorise_touching() -> None:
    # Touching spheres collide (declared against the textbook): a convention; touching
    # boxes do not (declared against the textbook): a convention for face, edge, corner.
    verdict = judged(sphere(0.0, 1.0), "hit")
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)
    for cb in ([2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [2.0, 2.0, 2.0]):
        case = aabb(ORIGIN, UNIT, cb, UNIT)
        assert DRAKE.observe(case).distance == 0.0
        verdict = judged(case, "hit")
        assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)
    # an overlap of DBL_EPSILON reads as no contact: within the verdict's declared margin
    verdict = judged(aabb(ORIGIN, UNIT, [2.0 - OSCULATION, 0.5, 0.0], UNIT), "hit")
    assert verdict.status is Status.DISAGREE and verdict.category is not Category.ERROR


@pytest.mark.parametrize("case", [
    sphere(0.0, 0.7), sphere(0.0, 3.0), ball(ORIGIN, 1.0, [0.0, 0.0, 3.0], 1.0),
    aabb(ORIGIN, UNIT, [1.5, 0.5, -0.25], UNIT), aabb(ORIGIN, UNIT, [2.0, 2.0, 2.0], UNIT),
], ids=["sphere-overlap", "sphere-gap", "sphere-gap-z", "box-overlap", "box-corner"])
def test_query_is_repeatable(case: AnyCase) -> None:
    prepared = DRAKE.prepare(case)
    try:
        first, second = DRAKE.query(prepared), DRAKE.query(prepared)
    finally:
        DRAKE.release(prepared)
    assert first == second


def test_reused_scenes_answer_as_new_ones(monkeypatch: pytest.MonkeyPatch) -> None:
    # ChangeShape and a new pose on an idle scene give what a scene built for the case gives.
    rng = random.Random(3)
    cases: list[AnyCase] = [random_box_pair(rng, 1.0) for _ in range(20)]
    cases += [ball(ORIGIN, rng.uniform(0.1, 2.0), unit(rng), rng.uniform(0.1, 2.0))
              for _ in range(20)]
    order = cases + cases[::-1] + cases[::3]
    reused = [repr(DRAKE.observe(case)) for case in order]
    monkeypatch.setattr(drake_calls, "IDLE_LIMIT", 0)
    monkeypatch.setattr(drake_calls, "_IDLE", {})
    fresh = [repr(DRAKE.observe(case)) for case in order]
    assert reused == fresh


def test_release_keeps_a_scene_idle_and_the_next_case_takes_it() -> None:
    first = DRAKE.prepare(aabb(ORIGIN, UNIT, [3.0, 0.0, 0.0], UNIT))
    assert isinstance(first, Prepared)
    DRAKE.release(first)
    second = DRAKE.prepare(aabb(ORIGIN, [0.5, 1.0, 2.0], [0.0, 3.0, 0.0], UNIT))
    assert isinstance(second, Prepared)
    try:
        assert second.built is first.built
        assert second.built["sizes"] == ((1.0, 2.0, 4.0), (2.0, 2.0, 2.0))
    finally:
        DRAKE.release(second)


def test_claims_are_drakes_tables_for_the_suites_pairs() -> None:
    # Table 4 (signed distance) Sphere-Sphere 6e-15 and Box-Box 4e-15; Table 1
    # (penetration) Sphere-Sphere 5e-15; the regime a band around 20 cm and 2 mm.
    assert {(c.kinds, c.bound) for c in CLAIMS} == {
        (("sphere",), 6e-15), (("aabb",), 4e-15), (("sphere",), 5e-15)}
    for claim in DRAKE.claims:
        assert claim.quantity == "distance" and claim.dims == (3,)
        assert claim.in_gap(-2e-3) and not claim.in_gap(0.0) and not claim.in_gap(1.0)
        assert claim.in_size(0.2 if claim.kinds == ("sphere",) else 0.1)
        assert claim.source.startswith("https://github.com/RobotLocomotion/drake/blob/v1.51.1/")


@pytest.mark.parametrize("gap", [-2e-3, 2e-3])
def test_a_claimed_configuration_is_within_drakes_published_bound(gap: float) -> None:
    # Drake's characterised configuration, axis-aligned: spheres of radius 0.2 m, boxes of
    # largest half-width 0.1 m, 2 mm apart or overlapping, in a few directions.
    rng = random.Random(5)
    for _ in range(20):
        u = unit(rng)
        spheres = ball(ORIGIN, 0.2, [(0.4 + gap) * x for x in u], 0.2)
        ha, hb = [0.1, 0.038, 0.073], [0.037, 0.1, 0.043]
        axis = rng.randrange(3)
        cb = [0.0, 0.0, 0.0]
        cb[axis] = rng.choice([-1.0, 1.0]) * (ha[axis] + hb[axis] + gap)
        for case in (spheres, aabb(ORIGIN, ha, cb, hb)):
            obs, truth = DRAKE.observe(case), oracle.truth(case)
            assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
            bound = max(c.bound for c in CLAIMS if case.kind in c.kinds and c.in_gap(gap))
            assert abs(obs.distance - truth.distance) <= bound, case


def test_registry_availability_and_declarations() -> None:
    assert type(adapters.get("drake")) is Drake
    assert DRAKE.available() is None and DRAKE.version() == "1.51.1"
    assert DRAKE.capabilities == frozenset({(Kind.AABB, 3), (Kind.SPHERE, 3)})
    assert DRAKE.unsupported(sphere(0.0, 1.0, dim=2)) is not None
    conv = DRAKE.conventions
    assert conv.box_extents.startswith("full") and "flipped" in conv.normal
    assert conv.touching_is_contact("sphere")
    assert not any(conv.touching_is_contact(f) for f in ("face", "edge", "corner"))
    assert conv.verdict_margin_for("face") == OSCULATION and conv.verdict_margin_for(
        "sphere") == 0.0
    assert conv.margin_for("corner") == DISTANCE_TOLERANCE and conv.margin_for("sphere") == 0
    assert conv.no_value == ("float64-textbook",)
    assert (conv.time_step, conv.damping, conv.zero_mass, conv.negative_extents) == (
        None, 0.0, "", "")
    assert all(s.startswith(("https://github.com/RobotLocomotion/drake/blob/v1.51.1/",
                             "https://drake.mit.edu/")) for s in conv.sources)
