"""PyBullet scenes with gravity and static walls (the scene calls of adapters/pybullet/calls.py).

Every expectation comes from a closed form (free fall, an elastic bounce, a sphere at rest)
or from what the variant declares (``rest_gap``, ``rest_sink_steps``, ``sleeps``); none is
an engine output copied here.  Variants: tuned, default and CCD (whose walls are rigid
bodies like its spheres).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("pybullet")

import adapters
from adapters.pybullet import PyBulletDefault, PyBulletTuned, engine
from tests.adapters.scene_calls import Body, SceneCalls, SceneRun, Surroundings, Wall

pytestmark = pytest.mark.engine

G = 9.81
R = 0.1
NAMES = ("pybullet", "pybullet-default", "pybullet-ccd")
NO_DAMPING = ("pybullet", "pybullet-ccd")
ROUNDING = 1e-12
"""Absolute slack for float64 positions of order 1 after a few hundred steps."""


pybullet_scene = SceneCalls(PyBulletTuned())
"""PyBullet's scene calls with a scene module's interface (a variant's settings passed in)."""
DEFAULTS = PyBulletDefault().scene_settings()
"""What the default variant passes: nothing set."""


def tuning(name: str) -> dict[str, Any]:
    value: dict[str, Any] = getattr(adapters.get(name), "scene_settings")()  # noqa: B009
    return value


def ground(dim: int, gravity: float = G) -> Surroundings:
    """A ground with its top at 0, gravity down the last axis."""
    up = (0.0,) * (dim - 1) + (1.0,)
    return Surroundings(tuple(-gravity * u for u in up), (Wall(up, 0.0),))


def run(name: str, bodies: list[Body], dim: int, e: float, dt: float, steps: int,
        around: Surroundings | None, every: int = 1) -> SceneRun:
    p = pybullet_scene.prepare_scene(bodies, dim, e, dt, None, tuning(name), around)
    try:
        return pybullet_scene.run_scene(p, steps, record_every=every)
    finally:
        pybullet_scene.release_scene(p)


def rest_band(name: str, dt: float) -> tuple[float, float]:
    """The declared resting gaps, widened below by the declared sink."""
    c = adapters.get(name).conventions
    lo, hi = c.rest_gap
    return lo - c.rest_sink_steps * G * dt * dt - c.rest_sink_s2 * G - ROUNDING, hi + ROUNDING


def test_a_bad_wall_normal_raises_naming_the_wall() -> None:
    walls = (Wall((0.0, 0.0, 1.0), 0.0), Wall((0.0, 0.6, 0.8), 1.0))
    with pytest.raises(ValueError, match="wall 1"):
        pybullet_scene.prepare_scene([((0.0, 0.0, 1.0), R, 1.0, (0.0, 0.0, 0.0))], 3, 1.0,
                                     1e-3, None, DEFAULTS, Surroundings((0.0, 0.0, -G), walls))
    with pytest.raises(ValueError, match="gravity"):
        pybullet_scene.prepare_scene([((0.0, 0.0), R, 1.0, (0.0, 0.0))], 2, 1.0, 1e-3, None,
                                     DEFAULTS, Surroundings((0.0, 0.0, -G), ()))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("name", NO_DAMPING)
def test_gravity_acts_along_the_last_axis_as_free_fall(name: str, dim: int) -> None:
    # No walls: z(t) = z0 - g t^2 / 2; a first-order integrator lags it by at most g dt t / 2.
    dt, steps = 1 / 240, 120
    run_ = run(name, [((0.0,) * dim, R, 1.0, (0.0,) * dim)], dim, 1.0, dt, steps,
               Surroundings(ground(dim).gravity), every=0)
    t = steps * dt
    assert abs(run_.positions[0][-1] + G * t * t / 2) <= G * dt * t / 2 + ROUNDING
    assert run_.velocities[0][-1] == pytest.approx(-G * t, rel=1e-12)
    assert all(x == 0.0 for x in run_.positions[0][:-1])


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("name", NAMES)
def test_a_dropped_sphere_lands_when_free_fall_says_and_rests_in_the_declared_band(
        name: str, dim: int) -> None:
    # e = 0: the sphere stops at the ground.  It reaches it at sqrt(2h/g): within one step
    # (the discrete landing) and half a step (the integrator's lead), at most one step's
    # travel deep (a contact seen a step late), and is still from the next step on.  The
    # default variant's contact ERP then brings it into the declared band; the tuned one
    # (contactERP 0) keeps the landing depth (documented).
    dt, h = 1 / 240, 0.2
    start = (0.0,) * (dim - 1) + (h + R,)
    samples = run(name, [(start, R, 1.0, (0.0,) * dim)], dim, 0.0, dt, 480,
                  ground(dim)).samples
    assert samples is not None
    lo, hi = rest_band(name, dt)
    gaps = samples.positions[:, 0, dim - 1] - R
    landed = next(k for k, gap in enumerate(gaps) if gap <= hi)
    assert abs(landed * dt - math.sqrt(2 * h / G)) <= 1.5 * dt
    travel = (math.sqrt(2 * G * h) + G * dt) * dt
    assert lo - travel <= gaps[landed:].min() and gaps[landed:].max() <= hi
    assert abs(samples.velocities[landed + 1:]).max() < G * dt
    if tuning(name) == DEFAULTS:
        assert lo <= gaps[-1] <= hi


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240])
@pytest.mark.parametrize("name", NAMES)
def test_a_sphere_placed_on_the_ground_stays_at_rest_in_the_declared_band(
        name: str, dt: float) -> None:
    # e = 0 (with e > 0 and threshold 0 the tuned variant floats e g dt^2 up: documented).
    samples = run(name, [((0.0, 0.0, R), R, 1.0, (0.0, 0.0, 0.0))], 3, 0.0, dt,
                  round(2 / dt), ground(3)).samples
    assert samples is not None
    lo, hi = rest_band(name, dt)
    gaps = samples.positions[:, 0, 2] - R
    assert lo <= gaps.min() and gaps.max() <= hi
    assert abs(samples.velocities[1:]).max() < G * dt  # less than one step's gravity


