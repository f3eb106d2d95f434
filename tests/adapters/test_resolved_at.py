"""Where a stepping engine says it resolved a response contact (``Observation.resolved_at``).

PyBullet's is the start of the first step after which ``getContactPoints`` is not empty
(replayed here with PyBullet's own calls), so pairs touching at the start resolve at their
own centres; for PyBullet and pymunk the exact distance at ``resolved_at`` says the spheres
are in contact by each engine's declared touching rule.  Every expectation comes from the
exact oracle, a replay of the engine's calls or a declared rule, never from an engine's
output copied here.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

import adapters
from adapters import pybullet as pbe
from adapters.pybullet import engine
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Adapter
from crosscheck.core.geometry import Vec, approach_speed, to3
from crosscheck.core.schema import CASE_ADAPTER, ResponseCase
from crosscheck.truth import oracle
from tests.conftest import ROOT

pytestmark = pytest.mark.engine

PYBULLET = ("pybullet", "pybullet-default")
PYMUNK = ("pymunk", "pymunk-default")
SUITE = {case.id: case for case in load_paths([ROOT / "cases"]).cases}
RESPONSES = [c for c in SUITE.values() if isinstance(c, ResponseCase)]


def finite(case: ResponseCase) -> bool:
    """A response case whose every number is finite and whose masses and radii are positive."""
    numbers = (*case.a.center, *case.b.center, *case.a.velocity, *case.b.velocity,
               case.restitution)
    return (all(math.isfinite(x) for x in numbers) and case.restitution >= 0
            and all(0.0 < x < math.inf for x in (case.a.radius, case.b.radius,
                                                 case.a.mass, case.b.mass)))


def exact_gap(case: ResponseCase, centres: tuple[Vec, Vec]) -> float:
    """The oracle's signed distance between the case's spheres placed at ``centres``."""
    spheres = CASE_ADAPTER.validate_python({
        "id": "gap", "description": "d", "kind": "sphere", "dim": case.dim,
        "a": {"center": list(centres[0]), "radius": case.a.radius},
        "b": {"center": list(centres[1]), "radius": case.b.radius}})
    distance = oracle.truth(spheres).distance
    assert isinstance(distance, float)
    return distance


def size(case: ResponseCase) -> float:
    return max(abs(x) for x in (*case.a.center, *case.b.center, case.a.radius, case.b.radius))


def supported(adapter: Adapter, cases: list[ResponseCase]) -> list[ResponseCase]:
    """The finite cases ``adapter`` runs; for PyBullet only bodies of ordinary size (a
    dynamic body whose AABB overflows makes no contact: see test_pybullet.py)."""
    return [c for c in cases if adapter.unsupported(c) is None and finite(c)
            and (adapter.name not in PYBULLET
                 or pbe.ordinary(c, to3(c.a.center), to3(c.b.center), pbe.body_specs(c)))]


@pytest.mark.parametrize("name", PYBULLET)
@pytest.mark.parametrize("case_id", ["resp-2d-grazing", "resp-2d-grazing.swapped"])
def test_pybullet_grazing_is_resolved_where_the_touching_pair_starts(name: str,
                                                                    case_id: str) -> None:
    # The spheres touch at the start and PyBullet counts touching spheres as contact
    # (declared touching rule), so the first step reports the contact: resolved_at is the
    # case's own centres, where the oracle's distance is 0.
    case = SUITE[case_id]
    assert isinstance(case, ResponseCase)
    adapter = adapters.get(name)
    assert adapter.conventions.touching_is_contact("sphere")
    assert exact_gap(case, (case.a.center, case.b.center)) == 0.0
    obs = adapter.observe(case)
    assert obs.resolved_at == (tuple(case.a.center), tuple(case.b.center))


@pytest.mark.parametrize("name", PYBULLET)
def test_pybullet_pairs_touching_at_the_start_resolve_at_the_start(name: str) -> None:
    # Every suite case whose spheres touch or overlap as declared has its contact reported
    # in the first step, which starts at the case's centres.
    adapter = adapters.get(name)
    checked = 0
    for case in supported(adapter, RESPONSES):
        start = (tuple(case.a.center), tuple(case.b.center))
        if exact_gap(case, start) > 0.0:
            continue
        assert adapter.observe(case).resolved_at == start, case.id
        checked += 1
    assert checked >= 40


@pytest.mark.parametrize("name", PYBULLET + PYMUNK)
def test_resolved_at_is_a_configuration_in_contact(name: str) -> None:
    # Where an engine says it resolved the contact, the exact distance says the spheres touch
    # (PyBullet: touching counts) or overlap (pymunk: strictly), within the declared rtol.
    adapter = adapters.get(name)
    conventions = adapter.conventions
    checked = 0
    for case in supported(adapter, RESPONSES):
        at = adapter.observe(case).resolved_at
        if at is None:
            continue
        gap = exact_gap(case, at)
        tol = conventions.rtol * size(case) + conventions.margin_for("sphere")
        if conventions.touching_is_contact("sphere"):
            assert gap <= tol, (case.id, at, gap)
        else:
            assert gap < tol, (case.id, at, gap)
        checked += 1
    assert checked >= 30


def replay_first_contact(adapter: pbe.PyBulletTuned, case: ResponseCase) -> Any:
    """Step the prepared pair with PyBullet's own calls; the centres before the first step
    after which ``getContactPoints(A, B)`` is not empty (None if the pair stops approaching,
    or MAX_STEPS pass, first)."""
    bt = engine()
    prepared = adapter.prepare(case)
    pair = prepared.built
    try:
        m, cid = pair.motion, pair.cid
        assert m is not None
        for body, p, v in ((pair.a, m.pa, m.va), (pair.b, m.pb, m.vb)):
            bt.resetBasePositionAndOrientation(body, p, (0.0, 0.0, 0.0, 1.0), physicsClientId=cid)
            bt.resetBaseVelocity(body, v, (0.0, 0.0, 0.0), physicsClientId=cid)
        found = None
        for _ in range(pbe.MAX_STEPS):
            pa = bt.getBasePositionAndOrientation(pair.a, physicsClientId=cid)[0]
            pb = bt.getBasePositionAndOrientation(pair.b, physicsClientId=cid)[0]
            bt.stepSimulation(physicsClientId=cid)
            if found is None and bt.getContactPoints(pair.a, pair.b, physicsClientId=cid):
                found = (tuple(pa[:case.dim]), tuple(pb[:case.dim]))
            va = bt.getBaseVelocity(pair.a, physicsClientId=cid)[0]
            vb = bt.getBaseVelocity(pair.b, physicsClientId=cid)[0]
            if not approach_speed(pa, pb, va, vb) > m.tol:
                break
        return found
    finally:
        adapter.release(prepared)


@pytest.mark.parametrize("name", PYBULLET)
def test_pybullet_resolved_at_is_the_start_of_the_first_contact_step(name: str) -> None:
    adapter = adapters.get(name)
    assert isinstance(adapter, pbe.PyBulletTuned)
    for case in supported(adapter, RESPONSES):
        assert adapter.observe(case).resolved_at == replay_first_contact(adapter, case), case.id
