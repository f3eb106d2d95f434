"""The Box2D adapters: pinned native behaviour of Box2D 2.3.0 (pybox2d 2.3.10) and the translation.

The conformance tests pin what the engine does natively and the adapter relies on (half
widths, the polygon skin, the touching rules, no penetration depth, restitution by max, the
compiled-in thresholds), each with the expected value derived from the rule, never copied
from the engine's output, so an upgrade that changes a rule fails here.  The translation
tests check the adapter against the exact oracle within the declared float32 precision.
Nothing here calls ``CreateFixture(b2FixtureDef())`` (no shape) in this process: it
segfaults, which is pinned in a subprocess.
"""

from __future__ import annotations

import math
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any, cast

import pytest

Box2D = pytest.importorskip("Box2D")

import adapters  # noqa: E402
from adapters import box2d as b2e  # noqa: E402
from adapters.box2d import Box2dDefault, Box2dTuned  # noqa: E402
from crosscheck.core.contract import Adapter  # noqa: E402
from crosscheck.core.geometry import Vec, norm  # noqa: E402
from crosscheck.core.model import Category, Kind, Observation, Status  # noqa: E402
from crosscheck.core.options import RunOptions  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, ResponseCase, SceneCase  # noqa: E402
from crosscheck.results.run import read_results  # noqa: E402
from crosscheck.results.store import ResultsStore  # noqa: E402
from crosscheck.run.runner import run  # noqa: E402
from crosscheck.truth import oracle, scenes  # noqa: E402
from crosscheck.truth.score import judge  # noqa: E402
from tests.adapters.scene_calls import (  # noqa: E402
    Body,
    SceneCalls,
)
from tests.conftest import aabb, response, sphere  # noqa: E402

pytestmark = pytest.mark.engine

TUNED, DEFAULT = Box2dTuned(), Box2dDefault()
BOTH = pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=["box2d", "box2d-default"])
F32_EPS = 2.0**-23
"""FLT_EPSILON: b2_epsilon, and the spacing of float32 numbers in [1, 2)."""


