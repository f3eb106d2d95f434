"""Issue 13's scoring defects, each pinned by a test that failed on the code before the fix.

Engine answers here are synthetic, made from the exact oracle and the engine's declared
rule (a tilt its margin allows, a value it cannot resolve), never copied from an engine.
"""

from __future__ import annotations

import math
from dataclasses import replace

import pandas as pd

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Conventions
from crosscheck.core.model import Category, Observation, Status, Undefined
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.report.mirror import asymmetries
from crosscheck.truth import oracle, scenes
from crosscheck.truth.score import judge
from tests.conftest import ROOT, aabb, sphere

SUITE = {case.id: case for case in load_paths([ROOT / "cases"]).cases}


def _rotated(normal: tuple[float, ...], angle: float) -> tuple[float, ...]:
    """``normal`` turned by ``angle`` towards an axis perpendicular to it (3-D)."""
    x, y, z = normal
    side = (y, -x, 0.0) if abs(z) < 0.9 else (0.0, z, -y)
    length = math.hypot(*side)
    perp = tuple(c / length for c in side)
    return tuple(math.cos(angle) * n + math.sin(angle) * p for n, p in zip(normal, perp,
                                                                           strict=True))


def test_1_a_normal_across_the_gap_tilts_by_the_margin_over_the_gap() -> None:
    case = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [2.0, 2.0, 2.0], [0.5, 0.5, 0.5])
    truth = oracle.truth(case)  # gap sqrt(3) = 1.73, centres 3.46 apart
    assert isinstance(truth.normal, tuple) and isinstance(truth.distance, float)
    engine = Conventions(margins={"corner": 0.002})
    allowed = 0.002 / truth.distance  # what a 0.002 length error does across the gap
    tilted = _rotated(truth.normal, 0.8 * allowed)  # beyond 0.002 / 3.46 (the old rule)
    verdict = judge(case, engine, "normal", tilted, truth)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)
    beyond = judge(case, engine, "normal", _rotated(truth.normal, 1.5 * allowed), truth)
    assert beyond.category == Category.ERROR


def test_2_an_undefined_answer_within_declared_precision_is_tolerance() -> None:
    case = sphere(1e9, 1e9 + 1.5)  # float32 cannot tell these centres apart
    truth = oracle.truth(case)
    f32 = adapters.get("reference-f32").conventions
    assert oracle.textbook(case, "f32").normal == Undefined("coincident centres")
    verdict = judge(case, f32, "normal", Undefined("coincident centres"), truth)
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)
    assert "centres 1.5 apart" in verdict.reason
    far = judge(sphere(0.0, 2.0), f32, "normal", Undefined("x"), oracle.truth(sphere(0.0, 2.0)))
    assert far.category == Category.ERROR


def test_5_identical_infinite_answers_mirror() -> None:
    rows = pd.DataFrame([
        {"case_id": "c", "engine": "e", "quantity": "distance", "value": "Infinity",
         "tolerance": 1e-9, "twin_of": ""},
        {"case_id": "c.swapped", "engine": "e", "quantity": "distance", "value": "Infinity",
         "tolerance": 1e-9, "twin_of": "c"},
        {"case_id": "d", "engine": "e", "quantity": "distance", "value": "Infinity",
         "tolerance": 1e-9, "twin_of": ""},
        {"case_id": "d.swapped", "engine": "e", "quantity": "distance", "value": "-Infinity",
         "tolerance": 1e-9, "twin_of": "d"}])
    assert asymmetries(rows)["case_id"].tolist() == ["d"]


def test_6_no_truth_is_invented_where_the_case_has_none() -> None:
    case = SUITE["resp-2d-coincident-centres"]
    truth = oracle.truth(case)
    assert isinstance(truth.v1, Undefined)
    moved = Observation(v1=(0.5, 0.0), v2=(-0.5, 0.0), resolved_at=((-0.1, 0.0), (0.1, 0.0)))
    for quantity in ("v1", "v2"):
        verdict = judge(case, adapters.get("pymunk").conventions, quantity,
                        moved.get(quantity), truth, moved)
        assert verdict.status is Status.UNDEFINED


