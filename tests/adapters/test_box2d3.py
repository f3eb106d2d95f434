"""The Box2D v3 adapters: pinned native behaviour of Box2D 3.1.1 (pyb2d3 0.11.1), the translation.

The conformance tests pin what the engine does natively and the adapter relies on (touching is
a manifold with points, speculative up to 4 linear slops; the restitution threshold; the speed
cap; mass 0 immovable; bullets not swept against bullets), each expected value derived from
Box2D's source constants, never copied from the engine's output.  The translation tests check
the adapter against the exact oracle within the declared float32 precision.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

pyb2d3 = pytest.importorskip("pyb2d3")

import adapters  # noqa: E402
from adapters import box2d3 as b3  # noqa: E402
from adapters.box2d3 import Box2d3Bullet, Box2d3Default, Box2d3Tuned  # noqa: E402
from adapters.box2d3.scene import REST_SINK_S2  # noqa: E402
from crosscheck.core.contract import Adapter  # noqa: E402
from crosscheck.core.geometry import norm  # noqa: E402
from crosscheck.core.model import Category, Kind  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AnyCase  # noqa: E402
from crosscheck.truth import oracle  # noqa: E402
from crosscheck.truth.score import judge  # noqa: E402
from tests.adapters.scene_calls import SceneCalls, Surroundings, Wall  # noqa: E402
from tests.conftest import aabb, response  # noqa: E402

pytestmark = pytest.mark.engine

TUNED, DEFAULT, BULLET = Box2d3Tuned(), Box2d3Default(), Box2d3Bullet()
BOTH = pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=["box2d3", "box2d3-default"])
F32_EPS = 2.0**-23


def disc(ca: tuple[float, float], ra: float, cb: tuple[float, float], rb: float) -> AnyCase:
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": 2,
        "a": {"center": list(ca), "radius": ra}, "b": {"center": list(cb), "radius": rb}})


def begin_events(gap: float) -> list[Any]:
    """Two unit discs (r 0.5) ``gap`` apart on x, at rest, stepped once: the begin events."""
    world = pyb2d3.World(gravity=(0.0, 0.0))
    sd = pyb2d3.shape_def(enable_contact_events=True)
    for x in (0.0, 1.0 + gap):
        body = world.create_dynamic_body(position=(x, 0.0))
        body.create_shape(sd, pyb2d3.circle(radius=0.5))
    world.step(1.0 / 60.0, 4)
    return [event.manifold for event in world.get_contact_events().begin_events()]


def tolerance(adapter: Adapter, size: float) -> float:
    conv = adapter.conventions
    return conv.margin_for("sphere") + conv.rtol * size


# --- native behaviour (conformance) ----------------------------------------------------------

def test_touching_is_a_manifold_with_points_up_to_the_speculative_distance() -> None:
    # contact.c: touching = pointCount > 0; manifold.c keeps points up to
    # B2_SPECULATIVE_DISTANCE = 4 B2_LINEAR_SLOP apart: the begin-touch event fires there.
    assert b3.SPECULATIVE_DISTANCE == 4 * b3.LINEAR_SLOP == 0.02
    band = b3.SPECULATIVE_DISTANCE
    for gap in (-0.1, 0.0, 0.5 * band, 0.99 * band):
        (manifold,) = begin_events(gap)
        assert manifold.point_count == 1
        (point,) = list(manifold.points())
        assert point.separation == pytest.approx(gap, abs=4 * F32_EPS)
    assert begin_events(1.01 * band) == []
    for adapter in (TUNED, DEFAULT):
        conv = adapter.conventions
        assert all(conv.verdict_margin_for(f) == band for f in ("sphere", "face", "corner"))
        assert all(conv.touching_is_contact(f) for f in ("sphere", "face", "corner"))


def test_distance_and_time_of_impact_are_not_bound_in_pyb2d3_0_11_1() -> None:
    # src/export_collision.cpp wraps them in #if 0: no sphere_toi capability.
    for name in ("time_of_impact", "shape_distance", "make_proxy", "shape_cast"):
        assert not hasattr(pyb2d3, name)
    assert all(kind is not Kind.SPHERE_TOI for kind, _ in TUNED.capabilities)


def head_on(speed: float, adapter: Adapter = TUNED) -> Any:
    return adapter.observe(response([0.0, 0.0], [speed, 0.0], [1.0, 0.0], [0.0, 0.0]))


def test_restitution_threshold_is_one_and_an_approach_of_one_bounces() -> None:
    # contact_solver.c skips restitution when relativeVelocity + threshold > 0: at exactly
    # -1 + 1 = 0 it bounces; one float32 unit below 1 it does not.
    assert pyb2d3.WorldDef().restitution_threshold == 1.0
    at = head_on(1.0)
    assert (at.v1, at.v2) == ((0.0, 0.0), (1.0, 0.0))
    below = 1.0 - 2.0**-24
    slow = head_on(below)
    assert slow.v1 == pytest.approx((below / 2, 0.0), abs=F32_EPS)
    assert slow.v2 == pytest.approx((below / 2, 0.0), abs=F32_EPS)
    for adapter in (TUNED, DEFAULT):
        assert adapter.conventions.restitution_threshold == b3.THRESHOLD == 1.0


def test_speed_cap_default_and_tuned() -> None:
    # b2DefaultWorldDef: 400 m/s, clamped in every sub-step's velocity integration (solver.c).
    assert pyb2d3.WorldDef().maximum_linear_speed == b3.DEFAULT_MAX_SPEED
    for adapter, speed, want in ((DEFAULT, 1000.0, b3.DEFAULT_MAX_SPEED), (TUNED, 1000.0, 1000.0)):
        scenes = SceneCalls(adapter)
        built = scenes.prepare_scene([((0.0, 0.0), 0.5, 1.0, (speed, 0.0))], 2, 1.0, 1e-3, None,
                                     scenes.settings())
        try:
            run = scenes.run_scene(built, 1)
        finally:
            scenes.release_scene(built)
        assert run.velocities[0][0] == pytest.approx(want, rel=F32_EPS)
        assert adapter.conventions.max_speed == (
            b3.DEFAULT_MAX_SPEED if adapter is DEFAULT else b3.B2_HUGE)


def test_mass_zero_is_immovable() -> None:
    # body.c: invMass = mass > 0 ? 1 / mass : 0.  A at rest with mass 0, B hits it at 2:
    # A stays, B bounces back (e = 1), as off a static body.
    obs = TUNED.observe(response([0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [-2.0, 0.0], ma=0.0))
    assert obs.v1 == (0.0, 0.0)
    assert obs.v2 == pytest.approx((2.0, 0.0), abs=4 * F32_EPS)
    assert TUNED.conventions.zero_mass == "static"


@pytest.mark.parametrize(("case", "words"), [
    (aabb([0.0, 0.0], [-1.0, 1.0], [0.5, 0.0], [1.0, 1.0]), "negative size"),
    (disc((0.0, 0.0), math.nan, (0.0, 0.0), 1.0), "non-finite"),
    (aabb([-math.inf, 0.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0]), "non-finite"),
    (response([0.0, 0.0], [math.nan, 0.0], [1.0, 0.0], [0.0, 0.0]), "non-finite velocity"),
    (response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], ma=-1.0), "mass"),
    (response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], restitution=-0.5),
     "restitution"),
], ids=["negative-half", "nan-radius", "inf-centre", "nan-velocity", "negative-mass",
        "negative-restitution"])
def test_inputs_box2d_takes_unchecked_are_refused(case: AnyCase, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        TUNED.prepare(case)


def test_the_release_build_takes_a_nan_position_and_a_negative_box_unchecked() -> None:
    # Why the adapter refuses them: no B2_ASSERT in pyb2d3's build (base.h).
    world = pyb2d3.World(gravity=(0.0, 0.0))
    body = world.create_dynamic_body(position=(math.nan, 0.0))
    body.create_shape(pyb2d3.shape_def(), pyb2d3.circle(radius=0.5))
    world.step(1.0 / 60.0, 4)
    assert math.isnan(body.position.x)
    world = pyb2d3.World(gravity=(0.0, 0.0))
    sd = pyb2d3.shape_def(enable_contact_events=True)
    for x, hx in ((0.0, -0.5), (0.6, 0.5)):  # overlapping by 0.4 were -0.5 read as 0.5
        world.create_dynamic_body(position=(x, 0.0)).create_shape(sd, pyb2d3.box(hx, 0.5))
    world.step(1.0 / 60.0, 4)
    assert world.get_contact_events().begin_count == 0


def test_bullets_are_not_swept_against_bullets() -> None:
    # simulation.md: bullets "perform CCD with all body types, but not other bullets".  Two
    # bullets (r 0.05) head-on at 30 m/s each, dt 1/60: one step's closing travel is 1 m, and
    # the centres 2.5, 1.5, 0.5, -0.5 apart at step starts never within 0.1 + 0.02 of each
    # other: they pass through each other.
    assert BULLET.conventions.sampled_contacts and BULLET.variant.bullet
    scenes = SceneCalls(BULLET)
    bodies = [((-1.25, 0.0), 0.05, 1.0, (30.0, 0.0)), ((1.25, 0.0), 0.05, 1.0, (-30.0, 0.0))]
    built = scenes.prepare_scene(bodies, 2, 1.0, 1.0 / 60.0, None, scenes.settings())
    try:
        assert all(d.bullet for d in built["discs"])
        run = scenes.run_scene(built, 6)
    finally:
        scenes.release_scene(built)
    assert run.velocities == ((30.0, 0.0), (-30.0, 0.0))
    assert run.positions[0][0] > run.positions[1][0]


# --- translation: detection ------------------------------------------------------------------

DIRECTIONS = [k * math.pi / 6 for k in range(12)]


@BOTH
@pytest.mark.parametrize("radii", [(0.5, 0.5), (0.1, 2.0), (3.0, 0.25)])
@pytest.mark.parametrize("gap", [-0.3, -1e-3, 0.0, 0.01, 0.05, 1.0])
def test_circles_against_the_oracle_over_directions(adapter: Adapter, radii: tuple[float, float],
                                                    gap: float) -> None:
    ra, rb = radii
    for angle in DIRECTIONS:
        d = ra + rb + gap
        case = disc((0.25, -0.5), ra, (0.25 + d * math.cos(angle), -0.5 + d * math.sin(angle)), rb)
        obs, truth = adapter.observe(case), oracle.truth(case)
        assert isinstance(truth.distance, float)
        touching = truth.distance <= b3.SPECULATIVE_DISTANCE
        assert obs.hit is touching
        if not touching:
            assert (obs.distance, obs.normal) == (None, None)
            continue
        tol = tolerance(adapter, 0.5 + d)
        assert isinstance(obs.distance, float) and abs(obs.distance - truth.distance) <= tol
        assert isinstance(obs.normal, tuple) and isinstance(truth.normal, tuple)
        assert norm([x - y for x, y in zip(obs.normal, truth.normal, strict=True)]) <= 1e-6


@BOTH
@pytest.mark.parametrize(("cb", "hb"), [
    ([0.9, 0.3], [0.5, 0.5]), ([-0.3, 1.2], [0.5, 0.75]), ([0.0, -1.01], [2.0, 0.5]),
    ([-1.505, 0.2], [1.0, 0.5]), ([1.5, 0.0], [1.0, 1.0]), ([1.01, 1.01], [0.5, 0.5]),
], ids=["+x-overlap", "+y-overlap", "-y-speculative", "-x-speculative", "apart", "corner-band"])
def test_boxes_against_the_oracle(adapter: Adapter, cb: list[float], hb: list[float]) -> None:
    case = aabb([0.0, 0.0], [0.5, 0.5], cb, hb)
    obs, truth = adapter.observe(case), oracle.truth(case)
    assert isinstance(truth.distance, float)
    touching = truth.distance <= b3.SPECULATIVE_DISTANCE
    assert obs.hit is touching
    if touching:
        assert isinstance(obs.distance, float)
        assert abs(obs.distance - truth.distance) <= tolerance(adapter, 3.0)
        assert isinstance(obs.normal, tuple) and isinstance(truth.normal, tuple)
        assert norm([x - y for x, y in zip(obs.normal, truth.normal, strict=True)]) <= 1e-6


def test_detection_is_repeatable_on_one_prepared_pair() -> None:
    case = disc((0.0, 0.0), 0.5, (0.6, 0.5), 0.5)
    prepared = TUNED.prepare(case)
    try:
        first = TUNED.query(prepared)
        assert all(TUNED.query(prepared) == first for _ in range(4))
    finally:
        TUNED.release(prepared)
    assert first == TUNED.observe(case)


def test_coincident_centres_have_no_normal() -> None:
    obs = TUNED.observe(disc((1.0, 2.0), 0.5, (1.0, 2.0), 0.25))
    assert obs.hit is True and obs.distance == pytest.approx(-0.75, abs=F32_EPS)
    assert "zero vector" in str(obs.normal)


# --- translation: response and scenes ---------------------------------------------------------

@BOTH
@pytest.mark.parametrize("e, mb", [(1.0, 1.0), (0.5, 3.0), (0.0, 2.0)])
def test_touching_head_on_response_is_the_textbook(adapter: Adapter, e: float, mb: float) -> None:
    case = response([0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [-1.0, 0.0], mb=mb, restitution=e)
    obs, truth = adapter.observe(case), oracle.truth(case)
    assert obs.resolved_at == ((0.0, 0.0), (1.0, 0.0))
    for mine, want in ((obs.v1, truth.v1), (obs.v2, truth.v2)):
        assert isinstance(mine, tuple) and isinstance(want, tuple)
        assert norm([x - y for x, y in zip(mine, want, strict=True)]) <= 8 * F32_EPS * 3.0


def test_separating_pair_is_left_alone() -> None:
    assert TUNED.conventions.resolves_separating is False
    obs = TUNED.observe(response([0.0, 0.0], [-1.0, 0.0], [3.0, 0.0], [1.0, 0.0]))
    assert (obs.v1, obs.v2, obs.resolved_at) == ((-1.0, 0.0), (1.0, 0.0), None)


def run_scene(adapter: Adapter, bodies: list[Any], e: float, dt: float, steps: int,
              surroundings: Surroundings | None = None, record_every: int = 0) -> Any:
    scenes = SceneCalls(adapter)
    built = scenes.prepare_scene(bodies, 2, e, dt, None, scenes.settings(), surroundings)
    try:
        return scenes.run_scene(built, steps, record_every=record_every)
    finally:
        scenes.release_scene(built)


@pytest.mark.parametrize("adapter", [TUNED, DEFAULT, BULLET], ids=lambda a: a.name)
def test_scene_head_on_pair_exchanges_velocities(adapter: Adapter) -> None:
    bodies = [((-2.0, 0.0), 0.5, 1.0, (1.0, 0.0)), ((2.0123456789, 0.0), 0.5, 1.0, (-1.0, 0.0))]
    got = run_scene(adapter, bodies, 1.0, 1.0 / 60.0, 180)
    flat = [x for v in got.velocities for x in v]
    assert flat == pytest.approx([-1.0, 0.0, 1.0, 0.0], abs=8 * F32_EPS)


@pytest.mark.parametrize("adapter", [TUNED, DEFAULT, BULLET], ids=lambda a: a.name)
@pytest.mark.parametrize("speed", [60.0, 300.0])
def test_a_fast_disc_bounces_off_a_wall_instead_of_tunnelling(adapter: Adapter,
                                                              speed: float) -> None:
    # Continuous collision against static bodies (enableContinuous, on in every variant): a
    # disc (r 0.05) at up to 5 m a step, 50 diameters, comes back from the wall at x = 1.
    wall = Surroundings((0.0, 0.0), (Wall((-1.0, 0.0), -1.0),))
    got = run_scene(adapter, [((0.0, 0.0), 0.05, 1.0, (speed, 0.0))], 1.0, 1.0 / 60.0, 3, wall)
    assert got.velocities[0][0] == pytest.approx(-speed, rel=8 * F32_EPS)
    assert got.positions[0][0] <= 1.0 - 0.05 + 1e-6


@pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=lambda a: a.name)
def test_a_resting_disc_sags_within_the_declared_soft_contact(adapter: Adapter) -> None:
    g, r, dt = 9.81, 0.1, 1.0 / 60.0
    ground = Surroundings((0.0, -g), (Wall((0.0, 1.0), 0.0),))
    got = run_scene(adapter, [((0.0, r), r, 1.0, (0.0, 0.0))], 0.0, dt, 120, ground,
                    record_every=1)
    gap = got.samples.positions[:, 0, 1] - r
    lo, hi = adapter.conventions.rest_gap
    assert gap.min() >= lo - REST_SINK_S2 * g - b3.RTOL
    assert gap.max() <= hi + b3.RTOL
    assert gap.max() - gap.min() <= b3.LINEAR_SLOP


# --- registry, capabilities -----------------------------------------------------------------

def test_registry_version_and_capabilities() -> None:
    assert type(adapters.get("box2d3")) is Box2d3Tuned
    assert type(adapters.get("box2d3-default")) is Box2d3Default
    assert type(adapters.get("box2d3-bullet")) is Box2d3Bullet
    assert TUNED.version() == f"0.11.1 (Box2D {b3.BOX2D_VERSION})"
    assert TUNED.package == "pyb2d3" and TUNED.available() is None
    assert BULLET.capabilities == {(Kind.SPHERE_SCENE, 2)}
    assert all(s.startswith("https://github.com/") for s in TUNED.conventions.sources)
    reason = TUNED.unsupported(CASE_ADAPTER.validate_python({
        "id": "s", "description": "d", "kind": "sphere", "dim": 3,
        "a": {"center": [0, 0, 0], "radius": 1}, "b": {"center": [1, 0, 0], "radius": 1}}))
    assert reason is not None and "2-D engine" in reason


@pytest.mark.parametrize("speed, e, mb", [(1000.0, 1.0, 1.0), (3000.0, 1.0, 1.0),
                                          (1000.0, 0.5, 2.0)])
def test_a_capped_response_is_the_declared_cap_before_the_contact_solve(speed: float, e: float,
                                                                        mb: float) -> None:
    # solver.c clamps the velocities the contact solve starts from; contact_solver.c bounces
    # with the approach the step started with: the plastic response of the capped velocities
    # plus e times the uncapped approach (momentum is not kept).
    case = response([0.0, 0.0], [speed, 0.0], [1.0, 0.0], [0.0, 0.0], mb=mb, restitution=e)
    obs, truth = DEFAULT.observe(case), oracle.truth(case)
    assert DEFAULT.conventions.max_speed_at == "before the contact solve"
    cap = b3.DEFAULT_MAX_SPEED
    common = cap / (1.0 + mb)  # the plastic velocity of A at the cap and B at rest
    want_a, want_b = common - mb / (1.0 + mb) * e * speed, common + e * speed / (1.0 + mb)
    assert obs.v1 == pytest.approx((want_a, 0.0), rel=8 * F32_EPS, abs=1e-3)
    assert obs.v2 == pytest.approx((want_b, 0.0), rel=8 * F32_EPS, abs=1e-3)
    for quantity in ("v1", "v2"):
        verdict = judge(case, DEFAULT.conventions, quantity, obs.get(quantity), truth, obs)
        assert verdict.category == Category.CONVENTION and "speed cap" in verdict.reason