def disc(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A 2-D sphere case with centres anywhere in the plane."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": 2,
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def xf(x: float, y: float) -> Any:
    t = Box2D.b2Transform()
    t.position = (x, y)
    t.angle = 0.0
    return t


def manifold(shape_a: Any, at_a: tuple[float, float], shape_b: Any,
             at_b: tuple[float, float]) -> Any:
    m = Box2D.b2Manifold()
    collide = (Box2D.b2CollideCircles if isinstance(shape_a, Box2D.b2CircleShape)
               else Box2D.b2CollidePolygons)
    collide(m, shape_a, xf(*at_a), shape_b, xf(*at_b))
    return m


def box(hx: float, hy: float, radius: float | None = None) -> Any:
    shape = Box2D.b2PolygonShape(box=(hx, hy))
    if radius is not None:
        shape.radius = radius
    return shape


def distance(shape_a: Any, at_a: tuple[float, float], shape_b: Any, at_b: tuple[float, float],
             use_radii: bool) -> float:
    out = Box2D.b2Distance(shapeA=shape_a, shapeB=shape_b, transformA=xf(*at_a),
                           transformB=xf(*at_b), useRadii=use_radii)
    return float(out.distance)


def head_on_world(speed: float, e_a: float, e_b: float, dt: float = 1e-3) -> tuple[Any, Any]:
    """Two unit discs of unit mass touching on x, A approaching B at ``speed``, stepped once."""
    world = Box2D.b2World(gravity=(0.0, 0.0), doSleep=False)
    bodies = []
    for x, v, e in ((0.0, speed, e_a), (1.0, 0.0, e_b)):
        body = world.CreateDynamicBody(position=(x, 0.0), linearVelocity=(v, 0.0),
                                       fixedRotation=True)
        body.CreateCircleFixture(radius=0.5, density=0.0, friction=0.0, restitution=e)
        body.massData = Box2D.b2MassData(mass=1.0, center=(0.0, 0.0), I=0.0)
        bodies.append(body)
    world.Step(dt, 8, 3)
    return bodies[0], bodies[1]


def within(value: object, want: object, tol: float) -> bool:
    assert isinstance(value, tuple) and isinstance(want, tuple)
    return norm([x - y for x, y in zip(value, want, strict=True)]) <= tol


# --- native behaviour (conformance) ----------------------------------------------------------

def test_box_takes_half_widths() -> None:
    # SetAsBox(hx, hy): vertices at +-hx, +-hy.  A box of side 2 (box=(1, 1)) and a point at
    # x = 3 are 3 - 1 = 2 apart; were 1 the full side, they would be 2.5 apart.
    assert sorted({v[0] for v in box(1.0, 0.5).vertices}) == [-1.0, 1.0]
    assert sorted({v[1] for v in box(1.0, 0.5).vertices}) == [-0.5, 0.5]
    assert distance(box(1.0, 1.0, 0.0), (0.0, 0.0), box(0.0, 0.0, 0.0), (3.0, 0.0),
                    use_radii=False) == 2.0


def test_polygons_carry_a_skin_of_two_linear_slops() -> None:
    # b2PolygonShape() sets m_radius = b2_polygonRadius = 2 * b2_linearSlop (0.005f).
    f32_slop = float(Box2D.b2_linearSlop)
    assert Box2D.b2_polygonRadius == box(1.0, 1.0).radius == 2.0 * f32_slop
    assert 2.0 * Box2D.b2_polygonRadius == pytest.approx(b2e.SKIN, abs=1e-8)
    # useRadii subtracts both skins from a 0.5 gap; useRadii=False reads the gap itself.
    skinned = distance(box(0.5, 0.5), (0.0, 0.0), box(0.5, 0.5), (1.5, 0.0), use_radii=True)
    bare = distance(box(0.5, 0.5), (0.0, 0.0), box(0.5, 0.5), (1.5, 0.0), use_radii=False)
    assert bare == 0.5
    assert skinned == pytest.approx(0.5 - 4.0 * f32_slop, abs=4 * F32_EPS)


def test_touching_circles_collide() -> None:
    # b2CollideCircles rejects only distSqr > radius^2: an exact touch is a contact.
    circle = Box2D.b2CircleShape(radius=0.5)
    assert manifold(circle, (0.0, 0.0), circle, (1.0, 0.0)).pointCount == 1
    big = Box2D.b2CircleShape(radius=2.5)
    assert manifold(big, (0.0, 0.0), big, (3.0, 4.0)).pointCount == 1
    assert manifold(circle, (0.0, 0.0), circle, (1.0 + F32_EPS, 0.0)).pointCount == 0


def test_face_touching_boxes_collide_and_corner_touching_ones_do_not() -> None:
    # b2CollidePolygons rejects only separation > totalRadius (0 here), but a corner touch
    # clips the incident edge to no point.  With the default skins (0.02) it is a contact.
    unit = box(1.0, 1.0, 0.0)
    assert manifold(unit, (0.0, 0.0), unit, (2.0, 0.0)).pointCount == 2
    assert manifold(unit, (0.0, 0.0), box(2.0, 2.0, 0.0), (0.5, -3.0)).pointCount == 2
    assert manifold(unit, (0.0, 0.0), unit, (2.0, 2.0)).pointCount == 0
    assert manifold(box(1.0, 1.0), (0.0, 0.0), box(1.0, 1.0), (2.0, 2.0)).pointCount == 2


def test_gjk_has_no_penetration_depth() -> None:
    # b2Distance on overlapping shapes returns 0 with and without radii: no depth to report.
    for radii in (True, False):
        assert distance(box(0.5, 0.5, 0.0), (0.0, 0.0), box(0.5, 0.5, 0.0), (0.75, 0.0),
                        use_radii=radii) == 0.0
    circle = Box2D.b2CircleShape(radius=0.5)
    assert distance(circle, (0.0, 0.0), circle, (0.75, 0.0), use_radii=True) == 0.0


def test_b2_epsilon_is_an_absolute_length_tolerance() -> None:
    # b2_epsilon = FLT_EPSILON; with radii, a distance not above it reads 0 (b2Distance.cpp),
    # and b2Vec2::Normalize leaves a vector shorter than it unnormalised (b2Math.h), so the
    # manifold normal of a box edge of length 2e-9 has that length.
    assert Box2D.b2_epsilon == pytest.approx(F32_EPS, rel=1e-9)  # a 10-digit literal
    for conv in (TUNED.conventions, DEFAULT.conventions):
        assert conv.margin_for("sphere") == b2e.B2_EPSILON == F32_EPS
    tiny = Box2D.b2CircleShape(radius=1e-9)
    assert distance(tiny, (0.0, 0.0), tiny, (2e-9 + 1e-12, 0.0), use_radii=True) == 0.0
    obs = TUNED.observe(aabb([0.0, 0.0], [1e-9, 1e-9], [1.5e-9, 0.0], [1e-9, 1e-9]))
    assert obs.hit is True and isinstance(obs.normal, tuple)
    edge = 2.0 * float(Box2D.b2Vec2(1e-9, 0.0)[0])  # 2 x the float32 half-width
    assert obs.normal[1] == 0.0 and obs.normal[0] == pytest.approx(edge, rel=F32_EPS)


def test_restitution_mixes_by_max() -> None:
    # b2MixRestitution: max.  A head-on approach at 2 (above the threshold) between unit
    # masses: e = max(0.5, 0) = 0.5 and e = max(0.5, 1) = 1 (the product would give 0 and 0.5).
    for e_a, e_b in ((0.5, 0.0), (0.5, 1.0)):
        a, b = head_on_world(2.0, e_a, e_b)
        e = max(e_a, e_b)
        assert tuple(a.linearVelocity) == pytest.approx((1.0 - e, 0.0), abs=4 * F32_EPS)
        assert tuple(b.linearVelocity) == pytest.approx((1.0 + e, 0.0), abs=4 * F32_EPS)


def test_restitution_threshold_is_one_and_strict() -> None:
    # vRel < -b2_velocityThreshold (1) bounces; an approach of exactly 1 is inelastic.
    assert Box2D.b2_velocityThreshold == 1.0
    a, b = head_on_world(1.0, 1.0, 0.0)
    assert (tuple(a.linearVelocity), tuple(b.linearVelocity)) == ((0.5, 0.0), (0.5, 0.0))
    speed = 1.0 + F32_EPS  # one float32 unit above: elastic
    a, b = head_on_world(speed, 1.0, 0.0)
    assert (tuple(a.linearVelocity), tuple(b.linearVelocity)) == ((0.0, 0.0), (speed, 0.0))
    for conv in (TUNED.conventions, DEFAULT.conventions):
        assert conv.restitution_threshold == b2e.THRESHOLD == speed


def test_speeds_above_two_metres_per_step_are_clipped() -> None:
    # b2Island: a translation beyond b2_maxTranslation (2) per step scales the velocity down.
    assert Box2D.b2_maxTranslation == 2.0
    world = Box2D.b2World(gravity=(0.0, 0.0), doSleep=False)
    body = world.CreateDynamicBody(position=(0.0, 0.0), linearVelocity=(3000.0, 0.0))
    body.CreateCircleFixture(radius=0.5, density=1.0)
    world.Step(TUNED.variant.dt, 8, 3)
    assert body.linearVelocity[0] == pytest.approx(2.0 / TUNED.variant.dt, rel=4 * F32_EPS)
    for adapter in (TUNED, DEFAULT):  # declared: 2 m per step, at the end of every step
        conv = adapter.conventions
        assert conv.max_speed == Box2D.b2_maxTranslation / adapter.variant.dt
        assert conv.max_speed_at == "step"


@BOTH
@pytest.mark.parametrize("speed, e, mb", [(200.0, 1.0, 1.0), (1000.0, 1.0, 1.0),
                                          (3000.0, 1.0, 1.0), (1000.0, 0.5, 2.0)])
def test_a_clipped_response_is_the_declared_speed_cap(adapter: Adapter, speed: float, e: float,
                                                      mb: float) -> None:
    # Touching at the start: the contact is solved in the first step with the case's speeds,
    # then each velocity is clipped; under the cap the answer is the textbook's.
    case = response([0.0, 0.0], [speed, 0.0], [1.0, 0.0], [0.0, 0.0], mb=mb, restitution=e)
    obs, truth = adapter.observe(case), oracle.truth(case)
    cap = adapter.conventions.max_speed
    assert cap is not None
    for quantity in ("v1", "v2"):
        verdict = judge(case, adapter.conventions, quantity, obs.get(quantity), truth, obs)
        want = truth.get(quantity)
        assert isinstance(want, tuple)
        if norm(cast(Vec, want)) > cap:
            assert verdict.category == Category.CONVENTION and "speed cap" in verdict.reason
        else:
            assert verdict.status is Status.AGREE or verdict.category != Category.CONVENTION


def test_the_verdict_has_no_b2_epsilon() -> None:
    # b2CollideCircles rejects only distSqr > radius^2, b2CollidePolygons separation >
    # totalRadius: b2_epsilon acts on distances and normals, never on the verdict.
    for adapter in (TUNED, DEFAULT):
        conv = adapter.conventions
        assert conv.verdict_margin_for("sphere") == 0.0 < conv.margin_for("sphere")
    assert TUNED.conventions.verdict_margin_for("face") == 0.0
    assert DEFAULT.conventions.verdict_margin_for("face") == b2e.SKIN
    case = disc([0.0, 0.0], 1e-9, [2e-9 + 5e-11, 0.0], 1e-9)  # apart by 5e-11 < b2_epsilon
    verdict = judge(case, TUNED.conventions, "hit", True, oracle.truth(case))
    assert verdict.category == Category.ERROR and "b2_epsilon" not in verdict.reason
    assert "margin" not in verdict.reason


def test_do_sleep_false_does_not_reach_box2d() -> None:
    # pybox2d 2.3.10: b2World.__init__ sets a Python attribute allowSleeping, which is no
    # property; only SetAllowSleeping reaches b2World::m_allowSleep (what the adapter calls).
    world = Box2D.b2World(gravity=(0.0, 0.0), doSleep=False)
    assert world.GetAllowSleeping() is True
    world.SetAllowSleeping(False)
    assert world.GetAllowSleeping() is False


def test_a_slow_body_falls_asleep_where_sleeping_is_allowed() -> None:
    # b2Island: slower than b2_linearSleepTolerance for b2_timeToSleep -> SetAwake(false),
    # which zeroes the velocity.  An approach at 0.005 m/s over a 0.1 gap (20 s) never
    # arrives by default; the tuned variant (sleeping off) resolves it, inelastically (0.005
    # m/s is below the restitution threshold).
    assert Box2D.b2_timeToSleep == 0.5
    assert Box2D.b2_linearSleepTolerance == pytest.approx(0.01)
    case = response([0.0, 0.0], [0.005, 0.0], [1.1, 0.0], [0.0, 0.0])
    asleep = DEFAULT.observe(case)
    assert (asleep.v1, asleep.v2, asleep.resolved_at) == ((0.0, 0.0), (0.0, 0.0), None)
    awake = TUNED.observe(case)
    assert awake.resolved_at is not None
    inelastic = oracle.truth(case.model_copy(update={"restitution": 0.0}))
    assert within(awake.v1, inelastic.v1, F32_EPS) and within(awake.v2, inelastic.v2, F32_EPS)


def test_mass_data_reads_a_non_positive_mass_as_one() -> None:
    # b2Body::SetMassData: m_mass <= 0 becomes 1.  Why the adapter refuses such masses.
    world = Box2D.b2World(gravity=(0.0, 0.0))
    body = world.CreateDynamicBody(position=(0.0, 0.0))
    for mass in (0.0, -1.0):
        body.massData = Box2D.b2MassData(mass=mass, center=(0.0, 0.0), I=0.0)
        assert body.mass == 1.0


def test_collide_takes_nan_unchecked_but_a_body_definition_asserts() -> None:
    # A NaN radius passes distSqr > radius^2 as false: "contact".  A body definition asserts
    # that its position and velocity are valid (b2Assert raises AssertionError in pybox2d).
    nan = Box2D.b2CircleShape(radius=math.nan)
    assert manifold(nan, (0.0, 0.0), Box2D.b2CircleShape(radius=1.0), (5.0, 0.0)).pointCount
    world = Box2D.b2World(gravity=(0.0, 0.0))
    with pytest.raises(AssertionError, match="IsValid"):
        world.CreateDynamicBody(position=(0.0, 0.0), linearVelocity=(math.nan, 0.0))


def test_a_fixture_definition_without_a_shape_segfaults(tmp_path: Path) -> None:
    # Why the runner isolates engines: CreateFixture(b2FixtureDef()) kills the interpreter
    # (b2Body::CreateFixture dereferences the null shape; never called in-process), while
    # pybox2d's keyword form without a shape raises ValueError first.
    code = ("import Box2D\nb = Box2D.b2World().CreateDynamicBody()\n"
            "try:\n    b.CreateFixture()\nexcept ValueError:\n    print('refused')\n"
            "b.CreateFixture(Box2D.b2FixtureDef())\nprint('survived')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=60, check=False)
    assert done.returncode == -signal.SIGSEGV
    assert done.stdout.split() == ["refused"]


# --- translation: detection --------------------------------------------------------------------

@BOTH
@pytest.mark.parametrize("kind", ["aabb", "sphere"])
def test_overlap_is_a_hit_with_normal_a_to_b_and_no_distance(adapter: Adapter, kind: str) -> None:
    def case(xa: float, xb: float) -> AnyCase:
        if kind == "aabb":
            return aabb([xa, 0.0], [0.5, 0.5], [xb, 0.0], [0.5, 0.5])
        return sphere(xa, xb, dim=2)

    right, left = adapter.observe(case(0.0, 0.75)), adapter.observe(case(0.75, 0.0))
    assert (right.hit, right.distance, right.normal) == (True, None, (1.0, 0.0))
    assert (left.hit, left.distance) == (True, None)
    assert left.normal == pytest.approx((-1.0, 0.0))


@pytest.mark.parametrize("kind", ["aabb", "sphere"])
def test_a_gap_is_measured_with_the_normal_from_a_to_b(kind: str) -> None:
    for sign in (1.0, -1.0):
        if kind == "aabb":
            case = aabb([0.0, 0.0], [0.5, 0.5], [0.0, 1.5 * sign], [0.5, 0.5])
        else:
            case = disc([0.0, 0.0], 0.5, [0.0, 1.5 * sign], 0.5)
        obs, truth = TUNED.observe(case), oracle.truth(case)
        assert (obs.hit, obs.distance) == (False, truth.distance)
        assert within(obs.normal, truth.normal, TUNED.conventions.rtol)


def test_the_default_skin_is_within_its_declared_margin() -> None:
    # Boxes 0.01 apart collide with the skins; 0.5 apart, the distance is the gap less 0.02.
    touching = DEFAULT.observe(aabb([0.0, 0.0], [0.5, 0.5], [1.01, 0.0], [0.5, 0.5]))
    assert touching.hit is True and TUNED.observe(
        aabb([0.0, 0.0], [0.5, 0.5], [1.01, 0.0], [0.5, 0.5])).hit is False
    apart = DEFAULT.observe(aabb([0.0, 0.0], [0.5, 0.5], [1.5, 0.0], [0.5, 0.5]))
    margin = DEFAULT.conventions.margin_for("face")
    assert isinstance(apart.distance, float) and abs(apart.distance - 0.5) <= margin
    assert margin == b2e.SKIN + b2e.B2_EPSILON and TUNED.conventions.margin_for("face") == F32_EPS


def test_variants_set_the_polygon_skin_as_declared() -> None:
    case = aabb([0.0, 0.0], [1.0, 0.5], [5.0, 0.0], [1.0, 1.0])
    tuned, default = TUNED.prepare(case).built, DEFAULT.prepare(case).built
    assert (tuned["a"].radius, tuned["use_radii"]) == (0.0, False)
    assert (default["a"].radius, default["use_radii"]) == (Box2D.b2_polygonRadius, True)
    assert TUNED.conventions.touching_is_contact("corner") is False
    assert DEFAULT.conventions.touching_is_contact("corner") is True


def test_float32_rounding_at_a_large_offset_is_within_the_declared_rtol() -> None:
    # Unit boxes 0.2 apart at 1e6: float32 spacing 0.0625 there; the answer is off by up to a
    # spacing, within rtol x the case's size (1e6).
    case = aabb([1e6, 1e6], [0.5, 0.5], [1e6 + 1.2, 1e6], [0.5, 0.5])
    obs, truth = TUNED.observe(case), oracle.truth(case)
    assert isinstance(obs.distance, float) and isinstance(truth.distance, float)
    assert obs.distance != truth.distance
    assert abs(obs.distance - truth.distance) <= TUNED.conventions.rtol * 1e6


# --- translation: response ---------------------------------------------------------------------

@BOTH
def test_touching_pair_resolves_at_the_start_with_the_textbook_answer(adapter: Adapter) -> None:
    # Approach 2 (above the threshold), head on, e = 1 and e = 0.5: the oracle's velocities.
    for e in (1.0, 0.5):
        case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], restitution=e, mb=3.0)
        obs, truth = adapter.observe(case), oracle.truth(case)
        assert obs.resolved_at == ((0.0, 0.0), (1.0, 0.0))
        tol = adapter.conventions.rtol * 1.0
        assert within(obs.v1, truth.v1, tol) and within(obs.v2, truth.v2, tol)


