"""MuJoCo scenes with gravity and walls (adapters/mujoco/calls.py, adapters/mujoco/scene.py).

Every expected value comes from a closed form (free fall, the declared rest band and sink,
the declared restitution precision) or from the engine compared with itself (a wall against
the mirror image of a sphere); none is an engine's output copied here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

import adapters  # noqa: E402
from adapters.mujoco import MujocoStiff  # noqa: E402
from adapters.mujoco import scene as mujoco_walls  # noqa: E402
from tests.adapters.scene_calls import (  # noqa: E402
    Body,
    MujocoSceneCalls,
    SceneRun,
    Surroundings,
    Wall,
)

pytestmark = pytest.mark.engine

G = 9.81
R = 0.1
mujoco_scene = MujocoSceneCalls(MujocoStiff())
"""MuJoCo's scene calls with a scene module's interface (a variant's Tuning passed in)."""
VARIANTS = {"mujoco": mujoco_walls.Tuning(), "mujoco-default": None}


def _up(dim: int) -> int:
    return dim - 1


def _ground(dim: int, g: float = G) -> Surroundings:
    gravity = [0.0] * dim
    gravity[_up(dim)] = -g
    normal = [0.0] * dim
    normal[_up(dim)] = 1.0
    return Surroundings(tuple(gravity), (Wall(tuple(normal), 0.0),))


def _sphere(dim: int, height: float) -> Body:
    centre = [0.0] * dim
    centre[_up(dim)] = R + height
    return (tuple(centre), R, 1.0, (0.0,) * dim)


def _run(name: str, bodies: list[Body], dim: int, e: float, dt: float, steps: int,
         surroundings: Surroundings | None, record_every: int = 0, **kw: Any) -> SceneRun:
    prepared = mujoco_scene.prepare_scene(bodies, dim, e, dt, None, VARIANTS[name], surroundings)
    return mujoco_scene.run_scene(prepared, steps, record_every=record_every, **kw)


@pytest.mark.parametrize("name", VARIANTS)
@pytest.mark.parametrize("dim", [2, 3])
def test_a_dropped_sphere_meets_the_ground_at_the_free_fall_time(name: str, dim: int) -> None:
    h, dt = 0.5, 1e-3
    run = _run(name, [_sphere(dim, h)], dim, 1.0, dt, 500, _ground(dim), record_every=1)
    assert run.samples is not None
    gaps = run.samples.positions[:, 0, _up(dim)] - R
    first = int(np.argmax(gaps <= 0.0))
    assert gaps[first] <= 0.0
    assert first * dt == pytest.approx(math.sqrt(2.0 * h / G), abs=dt)


@pytest.mark.parametrize("name", VARIANTS)
@pytest.mark.parametrize(("dim", "dt", "g", "e"), [
    (3, 0.002, G, 1.0), (2, 1 / 60, G, 1.0), (3, 1 / 240, 3.0, 1.0),
    (3, 1 / 60, G, mujoco_walls.TUNED_E_MIN), (2, 0.002, 30.0, 0.5)])
def test_a_sphere_set_on_the_ground_stays_within_the_declared_band_and_sink(
        name: str, dim: int, dt: float, g: float, e: float) -> None:
    conventions = adapters.get(name).conventions
    lo, hi = conventions.rest_gap
    sink = g * (conventions.rest_sink_steps * dt * dt + conventions.rest_sink_s2)
    steps = round(3.0 / dt)
    run = _run(name, [_sphere(dim, 0.0)], dim, e, dt, steps, _ground(dim, g), record_every=1)
    assert run.samples is not None
    gaps = run.samples.positions[:, 0, _up(dim)] - R
    steady = gaps[len(gaps) // 2:]
    assert steady.min() >= lo - sink
    assert gaps.max() <= hi + 2.0**-52  # one rounding of a coordinate near 1
    # Set down at distance 0, the default (margin 0) meets no force for one step: it falls
    # g dt^2 (semi-implicit Euler) before its spring takes over.
    assert gaps.min() >= lo - sink - g * dt * dt
    assert run.samples.positions[:, 0, :_up(dim)].tolist() == [[0.0] * _up(dim)] * len(gaps)


@pytest.mark.parametrize(("dt", "g"), [(0.002, G), (1 / 60, G), (0.002, 3.0)])
def test_the_default_contact_rests_at_the_fixed_point_of_mujocos_sink_formula(
        dt: float, g: float) -> None:
    # modeling.rst: r = a0 (1 - d) timeconst^2 dampratio^2 at a constant d; with the default
    # solimp d depends on the depth, and refsafe raises timeconst to 2 dt.
    run = _run("mujoco-default", [_sphere(3, 0.0)], 3, 1.0, dt, round(5.0 / dt), _ground(3, g))
    assert run.positions[0][2] - R == pytest.approx(-mujoco_walls.soft_rest_sink(g, dt),
                                                    rel=1e-6)
    assert mujoco_walls.soft_rest_sink(g, dt) <= g * mujoco_walls.DEFAULT_SINK_S2 + \
        g * mujoco_walls.DEFAULT_SINK_STEPS * dt * dt


def test_the_tuned_sink_bound_covers_every_restitution_from_its_minimum() -> None:
    grid = np.linspace(mujoco_walls.TUNED_E_MIN, 1.0, 37)
    assert max(mujoco_walls.stiff_sink_steps(float(e)) for e in grid) <= \
        mujoco_walls.TUNED_SINK_STEPS


def test_a_tuned_elastic_drop_returns_to_its_height_within_the_declared_precision() -> None:
    h, dt = 1.0, 1e-3
    fall = math.sqrt(2.0 * h / G)
    run = _run("mujoco", [_sphere(3, h)], 3, 1.0, dt, round(3.0 * fall / dt), _ground(3),
               record_every=1)
    assert run.samples is not None
    gaps = run.samples.positions[:, 0, 2] - R
    after = gaps[round(1.5 * fall / dt):]  # the flight after the first bounce
    rtol = mujoco_walls.TUNED_RTOL
    assert h * (1.0 - rtol) ** 2 - G * dt * dt <= after.max() <= h * (1.0 + rtol) ** 2


@pytest.mark.parametrize("dim", [2, 3])
def test_a_tuned_elastic_ball_between_two_walls_keeps_its_speed(dim: int) -> None:
    speed, dt, duration = 2.0, 1e-3, 3.0
    walls = tuple(Wall(tuple(s if k == 0 else 0.0 for k in range(dim)), -1.0) for s in (1.0, -1.0))
    velocity = (speed, *(0.0,) * (dim - 1))
    body: Body = ((0.0,) * dim, R, 1.0, velocity)
    run = _run("mujoco", [body], dim, 1.0, dt, round(duration / dt),
               Surroundings((0.0,) * dim, walls))
    free = 2.0 * (1.0 - R)  # the centre's travel between the walls
    bounces = math.floor((speed * duration - free / 2.0) / free) + 1
    rtol = mujoco_walls.TUNED_RTOL
    got = math.hypot(*run.velocities[0])
    assert speed * (1.0 - rtol) ** bounces <= got <= speed * (1.0 + rtol) ** bounces
    assert -1.0 + R - 0.01 < run.positions[0][0] < 1.0 - R + 0.01


def test_a_tuned_wall_bounces_like_the_mirror_image_sphere() -> None:
    # A sphere hitting a wall at x = 0 against two equal spheres meeting head-on at x = 0:
    # the same contact (frictionless, one constraint row) gives the same bounce, e.
    dt, steps, e = 1e-3, 300, 0.7
    ball: Body = ((-0.15, 0.0, 0.0), R, 1.0, (1.0, 0.0, 0.0))
    mirror: Body = ((0.15, 0.0, 0.0), R, 1.0, (-1.0, 0.0, 0.0))
    wall = Surroundings((0.0, 0.0, 0.0), (Wall((-1.0, 0.0, 0.0), 0.0),))
    alone = _run("mujoco", [ball], 3, e, dt, steps, wall)
    pair = _run("mujoco", [ball, mirror], 3, e, dt, steps, None)
    assert alone.velocities[0][0] == pytest.approx(pair.velocities[0][0], rel=1e-9)
    assert alone.velocities[0][0] == pytest.approx(-e, rel=mujoco_walls.TUNED_RTOL * 50)


@pytest.mark.parametrize("name", VARIANTS)
def test_a_wall_contact_has_the_parameters_of_a_sphere_contact(name: str) -> None:
    # Sphere 0 touches the ground and sphere 1: MuJoCo mixes each pair's geom parameters,
    # and the two contacts must come out the same (the wall's restitution is the spheres').
    bodies: list[Body] = [_sphere(3, -0.01), ((0.15, 0.0, R + 0.05), R, 1.0, (0.0, 0.0, 0.0))]
    prepared = mujoco_scene.prepare_scene(bodies, 3, 0.6, 1e-3, None, VARIANTS[name],
                                          _ground(3))
    m, d = prepared["model"], prepared["data"]
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    assert d.ncon == 2
    wall, spheres = sorted(range(2), key=lambda k: -int(d.contact.geom[k][0] == 0))
    assert d.contact.geom[wall][0] == 0  # the plane, geom 0 of the world body
    for field in ("solref", "solimp", "friction", "dim", "includemargin"):
        got = np.asarray(getattr(d.contact, field)[wall])
        assert got.tolist() == np.asarray(getattr(d.contact, field)[spheres]).tolist(), field


@pytest.mark.parametrize(("surroundings", "match"), [
    (Surroundings((0.0, -G), (Wall((0.0, 1.0), 0.0), Wall((0.6, 0.8), 1.0))), "wall 1"),
    (Surroundings((0.0, -G), (Wall((0.0, 0.0, 1.0), 0.0),)), "wall 0"),
    (Surroundings((0.0, -G, 0.0), ()), "gravity"),
    (Surroundings((0.0, -G), (Wall((0.0, 1.0), math.inf),)), "wall 0"),
])
def test_bad_surroundings_are_refused_naming_what_is_wrong(surroundings: Surroundings,
                                                           match: str) -> None:
    with pytest.raises(ValueError, match=match):
        mujoco_scene.prepare_scene([_sphere(2, 1.0)], 2, 1.0, 1e-3, None, None, surroundings)


def test_every_wall_is_an_exact_plane_and_walls_never_touch_each_other() -> None:
    axes = [tuple(s * float(k == a) for k in range(3)) for a in range(3) for s in (1.0, -1.0)]
    walls = tuple(Wall(n, -2.0) for n in axes)  # a closed box |x|, |y|, |z| <= 2
    prepared = mujoco_scene.prepare_scene([_sphere(3, 0.0)], 3, 1.0, 1e-3, None, None,
                                          Surroundings((0.0, 0.0, -G), walls))
    m, d = prepared["model"], prepared["data"]
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    assert d.ncon == 0
    for g, wall in enumerate(walls):  # the world body's geoms come first
        assert tuple(d.geom_xmat[g][[2, 5, 8]]) == wall.normal
        assert tuple(d.geom_xpos[g]) == tuple(-2.0 * n + 0.0 for n in wall.normal)


@pytest.mark.parametrize("name", VARIANTS)
def test_samples_have_the_scene_shape_and_the_wall_time_comes_from_the_clock(name: str) -> None:
    readings = iter([1.0, 1.5, 2.0, 2.25, 3.0, 3.125, 4.0, 4.0625])
    run = _run(name, [_sphere(2, 1.0), ((1.0, 0.5), R, 2.0, (0.0, 0.0))], 2, 1.0, 1e-3, 10,
               _ground(2), record_every=4, clock=lambda: next(readings))
    assert run.samples is not None
    assert run.samples.every == 4
    assert run.samples.positions.shape == run.samples.velocities.shape == (4, 2, 2)
    assert run.samples.positions.dtype == np.float64
    assert run.samples.positions[0].tolist() == [[0.0, 1.0 + R], [1.0, 0.5]]
    assert run.samples.positions[-1].tolist() == [list(p) for p in run.positions]
    assert run.wall_s == 0.5 + 0.25 + 0.125
    assert run.steps == 10


@pytest.mark.parametrize("name", VARIANTS)
def test_open_space_given_explicitly_is_open_space(name: str) -> None:
    bodies: list[Body] = [((0.0, 0.0), R, 1.0, (1.0, 0.0)), ((0.3, 0.05), R, 2.0, (0.0, 0.0))]
    none = _run(name, bodies, 2, 0.8, 1e-3, 400, None)
    explicit = _run(name, bodies, 2, 0.8, 1e-3, 400, Surroundings.none(2))
    assert none.positions == explicit.positions
    assert none.velocities == explicit.velocities
    assert none.positions != tuple(b[0] for b in bodies)


@pytest.mark.parametrize("name", VARIANTS)
def test_each_variant_declares_no_sleeping_and_its_wall_restitution(name: str) -> None:
    conventions = adapters.get(name).conventions
    assert conventions.sleeps is False
    prepared = mujoco_scene.prepare_scene([_sphere(3, 0.0)], 3, 1.0, 1e-3, None,
                                          VARIANTS[name], _ground(3))
    assert prepared["model"].opt.enableflags == 0  # mjENBL_SLEEP is opt-in
    assert (conventions.wall_restitution == "") == (name == "mujoco")
