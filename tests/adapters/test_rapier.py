"""The rapier adapters: pinned native behaviour of rapier3d 0.36.1 (f32) and the translation.

The conformance tests call rapier3d directly and pin what the adapters rely on, each with
the engine fact named, so that an upgrade that changes it fails here.  Expected values come
from the case's geometry, the exact oracle or a declared rule, never from an engine run.
The scene tests (the scene calls of ``adapters/rapier/calls.py``) are at the end; with them
the module is over 400 lines: one engine's pinned behaviour, kept in the one test module this
engine has.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

rp = pytest.importorskip("rapier3d")

import adapters  # noqa: E402
from adapters import rapier as re_  # noqa: E402
from adapters.rapier import RapierDefault, RapierTuned  # noqa: E402
from crosscheck.core.geometry import norm  # noqa: E402
from crosscheck.core.model import Category, Observation, Status  # noqa: E402
from crosscheck.core.options import RunOptions  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, ResponseCase  # noqa: E402
from crosscheck.results.run import read_results  # noqa: E402
from crosscheck.results.store import ResultsStore  # noqa: E402
from crosscheck.run.runner import run  # noqa: E402
from crosscheck.truth import oracle  # noqa: E402
from crosscheck.truth.bounds import error_of  # noqa: E402
from crosscheck.truth.categories import length_scale, velocity_scale  # noqa: E402
from crosscheck.truth.score import judge  # noqa: E402
from tests.adapters.scene_calls import SceneCalls  # noqa: E402
from tests.conftest import aabb, response, sphere  # noqa: E402

pytestmark = pytest.mark.engine

TUNED, DEFAULT = RapierTuned(), RapierDefault()
F32_EPSILON = 2.0**-23
EVERY = rp.ActiveCollisionTypes.all()


def ball(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A sphere case (2-D or 3-D) with centres anywhere."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": len(ca),
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def moving(ca: list[float], va: list[float], cb: list[float], vb: list[float], radius: float,
           mb: float = 1.0) -> AnyCase:
    """A response case with both radii ``radius`` (A of mass 1)."""
    return CASE_ADAPTER.validate_python({
        "id": "r", "description": "d", "kind": "sphere_response", "dim": len(ca),
        "a": {"center": ca, "radius": radius, "mass": 1.0, "velocity": va},
        "b": {"center": cb, "radius": radius, "mass": mb, "velocity": vb}})


def pair(shape_a: Any, ca: tuple[float, ...], shape_b: Any, cb: tuple[float, ...],
         prediction: float, types: Any = EVERY) -> Any:
    """rapier's own narrow-phase pair of two standalone colliders (None: never paired)."""
    colliders = rp.ColliderSet()
    ha = colliders.insert(rp.Collider.new(shape_a).translation(ca).active_collision_types(types))
    hb = colliders.insert(rp.Collider.new(shape_b).translation(cb).active_collision_types(types))
    narrow = rp.NarrowPhase()
    rp.CollisionPipeline().step(prediction, rp.IslandManager(), rp.BroadPhaseBvh(), narrow,
                                rp.RigidBodySet(), colliders)
    return narrow.contact_pair(ha, hb)


def in_contact(*args: Any) -> bool:
    found = pair(*args)
    return found is not None and bool(found.has_any_active_contact)


def deepest(found: Any) -> float:
    return min(point.dist for manifold in found.manifolds for point in manifold.points)


def velocity_error(adapter: Any, case: AnyCase) -> float:
    """The larger velocity error against the oracle, relative to the case's speed."""
    assert isinstance(case, ResponseCase)
    obs, truth = adapter.observe(case), oracle.truth(case)
    return max(error_of(q, obs.get(q), truth.get(q)) for q in ("v1", "v2")) / velocity_scale(case)


# --- native behaviour (conformance) ----------------------------------------------------------