@BOTH
def test_an_approach_from_a_gap_is_right_where_the_contact_was_resolved(adapter: Adapter) -> None:
    case = response([0.0, 0.0], [2.0, 0.5], [1.6, 0.3], [-1.0, 0.0], mb=2.0)
    assert isinstance(case, ResponseCase)
    obs = adapter.observe(case)
    assert obs.resolved_at is not None and obs.resolved_at != (case.a.center, case.b.center)
    pa, pb = obs.resolved_at
    assert norm([y - x for x, y in zip(pa, pb, strict=True)]) <= 1.0  # touching or overlapping
    moved = case.model_copy(update={"a": case.a.model_copy(update={"center": pa}),
                                    "b": case.b.model_copy(update={"center": pb})})
    truth = oracle.truth(moved)
    if adapter is TUNED:  # no friction, no rotation: the textbook there, within float32
        tol = 4 * adapter.conventions.rtol * 2.0
        assert within(obs.v1, truth.v1, tol) and within(obs.v2, truth.v2, tol)


def test_slow_approach_is_inelastic() -> None:
    case = response([0.0, 0.0], [0.25, 0.0], [1.0, 0.0], [0.0, 0.0])
    inelastic = oracle.truth(case.model_copy(update={"restitution": 0.0}))
    obs = TUNED.observe(case)
    assert within(obs.v1, inelastic.v1, F32_EPS) and within(obs.v2, inelastic.v2, F32_EPS)


