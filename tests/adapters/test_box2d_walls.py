"""Box2D scenes with gravity and static walls (the scene calls of ``adapters/box2d/calls.py``,
``wall_boxes``).

Expected values come from closed forms (free fall, an elastic bounce between two walls, a
frictionless slide, a disc set rolling by friction) and from the conventions the variants
declare (Box2D's b2Settings.h constants among them), never from an engine run.  Box2D is
float32: positions are compared within ``RTOL`` of their size.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import pytest

pytest.importorskip("Box2D")

from adapters.box2d import RTOL, Box2dBullet, Box2dDefault, Box2dTuned
from adapters.box2d.scene import POLYGON_RADIUS
from tests.adapters.scene_calls import SceneCalls, Surroundings, Wall

pytestmark = pytest.mark.engine

G = 9.81
R = 0.1
VARIANTS = [Box2dTuned(), Box2dDefault(), Box2dBullet()]
IDS = [v.name for v in VARIANTS]
box2d_scene = SceneCalls(Box2dTuned())
"""Box2D's scene calls with a scene module's interface (a variant's settings passed in)."""
DEFAULTS = Box2dDefault().scene_settings()
GROUND = Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0),))


def disc(x: float, y: float, vx: float = 0.0, vy: float = 0.0) -> Any:
    return ((x, y), R, 1.0, (vx, vy))


def run(variant: Any, bodies: list[Any], e: float, dt: float, steps: int,
        surroundings: Surroundings | None, record_every: int = 0, clock: Any = None) -> Any:
    prepared = box2d_scene.prepare_scene(bodies, 2, e, dt, None, variant.scene_settings(),
                                         surroundings)
    try:
        extra = {} if clock is None else {"clock": clock}
        return box2d_scene.run_scene(prepared, steps, record_every=record_every, **extra)
    finally:
        box2d_scene.release_scene(prepared)


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1e-3])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_dropped_disc_turns_back_within_a_step_of_the_free_fall_time(variant: Any,
                                                                       dt: float) -> None:
    # Bottom 1 m above the ground: it reaches it at sqrt(2 h / g).  Box2D finds contacts at
    # step starts and then solves them, so it turns back within a step and a half of that,
    # earlier by the time it takes to cross the declared band's top (the skin) at the
    # impact speed.
    h = 1.0
    scene = run(variant, [disc(0.0, h + R)], 1.0, dt, round(1.0 / dt), GROUND, record_every=1)
    up = scene.samples.velocities[:, 0, 1]
    turned = next(k for k in range(1, len(up)) if up[k] > 0.0) * dt
    exact = math.sqrt(2.0 * h / G)
    lo, hi = variant.conventions.rest_gap
    speed = math.sqrt(2.0 * G * h)
    assert exact - dt - hi / speed <= turned <= exact + 1.5 * dt + abs(lo) / speed


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1.0 / 240.0])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_column_set_on_the_ground_stays_within_the_declared_band_and_sink(
        variant: Any, dt: float) -> None:
    # Three discs touching each other and the ground, 3 s: every gap within rest_gap, down
    # to rest_sink_steps |g| dt^2 below it (float32 positions: RTOL of the column's height).
    c = variant.conventions
    lo, hi = c.rest_gap
    floor = lo - c.rest_sink_steps * G * dt * dt - RTOL
    bodies = [disc(0.0, R), disc(0.0, 3 * R), disc(0.0, 5 * R)]
    scene = run(variant, bodies, 0.5, dt, round(3.0 / dt), GROUND, record_every=5)
    y = scene.samples.positions[:, :, 1]
    gaps = [y[:, 0] - R, y[:, 1] - y[:, 0] - 2 * R, y[:, 2] - y[:, 1] - 2 * R]
    for gap in gaps:
        assert floor <= gap.min() and gap.max() <= hi + RTOL


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1.0 / 240.0])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_disc_set_on_the_ground_rests_and_sleeps_as_declared(variant: Any, dt: float) -> None:
    # One disc on the ground, 3 s: within the band, and after b2_timeToSleep (0.5 s) at
    # speed exactly 0 when the variant declares sleeping; without sleeping no faster than
    # one step of gravity.
    c = variant.conventions
    lo, hi = c.rest_gap
    scene = run(variant, [disc(0.0, R)], 0.0, dt, round(3.0 / dt), GROUND, record_every=1)
    gap = scene.samples.positions[:, 0, 1] - R
    assert lo - c.rest_sink_steps * G * dt * dt - RTOL <= gap.min()
    assert gap.max() <= hi + RTOL
    late = abs(scene.samples.velocities[round(1.0 / dt):])
    if c.sleeps:
        assert late.max() == 0.0
    assert late.max() <= G * dt


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1e-3])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_disc_between_two_walls_keeps_its_speed_and_bounces_on_time(variant: Any,
                                                                      dt: float) -> None:
    # Zero gravity, walls at x = -1 and 1, speed 3 (above b2_velocityThreshold), e = 1: |v|
    # stays 3 (declared rtol), and the bounces fall at 0.3 + 0.6 k s: 8 of them in 5 s.
    walls = Surroundings((0.0, 0.0), (Wall((1.0, 0.0), -1.0), Wall((-1.0, 0.0), -1.0)))
    scene = run(variant, [disc(0.0, 0.0, vx=3.0)], 1.0, dt, round(5.0 / dt), walls,
                record_every=1)
    vx = scene.samples.velocities[:, 0, 0]
    assert abs(abs(vx) - 3.0).max() <= 3.0 * variant.conventions.rtol
    assert sum(1 for a, b in itertools.pairwise(vx) if a * b < 0) == 8
    x = scene.samples.positions[:, 0, 0]
    assert abs(x).max() <= 1.0 - R + 3.0 * dt  # never more than a step into a wall