def test_standalone_colliders_pair_only_with_every_collision_type() -> None:
    # A collider without a body is fixed; the default types leave fixed-fixed pairs out.
    ball_a, ball_b = rp.SharedShape.ball(0.5), rp.SharedShape.ball(0.5)
    default = rp.ActiveCollisionTypes.default_types()
    assert pair(ball_a, (0.0, 0.0, 0.0), ball_b, (0.75, 0.0, 0.0), 0.0, default) is None
    assert in_contact(ball_a, (0.0, 0.0, 0.0), ball_b, (0.75, 0.0, 0.0), 0.0)


def test_default_prediction_distance_and_step_are_the_declared_ones() -> None:
    params = rp.IntegrationParameters()
    assert params.prediction_distance() == re_.DEFAULT_PREDICTION == DEFAULT.prediction
    assert params.dt == re_.DEFAULT_DT == DEFAULT.conventions.time_step
    # the prediction distance is the verdict's threshold: it acts on hit alone
    assert DEFAULT.conventions.verdict_margins == dict.fromkeys(
        ("sphere", "face", "edge", "corner"), params.prediction_distance())
    assert DEFAULT.conventions.margins == {}


def test_the_prediction_distance_decides_the_verdict_only() -> None:
    # Both variants read the distance and normal from the same wide pass: a pair 0.01 apart
    # is contact at prediction 0.02 and apart at 0, with the same distance and normal.
    case = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.01, 0.0, 0.0], [0.5, 0.5, 0.5])
    tuned, default = TUNED.observe(case), DEFAULT.observe(case)
    assert (tuned.hit, default.hit) == (False, True)
    assert (tuned.distance, tuned.normal) == (default.distance, default.normal)
    truth = oracle.truth(case)
    far = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.005, 0.0, 0.0], [0.5, 0.5, 0.5])
    verdict = judge(far, DEFAULT.conventions, "distance", 0.0, oracle.truth(far))
    assert verdict.category == Category.ERROR and "margin" not in verdict.reason
    hit = judge(case, DEFAULT.conventions, "hit", True, truth)
    assert hit.category == Category.TOLERANCE and "verdict margin 0.02" in hit.reason