@BOTH
def test_separating_pair_is_left_alone(adapter: Adapter) -> None:
    # The accumulated normal impulse is clamped at 0 (b2ContactSolver.cpp).
    assert adapter.conventions.resolves_separating is False
    obs = adapter.observe(response([0.0, 0.0], [-1.0, 0.0], [0.9, 0.0], [1.0, 0.0]))
    assert (obs.v1, obs.v2) == ((-1.0, 0.0), (1.0, 0.0))


def test_bodies_that_never_meet_are_left_alone() -> None:
    obs = TUNED.observe(response([0.0, 0.0], [-1.0, 0.0], [3.0, 0.0], [1.0, 0.0]))
    assert obs == Observation(v1=(-1.0, 0.0), v2=(1.0, 0.0), resolved_at=None)


def test_variant_settings_reach_the_world() -> None:
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0], ma=2.0, mb=3.0,
                    restitution=0.5)
    tuned, default = TUNED.prepare(case).built, DEFAULT.prepare(case).built
    assert (tuned["a"].mass, tuned["b"].mass, default["a"].mass, default["b"].mass) == (
        2.0, 3.0, 2.0, 3.0)
    fa, fb = tuned["a"].fixtures[0], tuned["b"].fixtures[0]
    assert (fa.restitution, fb.restitution, fa.friction) == (0.5, 0.0, 0.0)
    assert default["a"].fixtures[0].friction == pytest.approx(0.2)  # b2FixtureDef's default
    assert (tuned["a"].fixedRotation, default["a"].fixedRotation) == (True, False)
    assert default["a"].inertia == pytest.approx(0.5 * 2.0 * 0.5**2)
    assert (tuned["world"].GetAllowSleeping(), default["world"].GetAllowSleeping()) == (
        False, True)
    assert (TUNED.conventions.time_step, DEFAULT.conventions.time_step) == (1e-3, 1.0 / 60.0)


