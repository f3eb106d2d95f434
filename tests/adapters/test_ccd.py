"""The CCD variants (pybullet-ccd, box2d-bullet, rapier-ccd, in their engines' packages): each
engine's continuous-collision switch on a fast head-on pair, judged against the exact
event-driven reference.

The pair: two spheres r = 0.05, m = 1, e = 1, head-on at +-50 from 0.6 apart, dt 1/240:
step travel |vb - va| dt / 2(ra + rb) = 2.08, so no step start finds them overlapping and an
engine that only samples contacts lets them pass through.  Every expected value comes from
the exact reference (crosscheck.truth.oracle.truth) or from the scene's initial velocities
(what a pass-through keeps); none is an engine's output copied here.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from adapters.box2d import Box2dBullet, Box2dTuned
from adapters.pybullet import PyBulletCcd, PyBulletTuned
from adapters.rapier import RapierCcd, RapierTuned
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Category, Kind, Observation, Status
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.studies.repro.calls import calls_code
from crosscheck.studies.repro.code import EngineCode
from crosscheck.truth import oracle, scenes
from crosscheck.truth.score import judge

pytestmark = pytest.mark.engine

RADIUS, SPEED, HALF_GAP, DT = 0.05, 50.0, 0.3, 1.0 / 240.0


def head_on(dim: int, speed: float = SPEED, dt: float = DT) -> SceneCase:
    """The fast pair, run to 10 steps after its impact (one impact in the exact run)."""
    pad = (0.0,) * (dim - 2)
    impact = (2.0 * HALF_GAP - 2.0 * RADIUS) / (2.0 * speed)
    case = CASE_ADAPTER.validate_python({
        "id": f"fast-head-on-{dim}d", "description": "two spheres crossing fast",
        "kind": "sphere_scene", "dim": dim, "restitution": 1.0, "duration": impact + 10.0 * dt,
        "dt": dt, "bodies": [
            {"center": (-HALF_GAP, 0.0, *pad), "radius": RADIUS, "mass": 1.0,
             "velocity": (speed, 0.0, *pad)},
            {"center": (HALF_GAP, 0.0, *pad), "radius": RADIUS, "mass": 1.0,
             "velocity": (-speed, 0.0, *pad)}]})
    assert isinstance(case, SceneCase)
    return case


def _velocities(case: SceneCase, adapter: Adapter) -> tuple[Observation, Observation, Any]:
    obs, truth = adapter.observe(case), oracle.truth(case)
    verdict = judge(case, adapter.conventions, "velocities", obs.velocities, truth, obs)
    return obs, truth, verdict


def resolved(case: SceneCase, adapter: Adapter) -> None:
    """The impact is resolved as the exact run has it: the velocities agree, or are off by
    no more than the step lag or the engine's declared precision allows."""
    _, truth, verdict = _velocities(case, adapter)
    assert truth.impacts and len(truth.impacts) == 1
    assert verdict.status is Status.AGREE or verdict.category in (
        Category.TIMESTEP, Category.TOLERANCE), verdict


def passed_through(case: SceneCase, adapter: Adapter) -> None:
    """The bodies passed through each other: final velocities the initial ones, against the
    exact run's exchanged ones."""
    obs, _, verdict = _velocities(case, adapter)
    initial = tuple(tuple(b.velocity) for b in case.bodies)
    assert scenes.relative_error(case, "velocities", obs.velocities, initial) <= 1e-6
    assert verdict.status is Status.DISAGREE and verdict.error >= 1.0


def test_the_pair_crosses_its_overlap_window_between_two_steps() -> None:
    case = head_on(2)
    travel = 2.0 * SPEED * DT / (4.0 * RADIUS)
    assert travel == pytest.approx(2.0833333333333335)
    for k in range(case.step_count + 1):  # no step start finds the two overlapping
        assert abs(2.0 * HALF_GAP - 2.0 * SPEED * k * DT) >= 2.0 * RADIUS


def test_box2d_bullets_resolve_the_impact_that_box2d_passes_through() -> None:
    case = head_on(2)
    resolved(case, Box2dBullet())
    passed_through(case, Box2dTuned())