def test_the_default_speed_cap_acts_before_the_bounce_as_declared() -> None:
    # normalized_max_linear_velocity x length_unit caps a body after each solver substep;
    # the restitution pass adds the bounce after it (contact_constraint_element.rs).
    params = rp.IntegrationParameters()
    cap = params.normalized_max_linear_velocity * params.length_unit
    assert DEFAULT.conventions.max_speed == cap and TUNED.conventions.max_speed is None
    assert DEFAULT.conventions.max_speed_at == "before restitution"
    for speed, e, mb in ((1000.0, 1.0, 1.0), (3000.0, 1.0, 1.0), (1000.0, 0.5, 2.0)):
        case = moving([0.0, 0.0, 0.0], [speed, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                      0.5, mb=mb).model_copy(update={"restitution": e})
        obs, truth = DEFAULT.observe(case), oracle.truth(case)
        for quantity in ("v1", "v2"):
            verdict = judge(case, DEFAULT.conventions, quantity, obs.get(quantity), truth, obs)
            assert verdict.status in (Status.AGREE, Status.DISAGREE)
            if verdict.status is Status.DISAGREE:
                assert verdict.category == Category.CONVENTION, verdict.reason
                assert "speed cap 400" in verdict.reason
        assert velocity_error(TUNED, case) <= TUNED.conventions.rtol  # no cap: the textbook


@pytest.mark.parametrize("shape, cb", [
    (rp.SharedShape.ball(0.5), (1.0, 0.0, 0.0)),
    (rp.SharedShape.cuboid(1.0, 1.0, 1.0), (2.0, 0.0, 0.0)),
    (rp.SharedShape.cuboid(1.0, 1.0, 1.0), (2.0, 2.0, 0.0)),
    (rp.SharedShape.cuboid(1.0, 1.0, 1.0), (2.0, 2.0, 2.0)),
], ids=["sphere", "face", "edge", "corner"])
def test_touching_is_apart_at_prediction_zero_and_contact_within_prediction(
        shape: Any, cb: tuple[float, float, float]) -> None:
    # A contact needs dist < prediction (strict): the touching rule of both variants.
    assert not in_contact(shape, (0.0, 0.0, 0.0), shape, cb, 0.0)
    assert in_contact(shape, (0.0, 0.0, 0.0), shape, cb, re_.DEFAULT_PREDICTION)


def test_a_gap_below_the_default_prediction_distance_is_contact() -> None:
    # 0.01 apart is contact at 0.02: the default variant's declared margin.
    shape = rp.SharedShape.ball(0.5)
    assert in_contact(shape, (0.0, 0.0, 0.0), shape, (1.01, 0.0, 0.0), re_.DEFAULT_PREDICTION)
    assert not in_contact(shape, (0.0, 0.0, 0.0), shape, (1.03, 0.0, 0.0),
                          re_.DEFAULT_PREDICTION)


def test_cuboid_takes_half_extents() -> None:
    # cuboid(1, 1, 1) at 0 and 2.5: a gap of 0.5 with half-extents (full sides would overlap).
    cube = rp.SharedShape.cuboid(1.0, 1.0, 1.0)
    assert deepest(pair(cube, (0.0, 0.0, 0.0), cube, (2.5, 0.0, 0.0), 10.0)) == 0.5


def test_the_manifold_normal_points_from_collider1_to_collider2() -> None:
    shape = rp.SharedShape.ball(0.5)
    found = pair(shape, (0.0, 0.0, 0.0), shape, (-0.75, 0.0, 0.0), 0.0)
    assert found.collider1 == rp.ColliderHandle(0, 0)
    assert found.manifolds[0].data.normal.to_tuple() == (-1.0, 0.0, 0.0)


def test_nan_and_infinite_geometry_are_ignored_without_a_word() -> None:
    # Why the adapter refuses them: rapier forms no pair, which reads as "apart".
    shape = rp.SharedShape.ball(1.0)
    assert pair(shape, (0.0, math.nan, 0.0), shape, (0.0, 0.0, 0.0), 0.0) is None
    assert pair(rp.SharedShape.ball(math.inf), (0.0, 0.0, 0.0), shape, (10.0, 0.0, 0.0),
                0.0) is None


@pytest.mark.parametrize("half", [1e-4, 1e-3])
def test_small_boxes_collide_only_if_a_face_area_exceeds_f32_epsilon(half: float) -> None:
    # parry skips a face whose unnormalised normal (4 hx hy) is relative_eq to 0 (f32::EPSILON):
    # overlapping cubes of half-width 1e-4 (4e-8) never collide, 1e-3 (4e-6) do.
    cube = rp.SharedShape.cuboid(half, half, half)
    hit = in_contact(cube, (0.0, 0.0, 0.0), cube, (1.8 * half, 0.5 * half, 0.0), 0.0)
    assert hit == (4.0 * half * half > F32_EPSILON)


def test_negative_radius_reads_literally() -> None:
    # |d| - ra - rb as given: 0.75 - 1 - (-0.5) = 0.25 (negative_extents "").
    found = pair(rp.SharedShape.ball(1.0), (0.0, 0.0, 0.0), rp.SharedShape.ball(-0.5),
                 (0.75, 0.0, 0.0), 10.0)
    assert deepest(found) == 0.75 - 1.0 + 0.5


@pytest.mark.parametrize("rule, e_a, e_b, want", [
    (None, 0.5, 1.0, 0.75),  # Average, rapier's default
    (rp.CoefficientCombineRule.MULTIPLY, 0.5, 1.0, 0.5),
], ids=["average-default", "multiply"])
def test_restitution_combine_rules(rule: Any, e_a: float, e_b: float, want: float) -> None:
    # Equal masses head-on at +-1, touching: the bounce is the combined e (speeds -+e).
    world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
    bodies = []
    for x, v, e in ((0.0, 1.0, e_a), (1.0, -1.0, e_b)):
        collider = rp.Collider.ball(0.5).mass(1.0).friction(0.0).restitution(e)
        if rule is not None:
            collider = collider.restitution_combine_rule(rule)
        handle = world.add_body(rp.RigidBody.dynamic().translation((x, 0.0, 0.0))
                                .linvel((v, 0.0, 0.0)), [collider])
        bodies.append(world.rigid_bodies[handle])
    world.step()
    assert bodies[0].linvel.x == pytest.approx(-want, abs=1e-6)
    assert bodies[1].linvel.x == pytest.approx(want, abs=1e-6)


def test_default_speed_cap_is_400_and_the_tuned_variant_lifts_it() -> None:
    # normalized_max_linear_velocity 400 caps the speed after a substep.
    params = rp.IntegrationParameters()
    assert params.normalized_max_linear_velocity == 400.0
    case = response([0.0, 0.0, 0.0], [1000.0, 0.0, 0.0], [10.0, 0.0, 0.0], [-1000.0, 0.0, 0.0])
    world = rp.PhysicsWorld(gravity=(0.0, 0.0, 0.0))
    handle = world.add_body(rp.RigidBody.dynamic().linvel((1000.0, 0.0, 0.0)),
                            [rp.Collider.ball(0.5).mass(1.0)])
    other = world.add_body(rp.RigidBody.dynamic().translation((10.0, 0.0, 0.0))
                           .linvel((-1000.0, 0.0, 0.0)), [rp.Collider.ball(0.5).mass(1.0)])
    for _ in range(3):
        world.step()
    speeds = [world.rigid_bodies[h].linvel.norm() for h in (handle, other)]
    assert max(speeds) <= 400.0 * (1 + 1e-6)
    assert velocity_error(TUNED, case) <= TUNED.conventions.rtol


def test_mass_zero_is_immovable() -> None:
    # inv(0) = 0: B (mass 0, at -1) keeps its velocity and sends A back as a wall moving at
    # -1 would: A's velocity relative to B reverses, so A leaves at 2 vb - va = -3.
    obs = TUNED.observe(response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0],
                                 [-1.0, 0.0, 0.0], mb=0.0))
    assert obs.v2 == (-1.0, 0.0, 0.0)
    assert isinstance(obs.v1, tuple) and obs.v1[0] == pytest.approx(2 * -1.0 - 1.0, abs=1e-6)