@BOTH
@pytest.mark.parametrize("case", [
    aabb([0.0, 0.0], [1.0, 1.0], [1.5, 0.5], [1.0, 1.0]),
    aabb([0.0, 0.0], [0.5, 0.5], [1.5, 0.3], [0.5, 0.5]),
    sphere(0.0, 3.0, dim=2),
    response([0.0, 0.0], [1.0, 0.5], [0.8, 0.6], [-1.0, 0.0], mb=3.0),
    response([0.0, 0.0], [2.0, 0.0], [0.25, 0.0], [-1.0, 0.0]),  # deep overlap
    response([0.0, 0.0], [2.0, 0.5], [1.6, 0.3], [-1.0, 0.0]),  # from a gap
], ids=["boxes", "boxes-apart", "circles", "oblique", "deep-overlap", "gap"])
def test_query_is_repeatable(adapter: Adapter, case: AnyCase) -> None:
    fresh = adapter.observe(case)
    prepared = adapter.prepare(case)
    assert adapter.query(prepared) == adapter.query(prepared) == adapter.query(prepared) == fresh
    adapter.release(prepared)


# --- refused inputs, capabilities, registry ------------------------------------------------------

@pytest.mark.parametrize(("case", "words"), [
    (aabb([0.0, 0.0], [-1.0, 1.0], [0.5, 0.0], [1.0, 1.0]), "negative size"),
    (disc([0.0, 0.0], math.nan, [0.0, 0.0], 1.0), "non-finite"),
    (aabb([-math.inf, 0.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0]), "non-finite"),
    (response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], ma=0.0), "mass"),
    (response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], restitution=-0.5),
     "restitution"),
], ids=["negative-half", "nan-radius", "inf-centre", "zero-mass", "negative-restitution"])
def test_inputs_box2d_mishandles_silently_are_refused(case: AnyCase, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        TUNED.prepare(case)


def test_nan_velocity_is_refused_by_box2d_itself() -> None:
    with pytest.raises(AssertionError, match=r"linearVelocity\.IsValid"):
        TUNED.prepare(response([0.0, 0.0], [math.nan, 0.0], [1.0, 0.0], [0.0, 0.0]))


def test_refused_and_faulty_inputs_are_recorded_and_the_run_goes_on(tmp_path: Path) -> None:
    bad = response([0.0, 0.0], [math.nan, 0.0], [1.0, 0.0], [0.0, 0.0], id="nan-velocity",
                   tags=["bad-input"])
    zero = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], ma=0.0, id="zero-mass",
                    tags=["bad-input"])
    after = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], id="after")
    store = ResultsStore(tmp_path / "box2d")
    run([bad, zero, after], [TUNED], store, RunOptions(quick=True))
    store.close()
    frame = read_results(tmp_path / "box2d").set_index(["case_id", "quantity"])
    assert frame.loc[("nan-velocity", "v1"), "status"] == "error"
    assert "AssertionError" in frame.loc[("nan-velocity", "v1"), "reason"]
    assert "SetMassData" in frame.loc[("zero-mass", "v1"), "reason"]
    assert set(frame.loc["after", "status"]) == {"agree"}  # exchanged exactly, even in float32