def test_box2d_bullets_keep_the_speed_cap_of_2_m_per_step() -> None:
    # At dt 1/60 the cap is 2 / dt = 120: the bullet pair at +-200 is the exact run of the
    # pair at +-120 (the cap acts before the first step's positions are integrated).
    adapter = Box2dBullet()
    conv = adapter.conventions
    assert conv.max_speed is not None and conv.time_step is not None
    dt = 1.0 / 60.0
    cap = conv.max_speed * conv.time_step / dt
    assert cap == pytest.approx(120.0)
    fast, capped = head_on(2, 200.0, dt), head_on(2, cap, dt)
    fast = fast.model_copy(update={"duration": capped.duration})
    obs, want = adapter.observe(fast), oracle.truth(capped)
    err = scenes.relative_error(capped, "velocities", obs.velocities, want.velocities)
    assert err <= 2.0 * conv.rtol


@pytest.mark.parametrize("dim", [2, 3])
def test_pybullet_ccd_stops_the_pass_through_of_the_multibody_variant(dim: int) -> None:
    case = head_on(dim)
    passed_through(case, PyBulletTuned())
    obs = PyBulletCcd().observe(case)
    assert isinstance(obs.positions, tuple) and isinstance(obs.velocities, tuple)
    (xa, *_), (xb, *_) = obs.positions
    (va, *_), (vb, *_) = obs.velocities
    assert xa < xb and va < 0.0 < vb  # A stayed left of B and both turned back
    # ... but not with the exact run's bounce: the predictive contact has restitution 0
    truth = oracle.truth(case)
    assert isinstance(truth.velocities, tuple)
    assert abs(va) < abs(truth.velocities[0][0])


@pytest.mark.parametrize("dim", [2, 3])
def test_rapier_ccd_resolves_the_impact_as_tuned_rapier_does(dim: int) -> None:
    case = head_on(dim)
    resolved(case, RapierCcd())
    resolved(case, RapierTuned())  # soft CCD already catches it


def test_the_variants_run_scenes_only_and_declare_no_sampled_contacts() -> None:
    sphere = CASE_ADAPTER.validate_python({
        "id": "s", "description": "d", "kind": "sphere", "dim": 2,
        "a": {"center": (0.0, 0.0), "radius": 1.0}, "b": {"center": (1.0, 0.0), "radius": 1.0}})
    for adapter, dims in ((PyBulletCcd(), (2, 3)), (Box2dBullet(), (2,)), (RapierCcd(), (2, 3))):
        assert adapter.capabilities == {(Kind.SPHERE_SCENE, d) for d in dims}
        assert adapter.unsupported(sphere) is not None
        assert adapter.conventions.sampled_contacts is False
    assert PyBulletTuned.conventions.sampled_contacts is True
    assert Box2dBullet.conventions.max_speed == Box2dTuned.conventions.max_speed


def _run(code: EngineCode) -> dict[str, Any]:
    namespace: dict[str, Any] = {}
    exec("\n".join(code.imports), namespace)
    for name, source, _, _ in code.inputs:
        namespace[name] = eval(source, namespace)
    exec(code.code, namespace)
    return namespace


@pytest.mark.parametrize(("adapter", "write", "switch"), [
    (PyBulletCcd(), calls_code, "CCD = 0.9"),
    (Box2dBullet(), calls_code, "BULLET = True"),
    (RapierCcd(), calls_code, "CCD = True"),
], ids=["pybullet-ccd", "box2d-bullet", "rapier-ccd"])
def test_the_repro_script_makes_the_switch_and_the_adapter_s_answer(
        adapter: Any, write: Any, switch: str) -> None:
    case = head_on(2)
    code = write(adapter, case)
    assert switch in code.code + "".join(f"\n{n} = {plain}" for n, _, _, plain in code.inputs)
    ran, obs = _run(code), adapter.observe(case)
    assert ran["velocities"] == obs.velocities and ran["positions"] == obs.positions
    assert math.isfinite(ran["energy"])
