"""The categories and reasons of scene measures (:mod:`crosscheck.truth.measure_rules`): each
declared convention explains only what it can (the numbers are built from the conventions,
never from an engine's output)."""

from __future__ import annotations

from typing import Any

from crosscheck.core.contract import Conventions
from crosscheck.core.model import Observation, Status, Value
from crosscheck.core.schema import CASE_ADAPTER, SceneCase
from crosscheck.truth import measure_rules, scenes

G, DT = 8.0, 1.0 / 64.0
TOL = 1e-9


def case(center_y: float, restitution: float = 1.0, duration: float = 2.0) -> SceneCase:
    made = CASE_ADAPTER.validate_python({
        "id": "r", "description": "d", "kind": "sphere_scene", "dim": 2, "duration": duration,
        "dt": DT, "restitution": restitution, "gravity": [0.0, -G],
        "walls": [{"normal": [0.0, 1.0], "offset": 0.0}],
        "bodies": [{"center": [0.0, center_y], "radius": 0.5, "mass": 1.0,
                    "velocity": [0.0, 0.0]}]})
    assert isinstance(made, SceneCase)
    return made


def judged(scene: SceneCase, conventions: Conventions, quantity: str, value: Value,
           **observed: Any) -> tuple[Status, str, str]:
    truth = scenes.truth(scene)
    want = truth.get(quantity)
    assert want is not None
    status, _, _, category, reason = measure_rules.judge(
        scene, conventions, quantity, value, want, truth, Observation(**observed), TOL)
    return status, category, reason


REST = case(0.5)  # resting exactly on the ground
DROP = case(1.5)  # an elastic drop from a gap of 1: apexes 1


def test_a_settle_offset_inside_the_declared_rest_band_is_a_convention() -> None:
    band = Conventions(rest_gap=(-0.01, 0.0))
    assert judged(REST, band, "settle", (-0.005,))[:2] == (Status.DISAGREE, "convention")
    assert judged(REST, band, "settle", (-0.02,))[1] == "error"
    assert judged(REST, band, "settle", (0.005,))[1] == "error"  # floating is not in the band


def test_the_step_sink_allows_one_step_of_gravity_either_way_as_timestep() -> None:
    step = Conventions(rest_sink_steps=1.0)
    one = G * DT * DT
    assert judged(REST, step, "settle", (-0.9 * one,))[1] == "timestep"
    assert judged(REST, step, "settle", (0.9 * one,))[1] == "timestep"
    assert judged(REST, step, "settle", (-1.5 * one,))[1] == "error"


def test_soft_restitution_explains_lost_apex_height_but_never_gained() -> None:
    soft = Conventions(restitution_model="soft")
    exact = scenes.truth(DROP).apex
    assert isinstance(exact, tuple) and exact
    lower = tuple(0.5 * h for h in exact)
    higher = tuple(1.5 * h for h in exact)
    times = scenes.truth(DROP).bounce_time
    assert judged(DROP, soft, "apex", lower, apex=lower, bounce_time=times)[1] == "convention"
    assert judged(DROP, Conventions(), "apex", lower, apex=lower,
                  bounce_time=times)[1] == "error"
    status, category, reason = judged(DROP, soft, "apex", higher, apex=higher,
                                      bounce_time=times)
    assert (status, category) == (Status.DISAGREE, "error")
    assert "soft" in reason  # it names what it read and could not use


def test_declared_damping_explains_an_energy_loss_only_up_to_what_it_can_remove() -> None:
    damped = Conventions(damping=0.01)
    small, large = -0.001, -0.4  # per second of the energy scale, over a 2 s run
    assert judged(DROP, damped, "energy_drift", small)[1] == "convention"
    assert judged(DROP, damped, "energy_drift", large)[1] != "convention"
    assert judged(DROP, damped, "energy_drift", -small)[1] != "convention"  # a gain


def test_the_restitution_threshold_explains_no_energy_gain() -> None:
    threshold = Conventions(restitution_threshold=100.0)  # every bounce below it
    assert judged(DROP, threshold, "energy_drift", -0.001)[1] == "convention"
    assert judged(DROP, threshold, "energy_drift", 0.001)[1] != "convention"