def test_infinite_velocity_is_quarantined_and_raises() -> None:
    with pytest.raises(FloatingPointError, match="quarantined"):
        TUNED.observe(response([0.0, 0.0, 0.0], [math.inf, 0.0, 0.0], [1.0, 0.0, 0.0],
                               [0.0, 0.0, 0.0]))


# --- translation -------------------------------------------------------------------------

@pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=["tuned", "default"])
@pytest.mark.parametrize("case", [
    sphere(0.0, 0.75), sphere(0.0, -0.75), sphere(0.0, 3.0), sphere(0.0, 1.0, dim=2),
    ball([0.0, 0.0, 0.0], 2.5, [3.0, 4.0, 0.0], 2.0),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 0.5, 0.0], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [-2.5, 0.0, 0.0], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 2.5], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0], [1.0, 1.0], [0.5, -1.5], [1.0, 1.0]),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [3.0, 3.0, 3.0], [1.0, 1.0, 1.0]),
], ids=["overlap", "overlap-minus-x", "apart", "disc-touch", "gap-345", "box-overlap",
        "box-gap-minus-x", "box-gap-z", "box-2d-overlap-y", "box-corner-gap"])
def test_distance_and_normal_agree_with_the_oracle_within_f32(adapter: Any,
                                                              case: AnyCase) -> None:
    # Signed distance (gap positive) and unit normal from A to B, in the case's dimension.
    obs, truth = adapter.observe(case), oracle.truth(case)
    assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
    assert isinstance(obs.normal, tuple) and isinstance(truth.normal, tuple)
    assert len(obs.normal) == case.dim
    assert abs(obs.distance - truth.distance) <= adapter.conventions.rtol * length_scale(case)
    assert error_of("normal", obs.normal, truth.normal) <= 1e-6