def test_7_a_box_margin_is_never_applied_to_spheres() -> None:
    pybullet = adapters.get("pybullet").conventions
    assert pybullet.margin_for("sphere") == 0.0 and pybullet.margin_for("face") > 0
    case = sphere(0.0, 1.001)  # apart by 1e-3: a sphere verdict wrong by 1e-3 is an error
    truth = oracle.truth(case)
    verdict = judge(case, pybullet, "hit", True, truth)
    assert verdict.category == Category.ERROR and "margin" not in verdict.reason
    boxes = aabb([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.001, 0.0, 0.0], [0.5, 0.5, 0.5])
    within = judge(boxes, pybullet, "hit", True, oracle.truth(boxes))
    assert within.category == Category.TOLERANCE and "margin 0.002 at a face" in within.reason


def test_agree_is_as_right_as_float64_allows() -> None:
    mixed = SUITE["aabb-2d-mixed-scale"]
    truth = oracle.truth(mixed)
    assert isinstance(truth.distance, float)
    off = judge(mixed, adapters.get("pybullet").conventions, "distance", -0.001, truth)
    assert off.status is Status.DISAGREE  # 1e-9 x the 1e9 coordinate no longer excuses it
    far = sphere(1e10, 1e10 + 1.001)  # float32 reads -1 where the truth is +0.001
    verdict = judge(far, adapters.get("reference-f32").conventions, "distance", -1.0,
                    oracle.truth(far))
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.TOLERANCE)




def _scene(dt: float) -> SceneCase:
    case = CASE_ADAPTER.validate_python({
        "id": "s", "description": "head on", "kind": "sphere_scene", "dim": 2, "duration": 1.0,
        "dt": dt, "bodies": [
            {"center": [0.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [1.0, 0.0]},
            {"center": [2.0, 0.0], "radius": 0.5, "mass": 1.0, "velocity": [-1.0, 0.0]}]})
    assert isinstance(case, SceneCase)
    return case


def _shifted(truth: Observation, dx: float, dv: float) -> Observation:
    assert isinstance(truth.positions, tuple) and isinstance(truth.velocities, tuple)
    return replace(truth, positions=tuple((p[0] + dx, p[1]) for p in truth.positions),
                   velocities=tuple((v[0] + dv, v[1]) for v in truth.velocities), impacts=None)


def test_scenes_get_categories_from_the_step_and_declared_damping() -> None:
    case = _scene(0.01)
    truth = scenes.truth(case)
    assert truth.impacts is not None and len(truth.impacts) == 1
    lag = scenes.lag_bound(case, 1)  # 2 impacts' worth (1 + the end) x speed 1 x dt / r 0.5
    assert math.isclose(lag, 0.04)
    late = _shifted(truth, 0.5 * lag * 0.5, 0.0)  # positions off by half the lag (mean radii)
    for quantity in ("positions",):
        verdict = judge(case, Conventions(), quantity, late.get(quantity), truth, late)
        assert verdict.category == Category.TIMESTEP and "one step late" in verdict.reason
    far = _shifted(truth, 2.0 * lag * 0.5, 0.01)
    assert judge(case, Conventions(), "positions", far.positions, truth, far).category == "error"
    # velocities are excused by the lag only when the positions are within it too
    assert judge(case, Conventions(), "velocities", far.velocities, truth, far).category == "error"
    near = _shifted(truth, 0.0, 0.01)
    assert judge(case, Conventions(), "velocities", near.velocities, truth,
                 near).category == Category.TIMESTEP
    drained = replace(truth, energy=0.9 * float(truth.energy or 0.0))
    damped = judge(case, Conventions(damping=0.04), "energy", drained.energy, truth, drained)
    assert damped.category == Category.CONVENTION and "damps" in damped.reason
    assert judge(case, Conventions(), "energy", drained.energy, truth, drained).category == "error"