@pytest.mark.parametrize("name", ("pybullet", "pybullet-ccd"))
def test_an_elastic_ball_between_two_walls_keeps_its_speed(name: str) -> None:
    # 2-D, zero gravity, walls x = +-1.  Speed 1.8 at dt 1/60: 0.03 a step, below the CCD
    # variant's motion threshold 0.9 r / 2 = 0.045 (no sweep); the path to a wall, 0.9, is
    # 30 steps, so every step starts 0 or >= 0.03 from a wall, never inside the speculative
    # band (0.02 sqrt(3) r = 0.0035): each bounce is met at touching, and is elastic.
    dt, v = 1 / 60, 1.8
    walls = (Wall((1.0, 0.0), -1.0), Wall((-1.0, 0.0), -1.0))
    samples = run(name, [((0.0, 0.0), R, 1.0, (v, 0.0))], 2, 1.0, dt, 600,
                  Surroundings((0.0, 0.0), walls)).samples
    assert samples is not None
    vx = samples.velocities[:, 0, 0]
    assert (vx[1:] * vx[:-1] < 0).sum() == 10  # at steps 30, 90, ..., 570
    assert abs(abs(vx) - v).max() <= 1e-9 * v
    assert abs(samples.positions[:, 0, 0]).max() <= 1.0 - R + 1e-9