def test_the_verdict_follows_each_variants_prediction_distance() -> None:
    touching, near = sphere(0.0, 1.0), sphere(0.0, 1.01)
    assert TUNED.observe(touching).hit is False and DEFAULT.observe(touching).hit is True
    assert TUNED.observe(near).hit is False and DEFAULT.observe(near).hit is True
    box_touch = aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    assert TUNED.observe(box_touch).hit is False and DEFAULT.observe(box_touch).hit is True


def test_no_contact_point_is_an_undefined_distance_with_the_reason() -> None:
    # Zero-size boxes: parry gives no contact point (no face to clip), even within reach.
    obs = TUNED.observe(aabb([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 2.0, 2.0], [0.0, 0.0, 0.0]))
    assert obs.hit is False
    assert not isinstance(obs.distance, float) and obs.distance is not None
    assert "no contact point" in obs.distance.reason


@pytest.mark.parametrize("case", [
    sphere(0.0, 0.75), sphere(0.0, 3.0, dim=2),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 0.5, -0.25], [1.0, 1.0, 1.0]),
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
    response([0.0, 0.0], [1.0, 0.5], [3.0, 0.0], [-1.0, 0.0], mb=3.0),
], ids=["sphere", "disc-apart", "box", "response", "response-2d-apart"])
@pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=["tuned", "default"])
def test_query_is_repeatable(adapter: Any, case: AnyCase) -> None:
    prepared = adapter.prepare(case)
    try:
        assert adapter.query(prepared) == adapter.query(prepared)
    finally:
        adapter.release(prepared)


@pytest.mark.parametrize("case", [
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], mb=3.0),
    response([0.0, 0.0], [0.0, 2.0], [0.0, 1.0], [0.0, -1.0], restitution=0.5),
    moving([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 4.0, 0.0], [0.0, 0.0, 0.0], 2.5, mb=2.0),
    response([0.0, 0.0], [0.0009765625, 1.0], [1.0, 0.0], [0.0, -1.0]),
], ids=["head-on", "masses-1-3", "2d-restitution-half", "oblique-345", "2d-grazing"])
def test_tuned_responses_touching_at_the_start_agree_with_the_oracle_within_f32(
        case: AnyCase) -> None:
    # Touching at the start: soft CCD resolves the contact in the first step, at the case's
    # centres (all exact in f32 here), with restitution e by the product rule.
    assert isinstance(case, ResponseCase)
    obs = TUNED.observe(case)
    assert obs.resolved_at == (case.a.center, case.b.center)
    assert velocity_error(TUNED, case) <= TUNED.conventions.rtol


def test_default_variant_gives_the_case_restitution_by_averaging() -> None:
    # Head-on, no tangential motion: friction plays no part; average(e, e) = e.
    case = response([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0],
                    restitution=0.5)
    assert velocity_error(DEFAULT, case) <= DEFAULT.conventions.rtol


def test_a_separated_pair_is_resolved_where_it_meets() -> None:
    # 0.5 apart, closing at 2: resolved in a step that starts less than one step's travel
    # before the touch, and the answer is the oracle's there.
    case = response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.5, 0.0, 0.0], [-1.0, 0.0, 0.0])
    assert isinstance(case, ResponseCase)
    obs = TUNED.observe(case)
    assert obs.resolved_at is not None
    (pa, pb), step = obs.resolved_at, TUNED.conventions.time_step
    assert step is not None
    gap = norm([b - a for a, b in zip(pa, pb, strict=True)]) - 1.0
    assert -1e-6 <= gap <= 2.0 * step
    assert velocity_error(TUNED, case) <= TUNED.conventions.rtol