@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_sliding_on_the_ground_keeps_the_speed_only_without_friction(variant: Any) -> None:
    # Tuned (friction 0 on discs and walls, no rotation): the speed is kept.  Default
    # (b2FixtureDef's 0.2, rotation free): friction slows the disc down to rolling, which
    # for a uniform disc about a contact at least r - b2_polygonRadius below its centre is
    # v0 / (1 + (r / a)^2 / 2), and no lower.
    scene = run(variant, [disc(0.0, R, vx=1.0)], 0.0, 1.0 / 60.0, 60, GROUND)
    vx = scene.velocities[0][0]
    friction = variant.conventions.friction
    if friction == 0.0:
        assert vx == 1.0
    else:
        arm = R - POLYGON_RADIUS
        assert 1.0 / (1.0 + 0.5 * (R / arm) ** 2) <= vx < 1.0


def test_a_wall_normal_that_is_not_an_axis_raises_naming_the_wall() -> None:
    bad = Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0), Wall((0.0, 2.0), 2.0)))
    with pytest.raises(ValueError, match="wall 1"):
        box2d_scene.prepare_scene([disc(0.0, R)], 2, 1.0, 1e-3, None, DEFAULTS, bad)
    with pytest.raises(ValueError, match="wall 0: the offset"):
        box2d_scene.prepare_scene([disc(0.0, R)], 2, 1.0, 1e-3, None, DEFAULTS,
                                  Surroundings((0.0, -G), (Wall((0.0, 1.0), math.inf),)))


@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_open_space_is_gravity_zero_and_no_walls(variant: Any) -> None:
    bodies = [disc(0.0, 0.0, vx=2.0, vy=0.5), disc(0.5, 0.1, vx=-2.0)]
    plain = run(variant, bodies, 0.8, 1e-3, 500, None)
    none = run(variant, bodies, 0.8, 1e-3, 500, Surroundings.none(2))
    assert plain.positions == none.positions and plain.velocities == none.velocities
    prepared = box2d_scene.prepare_scene(bodies, 2, 0.8, 1e-3, None, variant.scene_settings())
    assert tuple(prepared["world"].gravity) == (0.0, 0.0) and prepared["planes"] == ()
    box2d_scene.release_scene(prepared)


@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_walls_are_static_boxes_with_the_variants_skin_and_e(variant: Any) -> None:
    b2 = pytest.importorskip("Box2D")
    walls = (Wall((0.0, 1.0), 0.0), Wall((-1.0, 0.0), -2.0))
    prepared = box2d_scene.prepare_scene([disc(0.0, R)], 2, 0.3, 1e-3, None,
                                         variant.scene_settings(), Surroundings((0.0, -G), walls))
    try:
        _, skin = variant.conventions.rest_gap
        for body in prepared["planes"]:
            assert body.type == b2.b2_staticBody
            (fixture,) = body.fixtures
            assert fixture.restitution == pytest.approx(0.3)
            assert fixture.shape.radius == pytest.approx(skin)
        ground, side = ([body.GetWorldPoint(v) for v in body.fixtures[0].shape.vertices]
                        for body in prepared["planes"])
        assert max(p[1] for p in ground) == 0.0 and min(p[0] for p in side) == 2.0
    finally:
        box2d_scene.release_scene(prepared)


def test_samples_have_the_scene_shape_and_the_wall_time_comes_from_the_clock() -> None:
    ticks = iter(range(100))
    scene = run(Box2dTuned(), [disc(0.0, R), disc(1.0, 0.5)], 1.0, 1e-3, 10, GROUND,
                record_every=4, clock=lambda: float(next(ticks)))
    assert scene.samples.every == 4
    assert scene.samples.positions.shape == (4, 2, 2)  # steps 0, 4, 8, 10
    assert scene.samples.velocities.shape == (4, 2, 2)
    assert tuple(scene.samples.positions[-1, 1]) == scene.positions[1]
    assert scene.wall_s == 3.0  # three timed runs of steps, one tick each
    assert scene.samples.positions[0, 1, 1] == 0.5
