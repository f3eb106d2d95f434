"""Declared conventions are what the engines do: the time step each engine takes, the
damping of one free step, how a zero mass and a negative half-width are read.

Every expectation comes from the exact oracle or from a rule the adapter declares; none
is an engine's output copied here.
"""

from __future__ import annotations

from typing import Any

import pytest

import adapters
from adapters import pybullet as pbe
from adapters.pybullet import engine
from crosscheck.cases.load import load_paths
from crosscheck.core.geometry import norm
from crosscheck.core.model import Observation
from crosscheck.core.schema import AnyCase, ResponseCase
from crosscheck.truth import oracle
from tests.conftest import ROOT, aabb, response

pytestmark = pytest.mark.engine

PYBULLET = ("pybullet", "pybullet-default")
PYMUNK = ("pymunk", "pymunk-default")
SUITE = {case.id: case for case in load_paths([ROOT / "cases"]).cases}


def test_declared_time_steps_are_the_steps_taken() -> None:
    for name in PYBULLET:
        adapter = adapters.get(name)
        assert isinstance(adapter, pbe.PyBulletTuned)
        w = pbe.world(name + "/response", adapter.world, response=True)
        step = engine().getPhysicsEngineParameters(physicsClientId=w.cid)["fixedTimeStep"]
        assert adapter.conventions.time_step == step
    for name in PYMUNK:
        adapter = adapters.get(name)
        assert adapter.conventions.time_step == getattr(adapter, "dt")  # noqa: B009
        # A head-on pair touching at the start: A has moved one step when pymunk resolves.
        obs = adapter.observe(response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]))
        assert obs.resolved_at == ((adapter.conventions.time_step, 0.0), (1.0, 0.0))
    for name in ("fcl", "reference", "reference-f32"):
        assert adapters.get(name).conventions.time_step is None


@pytest.mark.parametrize("name", PYBULLET + PYMUNK)
def test_declared_damping_is_the_drag_of_one_free_step(name: str) -> None:
    # A separating pair steps once, free: Bullet's multibody drag (btMultiBody.cpp,
    # DAMPING_K1_LINEAR + DAMPING_K2_LINEAR |v|, both the linear damping) takes
    # d (1 + |v|) v dt off each velocity; pymunk's Space damping 1.0 takes nothing.
    adapter = adapters.get(name)
    conventions = adapter.conventions
    dt = conventions.time_step
    assert dt is not None
    v0 = 0.75
    obs = adapter.observe(response([0.0, 0.0], [-v0, 0.0], [2.0, 0.0], [v0, 0.0]))
    assert obs.resolved_at is None
    want = v0 * (1.0 - conventions.damping * (1.0 + v0) * dt)
    assert isinstance(obs.v2, tuple) and obs.v2[0] == pytest.approx(want, rel=1e-9)
    assert obs.v1 == (-obs.v2[0], 0.0)


def test_pybullet_reads_a_zero_mass_as_a_static_body() -> None:
    # Declared "static" (URDF2Bullet: isFixedBase = (mass == 0)): B is immovable, an
    # infinitely heavy body moving at its velocity; the oracle with a vast mass for B is it.
    adapter = adapters.get("pybullet")
    assert adapter.conventions.zero_mass == "static"
    case = SUITE["bad-resp-3d-zero-mass"]
    assert isinstance(case, ResponseCase) and case.b.mass == 0.0
    heavy = case.model_copy(update={"b": case.b.model_copy(update={"mass": 2.0**200})})
    obs, truth = adapter.observe(case), oracle.truth(heavy)
    assert isinstance(truth.v1, tuple) and isinstance(truth.v2, tuple)
    assert obs.v1 == pytest.approx(truth.v1, abs=1e-12)
    assert obs.v2 == pytest.approx(truth.v2, abs=1e-12)


def test_zero_mass_declarations() -> None:
    assert adapters.get("pybullet-default").conventions.zero_mass == "static"
    for name in (*PYMUNK, "fcl", "reference", "reference-f32"):
        assert adapters.get(name).conventions.zero_mass == "", name


def magnitudes(case: AnyCase) -> AnyCase:
    """``case`` with every half-width and radius replaced by its magnitude."""
    update: dict[str, Any] = {}
    for which in ("a", "b"):
        body = getattr(case, which)
        field = "half" if hasattr(body, "half") else "radius"
        value = getattr(body, field)
        new = [abs(x) for x in value] if field == "half" else abs(value)
        update[which] = body.model_copy(update={field: new})
    return case.model_copy(update=update)


def agrees(obs: Observation, truth: Observation) -> bool:
    """Same verdict, and distance and normal (where reported) within 1e-12."""
    if obs.hit is not truth.hit:
        return False
    if (isinstance(obs.distance, float) and isinstance(truth.distance, float)
            and abs(obs.distance - truth.distance) > 1e-12):
        return False
    if isinstance(obs.normal, tuple) and isinstance(truth.normal, tuple):
        return norm([x - y for x, y in zip(obs.normal, truth.normal, strict=True)]) <= 1e-12
    return True


NEGATIVE_BOXES = [aabb([0.0, 0.0], [-1.0, 1.0], [0.5, 0.0], [1.0, 1.0], id="n1"),
                  aabb([0.0, 0.0], [-1.0, 1.0], [1.0, 0.0], [1.0, 1.0], id="n2"),
                  aabb([0.0, 0.0, 0.0], [-1.0, 1.0, 1.0], [0.5, 0.0, 0.0], [1.0, 1.0, 1.0],
                       id="n3")]


@pytest.mark.parametrize("name", ["fcl", *PYBULLET, *PYMUNK, "reference"])
def test_negative_half_widths_are_read_as_declared(name: str) -> None:
    # "absolute": the answer is the truth for the magnitudes; "": the literal textbook's.
    adapter = adapters.get(name)
    rule = adapter.conventions.negative_extents
    assert rule in ("absolute", "")
    for case in NEGATIVE_BOXES:
        if adapter.unsupported(case) is None:
            want = oracle.truth(magnitudes(case) if rule == "absolute" else case)
            assert agrees(adapter.observe(case), want), (name, case.a, case.b)


def test_negative_extent_declarations_match_the_engines() -> None:
    # pymunk's create_box builds the convex hull of +-w/2 (shapes.py): a negative half-width
    # is its magnitude.  FCL and PyBullet boxes with one negative half-width read literally.
    assert adapters.get("pymunk").conventions.negative_extents == "absolute"
    assert adapters.get("pymunk-default").conventions.negative_extents == "absolute"
    for name in ("fcl", *PYBULLET, "reference"):
        assert adapters.get(name).conventions.negative_extents == "", name
