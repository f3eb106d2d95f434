"""Scenes with gravity and walls in case files: every problem with the world is refused before
any work, naming the case, the field and the reason; the offset and scale sweeps move and
resize the whole scene (:mod:`crosscheck.cases.world_sweep`), and the exact run moves and
scales with it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from crosscheck.cases import load
from crosscheck.cases.load import load_paths
from crosscheck.cases.world_sweep import moved_scene
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import scenes
from reference_impl import events, gravity

HEAD = '[[case]]\nid = "w"\ndescription = "d"\nkind = "sphere_scene"\ndim = 2\n'
TIME = "duration = 1.0\n"
ONE = 'bodies = [{ center = [0.0, 1.5], radius = 0.5, mass = 1.0, velocity = [0.0, 0.0] }]\n'
PAIR = """bodies = [
  { center = [-1.0, 1.5], radius = 0.5, mass = 1.0, velocity = [1.0, 0.0] },
  { center = [1.0, 1.5], radius = 0.5, mass = 1.0, velocity = [-1.0, 0.0] },
]
steps = { dt = [0.01] }
"""
G = "gravity = [0.0, -8.0]\n"
GROUND = "walls = [{ normal = [0.0, 1.0], offset = 0.0 }]\n"


def loaded(tmp_path: Path, text: str) -> load.LoadResult:
    path = tmp_path / "world.toml"
    path.write_text(text, encoding="utf-8")
    return load_paths([path], cache=False)


@pytest.fixture
def no_work(monkeypatch: pytest.MonkeyPatch) -> None:
    """Any expansion or exact run fails the test: a refusal must come before them."""
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("work done on a refused block")

    monkeypatch.setattr(load, "expand", refuse)
    monkeypatch.setattr(gravity, "simulate", refuse)
    monkeypatch.setattr(events, "simulate", refuse)


@pytest.mark.usefixtures("no_work")
@pytest.mark.parametrize(("block", "field", "words"), [
    (HEAD + TIME + ONE + "gravity = [0.0, -8.0, 0.0]\n" + GROUND, "gravity",
     "expected 2 components for dim = 2, got 3"),
    (HEAD + TIME + ONE + "gravity = [-8.0]\n" + GROUND, "gravity", "expected 2 components"),
    (HEAD + TIME + ONE + "gravity = [0.0, -inf]\n" + GROUND, "gravity[1]", "must be finite"),
    (HEAD + TIME + ONE + G + "walls = [{ normal = [0.0, 2.0] }]\n", "walls[0].normal",
     "must be a unit axis vector of 2 components"),
    (HEAD + TIME + ONE + G + GROUND.replace("]\n", ", { normal = [0.6, 0.8] }]\n"),
     "walls[1].normal", "one +1 or -1, the rest 0), got [0.6, 0.8]"),
    (HEAD + TIME + ONE + G + "walls = [{ normal = [0.0, 0.0, 1.0] }]\n", "walls[0].normal",
     "expected 2 components for dim = 2, got 3"),
    (HEAD + TIME + ONE + G + "walls = [{ normal = [0.0, 1.0], offset = inf }]\n",
     "walls[0].offset", "must be finite"),
    (HEAD + TIME + ONE + G + "walls = [{ normal = [0.0, 1.0], offset = 1.25 }]\n",
     "bodies[0]", "starts inside wall 0"),
    (HEAD + TIME + ONE + G + "walls = [{ normal = [0.0, -1.0], offset = -1.75 }]\n",
     "bodies[0]", "starts inside wall 0"),  # a ceiling at y = 1.75 cuts the body's top
    (HEAD + TIME + ONE + G + GROUND + "restitution = 1.5\n", "restitution",
     "must be in [0, 1], got 1.5"),
    (HEAD + TIME + ONE, "bodies", "at least two bodies, or one with gravity or walls"),
    (HEAD + PAIR + G + GROUND + "sweep = { step_travel = [1.0] }\n", "sweep.step_travel",
     "gravity or walls is swept over scale and offset only"),
    (HEAD + PAIR + G + "sweep = { step_travel = [1.0] }\n", "sweep.step_travel",
     "swept over scale and offset only"),
    (HEAD + PAIR + GROUND + "sweep = { phase = [0.5] }\n", "sweep.phase",
     "swept over scale and offset only"),
    (HEAD + TIME + PAIR + G + GROUND + "sweep = { offset = [1.0], speed = [2.0] }\n",
     "sweep.speed", "swept over scale and offset only"),
], ids=["gravity-3-in-2d", "gravity-1-in-2d", "gravity-infinite", "normal-not-unit",
        "normal-not-axis", "normal-3-in-2d", "wall-offset-infinite", "inside-ground",
        "inside-ceiling", "restitution-above-1", "one-body-no-walls", "ground-step-travel",
        "gravity-step-travel", "walls-phase", "world-and-speed"])
def test_a_bad_world_is_refused_naming_its_field_before_any_work(
        tmp_path: Path, block: str, field: str, words: str) -> None:
    result = loaded(tmp_path, block)
    assert result.cases == []
    assert [e.field for e in result.errors] == [field], result.errors
    error = result.errors[0]
    assert words in error.reason and "case 'w'" in error.message
    assert f"field {field}:" in error.message and str(tmp_path) in error.message


@pytest.mark.usefixtures("no_work")
@pytest.mark.parametrize(("world", "field"), [
    ("gravity = [0.0, -8.0, 0.0]\n" + GROUND, "gravity"),
    (G + "walls = [{ normal = [0.0, 0.0, 1.0] }]\n", "walls[0].normal")])
def test_a_bad_input_case_still_has_its_world_lengths_checked(
        tmp_path: Path, world: str, field: str) -> None:
    result = loaded(tmp_path, HEAD + 'tags = ["bad-input"]\n' + TIME + ONE + world)
    assert result.cases == []
    assert [(e.field, "expected 2 components" in e.reason) for e in result.errors] == [
        (field, True)]


@pytest.mark.parametrize("world", [G + GROUND, GROUND, G], ids=["ground", "walls", "gravity"])
def test_one_body_with_gravity_or_walls_is_a_scene(tmp_path: Path, world: str) -> None:
    result = loaded(tmp_path, HEAD + TIME + ONE + world)
    assert result.errors == []
    (case,) = result.cases
    assert isinstance(case, SceneCase) and len(case.bodies) == 1


def test_a_body_touching_a_wall_is_not_inside_it(tmp_path: Path) -> None:
    result = loaded(tmp_path, HEAD + TIME + ONE + G
                    + "walls = [{ normal = [0.0, 1.0], offset = 1.0 }]\n")
    assert result.errors == [] and len(result.cases) == 1


# ------------------------------------------------------------------ sweeps


SWEPT = (HEAD + TIME + G + "restitution = 0.5\n"
         "walls = [{ normal = [0.0, 1.0], offset = 0.0 }, { normal = [-1.0, 0.0], "
         "offset = -4.0 }]\n"
         "bodies = [{ center = [0.0, 1.5], radius = 0.5, mass = 3.0, velocity = [1.0, 0.0] }]\n"
         "steps = { dt = [0.015625] }\n")


def test_offset_moves_every_centre_and_wall(tmp_path: Path) -> None:
    result = loaded(tmp_path, SWEPT + "sweep = { offset = [0.0, 1024.0] }\n")
    assert result.errors == []
    by_id = {c.id: c for c in result.cases if isinstance(c, SceneCase)}
    assert sorted(by_id) == ["w.dt=0.015625.offset=0", "w.dt=0.015625.offset=1024"]
    moved = by_id["w.dt=0.015625.offset=1024"]
    (b,) = moved.bodies
    assert b.center == (1024.0, 1025.5) and b.radius == 0.5 and b.velocity == (1.0, 0.0)
    # y >= 1024; -x >= -4 - 1024, i.e. x <= 1028: both walls carried along
    assert [(w.normal, w.offset) for w in moved.walls] == [((0.0, 1.0), 1024.0),
                                                           ((-1.0, 0.0), -1028.0)]
    assert moved.gravity == (0.0, -8.0) and b.mass == 3.0 and moved.restitution == 0.5
    assert moved.coords == {"dt": 0.015625, "offset": 1024.0}
    assert "metamorphic" in moved.tags and moved.sweep is None


def test_scale_multiplies_lengths_speeds_and_gravity(tmp_path: Path) -> None:
    result = loaded(tmp_path, SWEPT + "sweep = { scale = [0.001, 4.0] }\n")
    assert result.errors == []
    by_id = {c.id: c for c in result.cases if isinstance(c, SceneCase)}
    big, small = by_id["w.dt=0.015625.scale=4"], by_id["w.dt=0.015625.scale=0.001"]
    (b,) = big.bodies
    assert b.center == (0.0, 6.0) and b.radius == 2.0 and b.velocity == (4.0, 0.0)
    assert [w.offset for w in big.walls] == [0.0, -16.0] and big.gravity == (0.0, -32.0)
    assert b.mass == 3.0 and big.dt == 0.015625 and big.duration == 1.0
    (s,) = small.bodies
    assert s.center == (0.0, 1.5 * 0.001) and s.radius == 0.5 * 0.001
    assert small.gravity == (0.0, -8.0 * 0.001)


def test_scale_then_offset_in_one_sweep() -> None:
    case = loaded_case()
    moved = moved_scene(case, offset=-8.0, scale=0.5)
    assert moved.bodies[0].center == (-8.0, 0.75 - 8.0)
    assert [w.offset for w in moved.walls] == [-8.0, -2.0 + 8.0]  # -x >= -2 + 8: x <= -6
    assert moved.gravity == (0.0, -4.0) and moved.bodies[0].velocity == (2.0, 0.0)


def loaded_case() -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": "w", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": 2.0,
        "dt": 0.015625, "gravity": [0.0, -8.0], "restitution": 0.5,
        "walls": [{"normal": [0.0, 1.0]}, {"normal": [-1.0, 0.0], "offset": -4.0}],
        "bodies": [{"center": [0.0, 1.5], "radius": 0.5, "mass": 3.0, "velocity": [4.0, 0.0]}]})
    assert isinstance(case, SceneCase)
    return case


@pytest.mark.parametrize(("offset", "scale"), [(1024.0, 1.0), (0.0, 4.0), (-2.0**20, 0.25)])
def test_the_exact_run_moves_and_scales_with_the_scene(offset: float, scale: float) -> None:
    """A power-of-two scale and a dyadic offset change no rounding: the swept scene's exact
    final state is the origin's, scaled and moved; its times and relative apexes are the
    same (the drop at the origin: g = 8, a gap of 1, e = 1/2, thrown at 4 m/s towards a
    side wall at x = 4, which it meets at 7/8 s)."""
    case = loaded_case()
    origin, swept = scenes.truth(case), scenes.truth(moved_scene(case, offset, scale))
    assert isinstance(origin.positions, tuple) and isinstance(swept.positions, tuple)
    assert swept.positions == tuple(tuple(x * scale + offset for x in p)
                                    for p in origin.positions)
    assert isinstance(origin.velocities, tuple) and isinstance(swept.velocities, tuple)
    assert swept.velocities == tuple(tuple(v * scale for v in p) for p in origin.velocities)
    assert swept.impacts == origin.impacts and swept.bounce_time == origin.bounce_time
    assert isinstance(origin.apex, tuple) and isinstance(swept.apex, tuple)
    assert swept.apex == tuple(a * scale for a in origin.apex)
    assert swept.settle == origin.settle == (0.0,)
    assert swept.energy_drift == origin.energy_drift
    # the origin's own closed forms: bounces at 3/2 - 2^-k, the wall at 7/8 s, rests from 3/2 s
    # with its centre 1/2 above the ground, sliding back at e x 4 = 2 m/s from x = 3.5
    assert origin.impacts is not None and 0.875 in origin.impacts and 1.5 in origin.impacts
    assert origin.positions == ((3.5 - 2.0 * (2.0 - 0.875), 0.5),)
    assert origin.velocities == ((-2.0, 0.0),)