@BOTH
@pytest.mark.parametrize("case", [
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
    sphere(0.0, 1.0, dim=3),
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
], ids=["aabb", "sphere", "response"])
def test_3d_cases_are_unsupported_as_2d_engine(adapter: Adapter, case: AnyCase) -> None:
    reason = adapter.unsupported(case)
    assert reason is not None and "2-D engine" in reason


def test_registry_and_version() -> None:
    assert type(adapters.get("box2d")) is Box2dTuned
    assert type(adapters.get("box2d-default")) is Box2dDefault
    assert TUNED.version() == "2.3.10 (Box2D 2.3.0)"
    assert TUNED.conventions.box_extents.startswith("half")
    assert (TUNED.conventions.zero_mass, TUNED.conventions.negative_extents) == ("", "")
    assert all(s.startswith("https://") for s in TUNED.conventions.sources)


# Scenes (sphere_scene, 2-D): the scene calls of adapters/box2d/calls.py.

def scene_case(bodies: list[dict[str, Any]], restitution: float = 1.0, dt: float = 1e-3,
               duration: float = 3.0) -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": "s", "description": "d", "kind": "sphere_scene", "dim": 2,
        "duration": duration, "dt": dt, "restitution": restitution, "bodies": bodies})
    assert isinstance(case, SceneCase)
    return case