def test_separating_bodies_are_left_alone_and_categorised_by_the_declared_rule() -> None:
    case = response([0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    obs = TUNED.observe(case)
    assert (obs.v1, obs.v2, obs.resolved_at) == ((-1.0, 0.0, 0.0), (1.0, 0.0, 0.0), None)
    verdict = judge(case, TUNED.conventions, "v1", obs.v1, oracle.truth(case), obs)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)


def test_2d_responses_stay_in_the_plane_with_friction_on() -> None:
    # The default variant keeps friction 0.5; z translation is locked for a 2-D case.
    case = moving([0.0, 0.0], [1.0, 1.0], [3.0, 4.0], [0.0, 0.0], 2.5)
    obs = DEFAULT.observe(case)
    assert isinstance(obs.v1, tuple) and len(obs.v1) == 2
    assert obs.resolved_at is not None and len(obs.resolved_at[0]) == 2


@pytest.mark.parametrize("case, error", [
    (sphere(math.nan, 1.0), ValueError),
    (aabb([0.0, 0.0], [1.0, math.inf], [0.5, 0.0], [1.0, 1.0]), ValueError),
    (response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0],
              mb=math.nan), ValueError),
    (sphere(0.0, 1e39), OverflowError),
], ids=["nan-centre", "inf-half", "nan-mass", "beyond-f32"])
def test_inputs_rapier_would_mishandle_are_refused(case: AnyCase, error: type) -> None:
    with pytest.raises(error, match="rapier"):
        TUNED.prepare(case)


def test_an_infinite_mass_is_kept_and_immovable() -> None:
    # Not refused: inv(inf) = 0, the body is immovable (the oracle has no value for it).
    obs = TUNED.observe(response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0],
                                 [0.0, 0.0, 0.0], mb=math.inf))
    assert obs.v2 == (0.0, 0.0, 0.0)
    assert isinstance(obs.v1, tuple) and obs.v1[0] == pytest.approx(-1.0, abs=1e-6)


def test_a_refused_case_is_an_error_and_the_next_case_runs(tmp_path: Path) -> None:
    cases = [sphere(math.nan, 1.0, id="nan", tags=["bad-input"]), sphere(0.0, 3.0, id="after")]
    store = ResultsStore(tmp_path / "rapier")
    run(cases, [adapters.get("rapier")], store, RunOptions(quick=True, timeout_s=10.0))
    store.close()
    frame = read_results(tmp_path / "rapier")
    nan_rows = frame[frame["case_id"] == "nan"]
    assert set(nan_rows["status"]) == {"error"}
    assert all("rapier takes it without a word" in r for r in nan_rows["reason"])
    assert set(frame[frame["case_id"] == "after"]["status"]) <= {"agree", "disagree"}


# --- declarations ------------------------------------------------------------------------

def test_registry_availability_and_declarations() -> None:
    assert isinstance(adapters.get("rapier"), RapierTuned)
    assert isinstance(adapters.get("rapier-default"), RapierDefault)
    assert TUNED.available() is None and TUNED.version() == rp.__version__ == "0.36.1"
    tuned, default = TUNED.conventions, DEFAULT.conventions
    assert not any(tuned.touching_is_contact(f) for f in ("sphere", "face", "edge", "corner"))
    assert all(default.touching_is_contact(f) for f in ("sphere", "face", "edge", "corner"))
    assert tuned.margins == default.margins == {} and tuned.rtol == default.rtol == 2.0**-21
    assert tuned.no_value == default.no_value == ()  # no value is an error: no rule says so
    assert (tuned.zero_mass, tuned.negative_extents, tuned.resolves_separating) == (
        "static", "", False)
    assert tuned.restitution_threshold == 0.0 and tuned.damping == 0.0


def test_touching_boxes_are_a_convention_disagreement_for_the_tuned_variant() -> None:
    case = aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0], [1.0, 1.0, 1.0])
    verdict = judge(case, TUNED.conventions, "hit", TUNED.observe(case).hit, oracle.truth(case))
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)


def test_touching_spheres_are_a_convention_disagreement_for_the_default_variant() -> None:
    case = sphere(0.0, 1.0)
    obs: Observation = DEFAULT.observe(case)
    verdict = judge(case, DEFAULT.conventions, "hit", obs.hit, oracle.truth(case))
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)


