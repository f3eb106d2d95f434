"""Rapier scenes with gravity and static walls (``adapters/rapier/calls.py``, ``scene.py``).

Expected values come from closed forms (free fall, a spring's static deflection, an elastic
or inelastic bounce between two walls) and from the conventions the variants declare, never
from an engine run.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import pytest

rp = pytest.importorskip("rapier3d")

from adapters.rapier import RapierCcd, RapierDefault, RapierTuned  # noqa: E402
from adapters.rapier import scene as rapier_walls  # noqa: E402
from tests.adapters.scene_calls import (  # noqa: E402
    SceneCalls,
    Surroundings,
    Wall,
)

pytestmark = pytest.mark.engine

G = 9.81
R = 0.1
VARIANTS = [RapierTuned(), RapierDefault(), RapierCcd()]
IDS = [v.name for v in VARIANTS]
rapier_scene = SceneCalls(RapierTuned())
"""Rapier's scene calls with a scene module's interface (a variant's settings passed in)."""
F32_ULP_01 = 2.0**-27
"""The spacing of float32 numbers in [0.0625, 0.125): a centre at height 0.1."""


def ground(dim: int) -> Surroundings:
    """g = 9.81 down the last axis, a ground with its top at 0."""
    up = tuple(float(k == dim - 1) for k in range(dim))
    return Surroundings(tuple(-G * x for x in up), (Wall(up, 0.0),))


def at_height(dim: int, z: float) -> tuple[float, ...]:
    return (0.0,) * (dim - 1) + (z,)


def run(variant: Any, bodies: list[Any], dim: int, e: float, dt: float, steps: int,
        surroundings: Surroundings | None, record_every: int = 0) -> Any:
    prepared = rapier_scene.prepare_scene(bodies, dim, e, dt, None, variant.scene_settings(),
                                          surroundings)
    try:
        return rapier_scene.run_scene(prepared, steps, record_every=record_every)
    finally:
        rapier_scene.release_scene(prepared)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_dropped_sphere_turns_back_at_the_free_fall_time(variant: Any, dim: int) -> None:
    # Bottom 1 m above the ground: it reaches it at sqrt(2 h / g).  A step-based engine turns
    # it back within a step of that (the semi-implicit step falls a little ahead of the
    # exact fall), or one more step when the contact forms only once it has crossed
    # (the default variant's prediction distance 0.02 is less than a step's travel).
    dt, h = 1.0 / 60.0, 1.0
    body = (at_height(dim, h + R), R, 1.0, (0.0,) * dim)
    scene = run(variant, [body], dim, 1.0, dt, 60, ground(dim), record_every=1)
    up = scene.samples.velocities[:, 0, dim - 1]
    turned = next(k for k in range(1, len(up)) if up[k] > 0.0) * dt
    assert math.sqrt(2.0 * h / G) - dt <= turned <= math.sqrt(2.0 * h / G) + 2.0 * dt


@pytest.mark.parametrize(("dim", "dt"), [(2, 1.0 / 60.0), (3, 1.0 / 60.0), (3, 1.0 / 240.0)])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_a_resting_sphere_sinks_the_declared_spring_deflection(variant: Any, dim: int,
                                                               dt: float) -> None:
    # The declared band and sink: rest_gap (0, 0) and |g| rest_sink_s2 = g / omega^2 (a
    # 60 Hz spring), up to where float32 freezes the approach: a substep's move below half
    # an ulp of the height, the overdamped spring's slow mode moving h omega / 2 zeta of the
    # distance left per substep h (twice that estimate, see adapters/rapier/scene.py).
    conventions = variant.conventions
    sink = G * conventions.rest_sink_s2 + G * conventions.rest_sink_steps * dt**2
    omega = 2.0 * math.pi * rapier_walls.STATIC_CONTACT_HZ
    substep = dt / 4  # rapier's default num_solver_iterations
    frozen = 2.0 * (F32_ULP_01 / 2.0) * 2.0 * 10.0 / (omega * substep)  # damping ratio 10
    assert frozen < 0.01 * sink
    body = (at_height(dim, R), R, 1.0, (0.0,) * dim)
    scene = run(variant, [body], dim, 0.0, dt, round(3.0 / dt), ground(dim))
    gap = scene.positions[0][dim - 1] - R
    lo, hi = conventions.rest_gap
    assert lo - sink - frozen <= gap <= hi
    assert gap < lo - sink + frozen  # it does sink as declared, not merely less
    assert scene.positions[0][: dim - 1] == (0.0,) * (dim - 1)


@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_only_the_variants_declared_to_sleep_put_a_resting_sphere_to_sleep(variant: Any) -> None:
    # RigidBodyActivation: slower than the threshold for time_until_sleep (0.5 s) -> asleep.
    prepared = rapier_scene.prepare_scene([(at_height(3, R), R, 1.0, (0.0,) * 3)], 3, 0.0,
                                          1.0 / 60.0, None, variant.scene_settings(), ground(3))
    try:
        scene = rapier_scene.run_scene(prepared, 120)
        body = prepared["world"].rigid_bodies[prepared["handles"][0]]
        assert body.is_sleeping == variant.conventions.sleeps
        if variant.conventions.sleeps:
            assert scene.velocities == ((0.0, 0.0, 0.0),)
    finally:
        rapier_scene.release_scene(prepared)


@pytest.mark.parametrize("e", [1.0, 0.5])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("variant", VARIANTS, ids=IDS)
def test_walls_bounce_with_the_scenes_restitution(variant: Any, dim: int, e: float) -> None:
    # Zero gravity, walls at x = -1 and x = 1, the sphere from the centre at 1 m/s: the
    # exact run bounces at 0.9 s and then every 1.8 / v s, each bounce multiplying the
    # speed by e (the count by 5.5 s is 6 at e = 1, 2 at e = 0.5, none near a step); the
    # speed is e^k within the declared rtol (e = 0.5 and 1 are exact in float32).
    x = tuple(float(k == 0) for k in range(dim))
    box = Surroundings((0.0,) * dim, (Wall(x, -1.0), Wall(tuple(-c for c in x), -1.0)))
    duration, dt, speed = 5.5, 1.0 / 60.0, 1.0
    bounces, t, v = 0, (1.0 - R) / speed, speed
    while t < duration:
        bounces, v = bounces + 1, v * e
        t += 2.0 * (1.0 - R) / v
    scene = run(variant, [((0.0,) * dim, R, 1.0, x)], dim, e, dt, round(duration / dt), box)
    direction = (-1.0) ** bounces
    want = tuple(direction * speed * e**bounces * c for c in x)
    assert scene.velocities[0] == pytest.approx(want, rel=variant.conventions.rtol,
                                                abs=variant.conventions.rtol)
    assert -1.0 + R - 1e-6 <= scene.positions[0][0] <= 1.0 - R + 1e-6


def test_walls_are_one_fixed_body_with_a_half_space_each() -> None:
    box = Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0), Wall((1.0, 0.0), -2.0),
                                   Wall((-1.0, 0.0), -2.0)))
    prepared = rapier_scene.prepare_scene([((0.0, 1.0), R, 1.0, (0.0, 0.0))], 2, 1.0, 1e-3,
                                          None, RapierTuned().scene_settings(), box)
    world = prepared["world"]
    walls = [body for handle, body in world.rigid_bodies if handle not in prepared["handles"]]
    assert len(walls) == 1 and walls[0].is_fixed
    shapes = [world.colliders[c].shape for c in walls[0].colliders]
    assert [s.shape_type for s in shapes] == [rp.ShapeType.HALFSPACE] * 3
    assert world.gravity.to_tuple() == (0.0, pytest.approx(-G), 0.0)
    rapier_scene.release_scene(prepared)