def disc_body(x: float, vx: float, mass: float = 1.0) -> dict[str, Any]:
    return {"center": [x, 0.0], "radius": 0.5, "mass": mass, "velocity": [vx, 0.0]}


HEAD_ON = [disc_body(-2.0, 1.0), disc_body(2.0123456789, -1.0)]
"""cases/scenes.toml's scene-2d-head-on: equal discs meet at t = 1.506..., off the steps."""


def stepped(adapter: Adapter, case: SceneCase) -> Observation:
    prepared = adapter.prepare(case)
    try:
        return adapter.query(prepared)
    finally:
        adapter.release(prepared)


def test_scenes_are_a_2d_capability_of_both_variants() -> None:
    for adapter in (TUNED, DEFAULT):
        assert (Kind.SPHERE_SCENE, 2) in adapter.capabilities
        assert (Kind.SPHERE_SCENE, 3) not in adapter.capabilities
    assert TUNED.scene_tuning == TUNED.variant and DEFAULT.scene_tuning is None


@pytest.mark.parametrize("dt", [1e-3, 1.0 / 60.0, 0.1])
def test_scene_elastic_head_on_pair_exchanges_velocities_exactly(dt: float) -> None:
    # Declared (adapters/box2d/scene.py): the exchange is exact, momentum and energy too, at any dt.
    case = scene_case(HEAD_ON, dt=dt)
    got = stepped(TUNED, case)
    want = scenes.truth(case)
    assert got.velocities == want.velocities == ((-1.0, 0.0), (1.0, 0.0))
    assert got.momentum == (0.0, 0.0) and got.energy == 1.0
    assert isinstance(got.positions, tuple) and isinstance(want.positions, tuple)
    lag = 2 * 1.0 * dt  # met at most a step late, one step's travel at speed 1 each way
    for mine, exact in zip(got.positions, want.positions, strict=True):
        assert math.dist(mine, exact) <= lag