# --- scenes (the scene calls of adapters/rapier/calls.py) ------------------------------

HEAD_ON_2D = [((-2.0, 0.0), 0.5, 1.0, (1.0, 0.0)), ((2.0123456789, 0.0), 0.5, 1.0, (-1.0, 0.0))]
HEAD_ON_3D = [((-2.0, 0.0, 0.0), 0.5, 1.0, (1.0, 0.0, 0.0)),
              ((2.0123456789, 0.0, 0.0), 0.5, 1.0, (-1.0, 0.0, 0.0))]


def stepped_scene(bodies: list[Any], dim: int, e: float, tuning: Any, steps: int = 3000,
                  dt: float = 1e-3, iterations: int | None = None) -> Any:
    rapier_scene = SceneCalls(TUNED)
    prepared = rapier_scene.prepare_scene(bodies, dim, e, dt, iterations, tuning)
    try:
        return rapier_scene.run_scene(prepared, steps)
    finally:
        rapier_scene.release_scene(prepared)


@pytest.mark.parametrize(("bodies", "dim"), [(HEAD_ON_2D, 2), (HEAD_ON_3D, 3)], ids=["2d", "3d"])
def test_tuned_scene_exchanges_velocities_of_an_elastic_head_on_pair(bodies: list[Any],
                                                                     dim: int) -> None:
    # Equal masses, e = 1: the textbook exchanges the velocities (declared: exactly, in both
    # dims, measured in adapters/rapier/scene.py); momentum stays 0 and the energy 1.
    run = stepped_scene(bodies, dim, 1.0, TUNED.scene_settings())
    assert run.steps == 3000 and len(run.velocities[0]) == dim
    assert run.velocities == (bodies[1][3], bodies[0][3])
    momentum = [math.fsum(1.0 * v[i] for v in run.velocities) for i in range(dim)]
    assert momentum == [0.0] * dim
    assert math.fsum(0.5 * norm(v) ** 2 for v in run.velocities) == 1.0


@pytest.mark.parametrize("e", [0.25, 0.5, 0.81])
@pytest.mark.parametrize("variant", [TUNED, DEFAULT], ids=["rapier", "rapier-default"])
def test_scene_restitution_is_e_rounded_to_float32(variant: RapierTuned, e: float) -> None:
    # Every collider gets e: Max (tuned) and Average (default) of e and e are e, in float32.
    run = stepped_scene(HEAD_ON_2D, 2, e, variant.scene_settings())
    f32_e = float(rp.Vec3(e, 0.0, 0.0).to_tuple()[0])
    assert run.velocities[1][0] == pytest.approx(f32_e, rel=4 * F32_EPSILON)
    assert run.velocities[1][0] - run.velocities[0][0] == pytest.approx(2 * f32_e, rel=1e-6)


def test_tuned_scene_is_the_textbook_cradle_and_default_sleeps_slow_bodies() -> None:
    cradle = [((-1.0, 0.0), 0.5, 1.0, (1.0, 0.0))] + [
        ((float(i), 0.0), 0.5, 1.0, (0.0, 0.0)) for i in range(4)]
    run = stepped_scene(cradle, 2, 1.0, TUNED.scene_settings(), steps=2000)
    assert [v[0] for v in run.velocities] == pytest.approx([0.0, 0.0, 0.0, 0.0, 1.0],
                                                           abs=4 * F32_EPSILON)
    slow = [((0.0, 0.0), 0.5, 1.0, (0.05, 0.0))]
    assert stepped_scene(slow, 2, 1.0, TUNED.scene_settings()).velocities[0][0] == pytest.approx(
        0.05, rel=4 * F32_EPSILON)  # no sleeping: the body keeps its speed
    assert stepped_scene(slow, 2, 1.0, DEFAULT.scene_settings()).velocities == ((0.0, 0.0),)


