"""pymunk scenes with gravity and static walls (``adapters/pymunk/calls.py``, ``wall_boxes``).

Expected values come from closed forms (free fall, an elastic bounce between two walls, a
frictionless slide) and from the conventions the variants declare, never from an engine run.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import pytest

pytest.importorskip("pymunk")

from adapters.pymunk import PymunkDefault, PymunkTuned
from tests.adapters.scene_calls import SceneCalls, Surroundings, Wall

pytestmark = pytest.mark.engine

G = 9.81
R = 0.1
VARIANTS = [PymunkTuned(), PymunkDefault()]
IDS = [v.name for v in VARIANTS]
GROUND = Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0),))


def disc(x: float, y: float, vx: float = 0.0, vy: float = 0.0, r: float = R) -> Any:
    return ((x, y), r, 1.0, (vx, vy))


def run(variant: Any, bodies: list[Any], e: float, dt: float, steps: int,
        surroundings: Surroundings | None, record_every: int = 0, clock: Any = None) -> Any:
    scenes = SceneCalls(variant)
    prepared = scenes.prepare_scene(bodies, 2, e, dt, None, scenes.settings(), surroundings)
    try:
        extra = {} if clock is None else {"clock": clock}
        return scenes.run_scene(prepared, steps, record_every=record_every, **extra)
    finally:
        scenes.release_scene(prepared)


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1e-3])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_dropped_disc_turns_back_within_the_step_of_the_free_fall_time(variant: Any,
                                                                          dt: float) -> None:
    # Bottom 1 m above the ground: it reaches it at sqrt(2 h / g).  pymunk moves before it
    # collides, with the velocity of the step before, so it turns back in the step that
    # first overlaps: at most 1.5 steps after the exact time (and not before it).
    h = 1.0
    scene = run(variant, [disc(0.0, h + R)], 1.0, dt, round(1.0 / dt), GROUND, record_every=1)
    up = scene.samples.velocities[:, 0, 1]
    turned = next(k for k in range(1, len(up)) if up[k] > 0.0) * dt
    exact = math.sqrt(2.0 * h / G)
    assert exact <= turned <= exact + 1.5 * dt


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1.0 / 240.0])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_an_elastic_drop_keeps_its_apex_as_declared(variant: Any, dt: float) -> None:
    # Declared: the bounce is read before the step's gravity, so e = 1 keeps the height;
    # a sampled apex is within one step's fall, g dt^2, of it.
    h = 1.0
    scene = run(variant, [disc(0.0, h + R)], 1.0, dt, round(5.0 / dt), GROUND, record_every=1)
    y = scene.samples.positions[:, 0, 1] - R
    up = scene.samples.velocities[:, 0, 1]
    apexes = [max(y[k - 1], y[k]) for k in range(1, len(up)) if up[k - 1] > 0.0 >= up[k]]
    assert len(apexes) >= 4  # 5 s of 0.9 s round trips
    assert all(abs(a - h) <= G * dt * dt for a in apexes)


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1.0 / 240.0])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_disc_set_on_the_ground_stays_touching_it(variant: Any, dt: float) -> None:
    # A disc touching a Poly is a contact (d <= r): no fall, no sink, speed 0; the gap is
    # the declared band's top (touching), within the band.
    lo, hi = variant.conventions.rest_gap
    scene = run(variant, [disc(0.0, R)], 0.5, dt, round(3.0 / dt), GROUND, record_every=1)
    gap = scene.samples.positions[:, 0, 1] - R
    assert lo <= gap.min() and gap.max() <= hi
    assert abs(scene.samples.velocities).max() <= G * dt
    assert variant.conventions.sleeps is False


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1.0 / 240.0])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_disc_set_on_a_disc_sinks_at_most_the_declared_step(variant: Any, dt: float) -> None:
    # Two discs touching each other and the ground, e 0, 3 s: touching discs are no contact,
    # so the upper one falls one step before its contact holds it: every gap within
    # rest_gap down to rest_sink_steps |g| dt^2 below it, and no speed above one step of
    # gravity at the end.  (Taller columns sink more: see adapters/pymunk/__init__.py.)
    c = variant.conventions
    lo, hi = c.rest_gap
    floor = lo - c.rest_sink_steps * G * dt * dt * (1.0 + 1e-9)
    scene = run(variant, [disc(0.0, R), disc(0.0, 3 * R)], 0.0, dt, round(3.0 / dt), GROUND,
                record_every=1)
    y = scene.samples.positions[:, :, 1]
    for gap in (y[:, 0] - R, y[:, 1] - y[:, 0] - 2 * R):
        assert floor <= gap.min() and gap.max() <= hi + 4 * math.ulp(1.0)  # 0.3 - 0.1 - 0.2
    assert abs(scene.samples.velocities[-10:]).max() <= G * dt


@pytest.mark.parametrize("dt", [1.0 / 60.0, 1e-3])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_disc_between_two_walls_keeps_its_speed_and_bounces_on_time(variant: Any,
                                                                      dt: float) -> None:
    # Zero gravity, walls at x = -1 and 1, speed 3, e = 1: |v| stays 3 (declared rtol), and
    # the bounces fall at 0.3 + 0.6 k s: 8 of them in 5 s.
    walls = Surroundings((0.0, 0.0), (Wall((1.0, 0.0), -1.0), Wall((-1.0, 0.0), -1.0)))
    scene = run(variant, [disc(0.0, 0.0, vx=3.0)], 1.0, dt, round(5.0 / dt), walls,
                record_every=1)
    vx = scene.samples.velocities[:, 0, 0]
    assert abs(abs(vx) - 3.0).max() <= 3.0 * variant.conventions.rtol
    assert sum(1 for a, b in itertools.pairwise(vx) if a * b < 0) == 8
    x = scene.samples.positions[:, 0, 0]
    assert abs(x).max() <= 1.0 - R + 3.0 * dt  # never more than a step into a wall


@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_disc_sliding_on_the_ground_keeps_its_speed_without_friction(variant: Any) -> None:
    # Both variants give the discs and the walls friction 0 (tuned: set; default: pymunk's).
    scene = run(variant, [disc(0.0, R, vx=1.0)], 0.0, 1.0 / 60.0, 60, GROUND)
    assert scene.velocities[0][0] == 1.0
    assert scene.positions[0][0] == pytest.approx(1.0, rel=1e-12)


def test_a_wall_normal_that_is_not_an_axis_raises_naming_the_wall() -> None:
    bad = Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0), Wall((0.6, 0.8), 2.0)))
    scenes = SceneCalls(PymunkDefault())
    with pytest.raises(ValueError, match="wall 1"):
        scenes.prepare_scene([disc(0.0, R)], 2, 1.0, 1e-3, None, scenes.settings(), bad)
    with pytest.raises(ValueError, match="gravity"):
        scenes.prepare_scene([disc(0.0, R)], 2, 1.0, 1e-3, None, scenes.settings(),
                             Surroundings((0.0, 0.0, -G), ()))


@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_open_space_is_gravity_zero_and_no_walls(variant: Any) -> None:
    bodies = [disc(0.0, 0.0, vx=1.0, vy=0.5), disc(0.5, 0.1, vx=-1.0)]
    plain = run(variant, bodies, 0.8, 1e-3, 500, None)
    none = run(variant, bodies, 0.8, 1e-3, 500, Surroundings.none(2))
    assert plain.positions == none.positions and plain.velocities == none.velocities
    scenes = SceneCalls(variant)
    prepared = scenes.prepare_scene(bodies, 2, 0.8, 1e-3, None, scenes.settings())
    assert tuple(prepared["space"].gravity) == (0.0, 0.0) and len(prepared["shapes"]) == 2
    scenes.release_scene(prepared)


def test_walls_are_static_boxes_with_e_by_the_product_rule() -> None:
    walls = (Wall((0.0, 1.0), 0.0), Wall((-1.0, 0.0), -2.0))
    scenes = SceneCalls(PymunkDefault())
    prepared = scenes.prepare_scene([disc(0.0, R)], 2, 0.64, 1e-3, None, scenes.settings(),
                                    Surroundings((0.0, -G), walls))
    try:
        disc_shape, *wall_shapes = prepared["shapes"]
        assert len(wall_shapes) == 2
        for shape in wall_shapes:
            assert shape.body is prepared["space"].static_body
            assert shape.elasticity * disc_shape.elasticity == pytest.approx(0.64)
        ground_top = max(v.y for v in wall_shapes[0].get_vertices())
        side_left = min(v.x for v in wall_shapes[1].get_vertices())
        assert ground_top == 0.0 and side_left == 2.0
    finally:
        scenes.release_scene(prepared)


def test_samples_have_the_scene_shape_and_the_wall_time_comes_from_the_clock() -> None:
    ticks = iter(range(100))
    scene = run(PymunkTuned(), [disc(0.0, R), disc(1.0, 0.5)], 1.0, 1e-3, 10, GROUND,
                record_every=4, clock=lambda: float(next(ticks)))
    assert scene.samples.every == 4
    assert scene.samples.positions.shape == (4, 2, 2)  # steps 0, 4, 8, 10
    assert scene.samples.velocities.shape == (4, 2, 2)
    assert tuple(scene.samples.positions[-1, 1]) == scene.positions[1]
    assert scene.wall_s == 3.0  # three timed runs of steps, one tick each
    assert scene.samples.positions[0, 1, 1] == 0.5