@BOTH
def test_scene_restitution_is_the_scenes_on_every_pair(adapter: Adapter) -> None:
    # max(e, e) = e: masses 1 and 2 at +-1, e = 0.5 -> -1 and 0 by the textbook formula.
    got = stepped(adapter, scene_case([disc_body(-2.0, 1.0), disc_body(2.0123456789, -1.0, 2.0)],
                                      restitution=0.5))
    assert got.velocities == ((-1.0, 0.0), (0.0, 0.0))


@BOTH
def test_scene_approach_at_the_threshold_is_inelastic(adapter: Adapter) -> None:
    # b2_velocityThreshold (1 m/s, compiled in): no bounce at exactly 1, one above 1 + 2^-23.
    at = stepped(adapter, scene_case([disc_body(-1.0, 0.5), disc_body(1.0, -0.5)]))
    assert at.velocities == ((0.0, 0.0), (0.0, 0.0))
    half = (1.0 + F32_EPS) / 2
    above = stepped(adapter, scene_case([disc_body(-1.0, half), disc_body(1.0, -half)]))
    assert above.velocities == ((-half, 0.0), (half, 0.0))


def test_scene_speed_cap_is_two_metres_a_step() -> None:
    case = scene_case([disc_body(0.0, 30.0)], dt=0.1, duration=0.1)
    got = stepped(TUNED, case)
    assert got.velocities == ((b2e.MAX_TRANSLATION / 0.1, 0.0),)
    assert got.positions == ((b2e.MAX_TRANSLATION, 0.0),)


class LoggedWorld:
    """A world whose ``Step`` calls are logged (and passed on to Box2D)."""

    def __init__(self, world: Any, log: list[str]) -> None:
        self.world, self.log = world, log

    def Step(self, *args: Any) -> None:  # Box2D's name
        self.log.append("step")
        self.world.Step(*args)


def test_scene_clock_reads_only_around_the_stepping_loop() -> None:
    # Injected time: the clock's readings and the steps go to one log; no clock is real.
    log: list[str] = []
    readings = iter([10.0, 10.5, 20.0, 22.25])

    def clock() -> float:
        log.append("clock")
        return next(readings)

    bodies: list[Body] = [((-2.0, 0.0), 0.5, 1.0, (1.0, 0.0)), ((2.0, 0.0), 0.5, 1.0, (-1.0, 0.0))]
    scenes = SceneCalls(TUNED)
    built = scenes.prepare_scene(bodies, 2, 1.0, 1e-3, None, scenes.settings())
    world = built["world"]
    built["world"] = LoggedWorld(world, log)
    try:
        idle = scenes.run_scene(built, 0, clock=clock)
        assert log == ["clock", "clock"]
        log.clear()
        ran = scenes.run_scene(built, 7, clock=clock)
        assert log == ["clock", *["step"] * 7, "clock"]
    finally:
        built["world"] = world
        scenes.release_scene(built)
    assert (idle.steps, ran.steps) == (0, 7)
    assert (idle.wall_s, ran.wall_s) == (0.5, 2.25)
    assert ran.positions[0][0] == pytest.approx(-2.0 + 7e-3, abs=F32_EPS * 4)


@pytest.mark.parametrize(("bodies", "dim", "restitution", "match"), [
    ([((0.0, 0.0), 0.5, 0.0, (1.0, 0.0))], 2, 1.0, "mass"),  # Box2D reads mass 0 as 1
    ([((0.0, 0.0), 0.5, 1.0, (1.0, 0.0))], 2, -0.5, "restitution"),
    ([((0.0, 0.0), -0.5, 1.0, (1.0, 0.0))], 2, 1.0, "radius"),
    ([((0.0, 0.0), 0.5, 1.0, (math.nan, 0.0))], 2, 1.0, "finite"),
    ([((0.0, 0.0, 0.0), 0.5, 1.0, (1.0, 0.0, 0.0))], 3, 1.0, "2-D"),
], ids=["zero-mass", "negative-restitution", "negative-radius", "nan-velocity", "3d"])
def test_scene_bad_input_is_refused_before_box2d_sees_it(bodies: list[Body], dim: int,
                                                         restitution: float, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        scenes = SceneCalls(DEFAULT)
        scenes.prepare_scene(bodies, dim, restitution, 1e-3, None, scenes.settings())


def test_scene_negative_steps_are_refused() -> None:
    scenes = SceneCalls(DEFAULT)
    built = scenes.prepare_scene([((0.0, 0.0), 0.5, 1.0, (1.0, 0.0))], 2, 1.0, 1e-3, None,
                                 scenes.settings())
    try:
        with pytest.raises(ValueError, match="steps"):
            scenes.run_scene(built, -1)
    finally:
        scenes.release_scene(built)