def test_scene_speed_cap_only_in_the_default_variant() -> None:
    fast = [((0.0, 0.0, 0.0), 0.5, 1.0, (1000.0, 0.0, 0.0))]
    assert stepped_scene(fast, 3, 1.0, TUNED.scene_settings(), steps=1).velocities[0][0] == 1000.0
    capped = stepped_scene(fast, 3, 1.0, DEFAULT.scene_settings(), steps=1).velocities[0][0]
    assert capped == re_.DEFAULT_MAX_SPEED


def test_scene_clock_times_only_the_stepping_loop() -> None:
    # Injected time: the readings go to the same log as the world's steps.
    rapier_scene = SceneCalls(TUNED)
    log: list[str] = []
    readings = iter([1.0, 1.5, 3.0, 7.0])

    def clock() -> float:
        log.append("clock")
        return next(readings)

    prepared = rapier_scene.prepare_scene(HEAD_ON_3D, 3, 1.0, 1e-3, None, TUNED.scene_settings())
    world = prepared["world"]

    class Watched:
        quarantine = world.quarantine
        rigid_bodies = world.rigid_bodies

        @staticmethod
        def step() -> None:
            log.append("step")
            world.step()

    prepared["world"] = Watched()  # the same bodies, the steps logged
    idle = rapier_scene.run_scene(prepared, 0, clock=clock)
    assert log == ["clock", "clock"]
    log.clear()
    stepped = rapier_scene.run_scene(prepared, 5, clock=clock)
    assert log == ["clock", *["step"] * 5, "clock"]
    assert (idle.wall_s, stepped.wall_s) == (0.5, 4.0) and (idle.steps, stepped.steps) == (0, 5)


def test_bad_scenes_are_refused_with_value_error() -> None:
    rapier_scene = SceneCalls(TUNED)
    tuning = TUNED.scene_settings()
    with pytest.raises(ValueError, match="mass"):
        rapier_scene.prepare_scene([((0.0, 0.0), 0.5, 0.0, (1.0, 0.0))], 2, 1.0, 1e-3, None,
                                   tuning)
    with pytest.raises(ValueError, match="restitution"):
        rapier_scene.prepare_scene(HEAD_ON_2D, 2, -0.5, 1e-3, None, tuning)
    with pytest.raises(ValueError, match="dt"):
        rapier_scene.prepare_scene(HEAD_ON_2D, 2, 1.0, 0.0, None, tuning)
    with pytest.raises(ValueError, match="components"):
        rapier_scene.prepare_scene(HEAD_ON_2D, 3, 1.0, 1e-3, None, tuning)
    with pytest.raises(ValueError, match="iterations"):
        rapier_scene.prepare_scene(HEAD_ON_2D, 2, 1.0, 1e-3, 0, tuning)
    with pytest.raises(OverflowError, match="float32"):
        rapier_scene.prepare_scene([((0.0, 0.0), 1e39, 1.0, (1.0, 0.0))], 2, 1.0, 1e-3, None,
                                   tuning)
    prepared = rapier_scene.prepare_scene(HEAD_ON_2D, 2, 1.0, 1e-3, None, tuning)
    with pytest.raises(ValueError, match="steps"):
        rapier_scene.run_scene(prepared, -1)
    assert len(prepared["world"].rigid_bodies) == 2
    rapier_scene.release_scene(prepared)
    assert len(prepared["world"].rigid_bodies) == len(prepared["world"].colliders) == 0


def test_both_variants_step_suite_scenes_through_the_adapter() -> None:
    case = CASE_ADAPTER.validate_python({
        "id": "s", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 3.0,
        "dt": 1e-3, "bodies": [{"center": list(c), "radius": r, "mass": m, "velocity": list(v)}
                               for c, r, m, v in HEAD_ON_2D]})
    for variant in (TUNED, DEFAULT):
        assert variant.unsupported(case) is None
        obs = variant.observe(case)
        assert obs.velocities == ((-1.0, 0.0), (1.0, 0.0))
        assert obs.momentum == (0.0, 0.0) and obs.energy == 1.0