@pytest.mark.parametrize("dim", [2, 3])
def test_open_space_builds_no_wall_and_no_gravity(dim: int) -> None:
    bodies = [((0.0,) * dim, R, 1.0, (1.0,) + (0.0,) * (dim - 1))]
    for surroundings in (None, Surroundings.none(dim)):
        prepared = rapier_scene.prepare_scene(bodies, dim, 1.0, 1e-3, None,
                                              RapierTuned().scene_settings(), surroundings)
        assert len(prepared["world"].rigid_bodies) == 1
        assert prepared["world"].gravity.to_tuple() == (0.0, 0.0, 0.0)
        rapier_scene.release_scene(prepared)


def test_bad_surroundings_are_refused_naming_the_wall() -> None:
    tuning = RapierTuned().scene_settings()
    body = [((0.0, 1.0), R, 1.0, (0.0, 0.0))]
    tilted = Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0), Wall((0.6, 0.8), 0.0)))
    with pytest.raises(ValueError, match="wall 1"):
        rapier_scene.prepare_scene(body, 2, 1.0, 1e-3, None, tuning, tilted)
    with pytest.raises(ValueError, match="gravity"):
        rapier_scene.prepare_scene(body, 2, 1.0, 1e-3, None, tuning, ground(3))
    far = Surroundings((0.0, -G), (Wall((0.0, 1.0), -1e39),))
    with pytest.raises(OverflowError, match="wall 0 offset"):
        rapier_scene.prepare_scene(body, 2, 1.0, 1e-3, None, tuning, far)


@pytest.mark.parametrize(("steps", "every"), [(10, 3), (9, 3), (4, 10)])
def test_samples_have_the_scenes_shape_and_the_wall_time_comes_from_the_clock(
        steps: int, every: int) -> None:
    bodies = [((0.0, 0.5), R, 1.0, (0.0, 0.0)), ((1.0, 0.5), R, 2.0, (0.0, 0.0))]
    prepared = rapier_scene.prepare_scene(bodies, 2, 1.0, 1e-3, None,
                                          RapierDefault().scene_settings(), ground(2))
    ticks = itertools.count()
    scene = rapier_scene.run_scene(prepared, steps, clock=lambda: float(next(ticks)),
                                   record_every=every)
    rapier_scene.release_scene(prepared)
    chunks = math.ceil(steps / every)
    samples = scene.samples
    assert samples is not None and samples.every == every
    assert samples.positions.shape == samples.velocities.shape == (chunks + 1, 2, 2)
    assert samples.positions[0].tolist() == [[0.0, 0.5], [1.0, 0.5]]
    assert tuple(map(tuple, samples.positions[-1].tolist())) == scene.positions
    assert scene.wall_s == chunks and scene.steps == steps  # one tick per run of steps
    falling = samples.velocities[1:, :, 1]
    assert (falling < 0.0).all()  # gravity acts (before the ground is reached)
