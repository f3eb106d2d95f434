"""The scene calls of pybullet and pymunk (adapters/<engine>/calls.py) checked physically.

Each test states a physical expectation and a tolerance with its reason; none pins an
engine's output.  Head-on tests start the balls 0.02 apart so that the collision (at
t = 0.02 / 3 s) is over well before the 30 steps of dt = 1e-3 end: default damping has
little time to act.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from typing import Any

import pytest

pytest.importorskip("pybullet")
pytest.importorskip("pymunk")

from adapters.pybullet import TUNED_BODY, TUNED_WORLD, PyBulletDefault, PyBulletTuned, engine
from adapters.pymunk import PymunkDefault, PymunkTuned
from tests.adapters.scene_calls import Body, SceneCalls, SceneRun

pybullet_scene = SceneCalls(PyBulletTuned())
pymunk_scene = SceneCalls(PymunkTuned())
"""Each engine's scene calls with a scene module's interface (a variant's settings passed in)."""

pytestmark = pytest.mark.engine

DT = 1e-3
VARIANTS = [pytest.param(pybullet_scene, True, 3, id="pybullet-3d"),
            pytest.param(pybullet_scene, True, 2, id="pybullet-2d"),
            pytest.param(pybullet_scene, False, 3, id="pybullet-default-3d"),
            pytest.param(pybullet_scene, False, 2, id="pybullet-default-2d"),
            pytest.param(pymunk_scene, True, 2, id="pymunk"),
            pytest.param(pymunk_scene, False, 2, id="pymunk-default")]
TUNED = [p for p in VARIANTS if p.values[1] is True]
EXACT = 1e-12
"""Relative tolerance of a single contact solved exactly: the impulse is a handful of
float64 operations (rounding ~1e-16), and later solver iterations add corrections of that
size; 1e-12 leaves four orders of margin."""
SETTINGS: dict[tuple[Any, bool], Any] = {
    (pybullet_scene, True): PyBulletTuned().scene_settings(),
    (pybullet_scene, False): PyBulletDefault().scene_settings(),
    (pymunk_scene, True): PymunkTuned().scene_settings(),
    (pymunk_scene, False): PymunkDefault().scene_settings(),
}


def tuning(module: Any, tuned: bool) -> Any:
    """The settings value the adapter of that variant passes to ``module.prepare_scene``."""
    return SETTINGS[module, tuned]


def test_adapters_pass_the_tuned_settings_or_none() -> None:
    assert tuning(pybullet_scene, True) == {"world_settings": TUNED_WORLD, "body": TUNED_BODY,
                                            "maximal": False, "ccd": 0.0}
    assert PyBulletTuned.world is TUNED_WORLD and PyBulletTuned.body is TUNED_BODY
    assert tuning(pymunk_scene, True) == {"slop": 0.0, "bias": 1.0, "friction": 0.0}
    assert tuning(pybullet_scene, False) == {"world_settings": {}, "body": {},
                                             "maximal": False, "ccd": 0.0}
    assert tuning(pymunk_scene, False) == {"slop": None, "bias": None, "friction": None}


def run(module: Any, bodies: Sequence[Body], dim: int, e: float, steps: int,
        tuned: bool) -> SceneRun:
    prepared = module.prepare_scene(bodies, dim, e, DT, None, tuning(module, tuned))
    try:
        result: SceneRun = module.run_scene(prepared, steps)
    finally:
        module.release_scene(prepared)
    return result


def on_x(dim: int, *xs: float) -> tuple[float, ...]:
    return (*xs, *[0.0] * (dim - len(xs)))


def head_on(dim: int, va: float = 2.0, vb: float = -1.0) -> list[Body]:
    """Two unit-mass balls of radius 0.5, 0.02 apart on the x axis, closing at va - vb."""
    return [(on_x(dim, -0.51), 0.5, 1.0, on_x(dim, va)),
            (on_x(dim, 0.51), 0.5, 1.0, on_x(dim, vb))]


def exchange_tolerance(module: Any, tuned: bool) -> float:
    """How far from exchanged the head-on velocities may be (closing speed 3, 0.03 s).

    Exact contacts (``EXACT`` x the speed) everywhere but default pybullet.  pymunk's default
    slop and bias move positions only, through separate bias velocities.  Default pybullet
    adds two documented effects: damping 0.04 acting as dv/dt = -0.04 (1 + |v|) v, at most
    0.04 x 3 x 2 x 0.03 = 0.0072 here; and the contact ERP push, a relative separation of
    0.08 x depth / dt with depth <= closing speed x dt, shared by the equal masses:
    0.04 x 3 = 0.12 per ball.
    """
    if module is pybullet_scene and not tuned:
        return 0.0072 + 0.12
    return EXACT * 3.0


@pytest.mark.parametrize(("module", "tuned", "dim"), VARIANTS)
def test_head_on_equal_masses_exchange_velocities(module: Any, tuned: bool,
                                                  dim: int) -> None:
    result = run(module, head_on(dim), dim, 1.0, 30, tuned)
    tol = exchange_tolerance(module, tuned)
    assert result.velocities[0] == pytest.approx(on_x(dim, -1.0), abs=tol)
    assert result.velocities[1] == pytest.approx(on_x(dim, 2.0), abs=tol)


@pytest.mark.parametrize(("module", "tuned", "dim"), TUNED)
def test_head_on_tuned_conserves_momentum(module: Any, tuned: bool, dim: int) -> None:
    bodies = head_on(dim)
    result = run(module, bodies, dim, 1.0, 30, tuned)
    before = [sum(m * v[k] for _, _, m, v in bodies) for k in range(dim)]
    after = [sum(m * v[k] for (_, _, m, _), v in zip(bodies, result.velocities, strict=True))
             for k in range(dim)]
    scale = sum(m * math.hypot(*v) for _, _, m, v in bodies)  # 3: the momentum's magnitude
    assert result.velocities[0][0] < 0.0  # the collision happened
    assert all(abs(a - b) <= 1e-9 * scale for a, b in zip(after, before, strict=True))


def coefficient(result: SceneRun, closing: float) -> float:
    """Separation speed over approach speed along x."""
    return (result.velocities[1][0] - result.velocities[0][0]) / closing


@pytest.mark.parametrize(("module", "tuned", "dim"), TUNED)
def test_restitution_product_rule_gives_the_scene_value(module: Any, tuned: bool,
                                                         dim: int) -> None:
    # Each body gets sqrt(0.25) = 0.5; the product is 0.25 (min/max/mean would give 0.5).
    result = run(module, head_on(dim, 1.0, -1.0), dim, 0.25, 30, tuned)
    assert coefficient(result, 2.0) == pytest.approx(0.25, abs=EXACT)


def set_restitutions(module: Any, prepared: Any, values: Sequence[float]) -> None:
    if module is pybullet_scene:
        bt = engine()
        for uid, r in zip(prepared["spheres"], values, strict=True):
            bt.changeDynamics(uid, -1, restitution=r, physicsClientId=prepared["cid"])
    else:
        for shape, r in zip(prepared["shapes"], values, strict=True):
            shape.elasticity = r


@pytest.mark.parametrize(("module", "tuned", "dim"), TUNED)
def test_engines_combine_restitution_by_product(module: Any, tuned: bool,
                                                dim: int) -> None:
    # 0.5 and 0.8: product 0.4; min 0.5, mean 0.65, max 0.8, geometric mean 0.63.
    prepared = module.prepare_scene(head_on(dim, 1.0, -1.0), dim, 1.0, DT, None,
                                    tuning(module, tuned))
    try:
        set_restitutions(module, prepared, (0.5, 0.8))
        result = module.run_scene(prepared, 30)
    finally:
        module.release_scene(prepared)
    assert coefficient(result, 2.0) == pytest.approx(0.4, abs=EXACT)


def cluster(n: int, dim: int, seed: int) -> list[Body]:
    """``n`` spheres on a jittered grid of pitch 1.5 (radii 0.3-0.5), random velocities."""
    rnd = random.Random(seed)
    side = math.ceil(n ** (1 / dim))
    bodies: list[Body] = []
    for i in range(n):
        cell = [(i // side**k) % side for k in range(dim)]
        center = tuple(1.5 * c + rnd.uniform(-0.2, 0.2) for c in cell)
        velocity = tuple(rnd.uniform(-1.0, 1.0) for _ in range(dim))
        bodies.append((center, rnd.uniform(0.3, 0.5), rnd.uniform(0.5, 2.0), velocity))
    return bodies


@pytest.mark.parametrize("tuned", [True, False], ids=["pybullet", "pybullet-default"])
def test_pybullet_2d_scene_stays_in_the_plane(tuned: bool) -> None:
    # Oblique contacts, with default friction 0.5 too: the normals lie in z = 0.
    bodies = cluster(16, 2, seed=1)
    prepared = pybullet_scene.prepare_scene(bodies, 2, 0.7, DT, None,
                                            tuning(pybullet_scene, tuned))
    try:
        result = pybullet_scene.run_scene(prepared, 1500)
        positions, velocities = pybullet_scene.scene_state(prepared)
    finally:
        pybullet_scene.release_scene(prepared)
    assert all(len(p) == 2 for p in (*result.positions, *result.velocities))
    assert sum(v != b[3] for v, b in zip(result.velocities, bodies, strict=True)) >= 4
    assert [p[2] for p in positions] == [0.0] * 16
    assert [v[2] for v in velocities] == [0.0] * 16


def watch_steps(module: Any, prepared: Any, log: list[str],
                monkeypatch: pytest.MonkeyPatch) -> None:
    """Note each engine step of ``prepared`` in ``log`` (the step still runs)."""
    if module is pybullet_scene:
        owner, name = engine(), "stepSimulation"
    else:
        owner, name = prepared["space"], "step"
    step = getattr(owner, name)

    def noted(*args: Any, **kwargs: Any) -> Any:
        log.append("step")
        return step(*args, **kwargs)

    monkeypatch.setattr(owner, name, noted)


@pytest.mark.parametrize(("module", "tuned", "dim"), VARIANTS)
def test_setup_is_outside_the_timed_loop(module: Any, tuned: bool, dim: int,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    # Injected time: the clock's readings go to the same log as the engine's steps, so the
    # log shows what the timed span holds; building the scene takes no clock at all.
    log: list[str] = []
    readings = iter([10.0, 10.5, 20.0, 22.25])

    def clock() -> float:
        log.append("clock")
        return next(readings)

    prepared = module.prepare_scene(cluster(16, dim, seed=0), dim, 1.0, DT, None,
                                    tuning(module, tuned))
    try:
        watch_steps(module, prepared, log, monkeypatch)
        idle = module.run_scene(prepared, 0, clock=clock)
        assert log == ["clock", "clock"]
        log.clear()
        stepped = module.run_scene(prepared, 7, clock=clock)
        assert log == ["clock", *["step"] * 7, "clock"]
    finally:
        module.release_scene(prepared)
    assert (idle.steps, stepped.steps) == (0, 7)
    assert (idle.wall_s, stepped.wall_s) == (0.5, 2.25)  # the two readings' difference


@pytest.mark.parametrize(("n", "dim"), [(2, 3), (16, 2), (30, 3)])
def test_pybullet_client_holds_only_the_scene_and_release_empties_it(n: int,
                                                                     dim: int) -> None:
    bt = engine()
    pybullet_scene.drop_idle_scene_clients()
    prepared = pybullet_scene.prepare_scene(cluster(n, dim, seed=2), dim, 1.0, DT, 5,
                                            tuning(pybullet_scene, True))
    try:
        assert bt.getNumBodies(physicsClientId=prepared["cid"]) == n
        assert bt.isConnected(physicsClientId=prepared["cid"])
    finally:
        pybullet_scene.release_scene(prepared)
    assert bt.isConnected(physicsClientId=prepared["cid"])  # kept for the next scene, empty
    assert bt.getNumBodies(physicsClientId=prepared["cid"]) == 0
    assert pybullet_scene.idle_scene_clients() == 1
    pybullet_scene.drop_idle_scene_clients()
    assert not bt.isConnected(physicsClientId=prepared["cid"])


def test_pymunk_refuses_3d() -> None:
    with pytest.raises(ValueError, match="2-D"):
        pymunk_scene.prepare_scene(head_on(3), 3, 1.0, DT, None, tuning(pymunk_scene, True))


@pytest.mark.parametrize("module", [pybullet_scene, pymunk_scene], ids=["pybullet", "pymunk"])
def test_bad_scenes_raise_before_the_engine_sees_them(module: Any) -> None:
    # pymunk aborts the interpreter on mass 0, pybullet makes a mass-0 body static.
    zero_mass: list[Body] = [((0.0, 0.0), 0.5, 0.0, (1.0, 0.0))]
    with pytest.raises(ValueError, match="mass"):
        module.prepare_scene(zero_mass, 2, 1.0, DT, None, tuning(module, True))
    with pytest.raises(ValueError, match="restitution"):
        module.prepare_scene(head_on(2), 2, -0.5, DT, None, tuning(module, True))