@pytest.mark.parametrize("e", [0.0, 0.25, 0.81])
def test_a_wall_bounces_with_the_scene_restitution(e: float) -> None:
    # Tuned (no damping, threshold 0): a ball meeting a wall at touching leaves at e v.
    dt, v = 1 / 60, 3.0  # 0.05 a step: 18 steps to the wall, met at touching
    samples = run("pybullet", [((0.0, 0.0), R, 1.0, (v, 0.0))], 2, e, dt, 30,
                  Surroundings((0.0, 0.0), (Wall((-1.0, 0.0), -1.0),))).samples
    assert samples is not None
    assert samples.velocities[-1, 0, 0] == pytest.approx(-e * v, abs=1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_a_fast_sphere_never_ends_behind_a_wall(name: str) -> None:
    # 50 m/s at dt 1/60: 0.83 a step, over four times the diameter.  A plane is a
    # half-space, so the contact is found at any depth and the sphere comes back.
    dt = 1 / 60
    final = run(name, [((0.0, 0.0, 1.0), R, 1.0, (0.0, 0.0, -50.0))], 3, 1.0, dt, 6,
                ground(3, gravity=0.0), every=0)
    assert final.velocities[0][2] > 0.0
    assert final.positions[0][2] > 0.0


@pytest.mark.parametrize("name", NAMES)
def test_walls_stay_where_they_are_built(name: str) -> None:
    # A box of four static walls (they never collide with each other) around a gas.
    walls = (Wall((1.0, 0.0), -1.0), Wall((-1.0, 0.0), -1.0), Wall((0.0, 1.0), -1.0),
             Wall((0.0, -1.0), -2.0))
    bodies: list[Body] = [((x, y), 0.05, 1.0, (y - x, x + 2 * y)) for x, y in
                          itertools.product((-0.5, 0.0, 0.5), (-0.5, 0.5))]
    p = pybullet_scene.prepare_scene(bodies, 2, 1.0, 1 / 240, None, tuning(name),
                                     Surroundings((0.0, -G), walls))
    try:
        pybullet_scene.run_scene(p, 480)
        bt = engine()
        for uid, wall in zip(p["planes"], walls, strict=True):
            position = bt.getBasePositionAndOrientation(uid, physicsClientId=p["cid"])[0]
            assert tuple(position[:2]) == tuple(wall.offset * n for n in wall.normal)
            assert bt.getBaseVelocity(uid, physicsClientId=p["cid"])[0] == (0.0, 0.0, 0.0)
    finally:
        pybullet_scene.release_scene(p)


@pytest.mark.parametrize("name", NO_DAMPING)
def test_declared_no_sleeping_a_slow_body_keeps_moving(name: str) -> None:
    # 0.1 m/s (below Bullet's sleep thresholds) for 2.5 s, past the 2 s timeout.
    assert adapters.get(name).conventions.sleeps is False
    dt, steps = 1 / 60, 150
    final = run(name, [((0.0, 0.0, 0.0), R, 1.0, (0.1, 0.0, 0.0))], 3, 1.0, dt, steps,
                None, every=0)
    assert final.velocities[0][0] == 0.1
    assert final.positions[0][0] == pytest.approx(0.1 * steps * dt, rel=1e-12)


def test_open_space_is_the_same_with_none_or_no_surroundings() -> None:
    bodies: list[Body] = [((0.0, 0.0, 0.0), R, 1.0, (1.0, 0.0, 0.0)),
                          ((0.5, 0.01, 0.0), R, 2.0, (-1.0, 0.0, 0.0))]
    runs = []
    for around in (None, Surroundings.none(3)):
        runs.append(run("pybullet-default", bodies, 3, 0.9, 1e-3, 400, around, every=0))
    p = pybullet_scene.prepare_scene(bodies, 3, 0.9, 1e-3, None, DEFAULTS)  # positional call
    try:
        runs.append(pybullet_scene.run_scene(p, 400))
    finally:
        pybullet_scene.release_scene(p)
    assert runs[0].positions == runs[1].positions == runs[2].positions
    assert runs[0].velocities == runs[1].velocities == runs[2].velocities


def counter() -> Iterator[float]:
    return itertools.count(0.0, 1.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_samples_have_the_scene_shape_and_time_comes_from_the_clock(dim: int) -> None:
    low = (0.0,) * (dim - 2) + (R,)  # resting on the ground
    bodies: list[Body] = [((0.0, *low), R, 1.0, (1.0,) + (0.0,) * (dim - 1)),
                          ((1.0, *low), R, 1.0, (0.0,) * dim)]
    p = pybullet_scene.prepare_scene(bodies, dim, 1.0, 1e-3, None, DEFAULTS, ground(dim))
    try:
        ticks = counter()
        recorded = pybullet_scene.run_scene(p, 10, clock=lambda: next(ticks), record_every=3)
        ticks = counter()
        plain = pybullet_scene.run_scene(p, 5, clock=lambda: next(ticks))
    finally:
        pybullet_scene.release_scene(p)
    samples = recorded.samples
    assert samples is not None and samples.every == 3
    assert samples.positions.shape == samples.velocities.shape == (5, 2, dim)  # 0,3,6,9,10
    assert tuple(samples.positions[0, 1]) == bodies[1][0]
    assert tuple(map(tuple, samples.positions[-1])) == recorded.positions
    assert recorded.wall_s == 4.0  # one clock pair around each of the 4 runs of steps
    assert plain.wall_s == 1.0 and plain.samples is None and plain.steps == 5


@pytest.mark.parametrize("name", NAMES)
def test_a_reused_client_runs_a_scene_bit_for_bit_as_a_new_one(name: str) -> None:
    """Released scenes leave emptied clients for the next ones (``resetSimulation``): an
    open-space collision run in a client that last held a scene of the same settings with
    gravity and a wall must end exactly as in a new client (no gravity, no wall left)."""
    pybullet_scene.drop_idle_scene_clients()
    pair = [((0.0, 0.0), R, 1.0, (0.4, 0.0)), ((0.5, 0.05), R, 2.0, (-0.3, 0.0))]
    fresh = run(name, pair, 2, 0.8, 1 / 240, 300, None)
    assert pybullet_scene.idle_scene_clients() == 1
    run(name, [((0.0, 0.0, 2.0), 2 * R, 3.0, (1.0, -1.0, 0.5))], 3, 0.5, 1e-3, 50,
        ground(3, 2.0))  # other settings: another client
    run(name, [((0.1, 0.2), R, 1.0, (0.0, -1.0))], 2, 0.5, 1 / 240, 120,
        ground(2, 3.0))  # the same settings: the first client, now with gravity and a wall
    assert pybullet_scene.idle_scene_clients() == 2
    reused = run(name, pair, 2, 0.8, 1 / 240, 300, None)
    assert (reused.positions, reused.velocities) == (fresh.positions, fresh.velocities)
    assert fresh.samples is not None and reused.samples is not None
    assert (reused.samples.positions.tolist(), reused.samples.velocities.tolist()) == (
        fresh.samples.positions.tolist(), fresh.samples.velocities.tolist())
