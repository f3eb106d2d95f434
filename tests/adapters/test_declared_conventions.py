"""Issue 13, adapters: responses judged where the engine first reported the contact, pymunk's
moment, the declared conventions (time step, damping, zero mass, negative extents) and
PyBullet detection of huge bodies.

Every expectation comes from the exact oracle or from a rule the adapter declares; none
is an engine's output copied here.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

import adapters
from adapters import pybullet_engine as pbe
from adapters.pybullet_setup import engine
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Adapter
from crosscheck.core.geometry import Vec, approach_speed, norm, to3
from crosscheck.core.model import Observation
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, ResponseCase
from crosscheck.results.store import ResultsStore, read_results
from crosscheck.run.runner import run
from crosscheck.truth import oracle
from tests.conftest import ROOT, aabb, response, sphere

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


def moved(case: ResponseCase, centres: tuple[Vec, Vec]) -> ResponseCase:
    """``case`` with A and B at ``centres`` (velocities as declared)."""
    return case.model_copy(update={"a": case.a.model_copy(update={"center": centres[0]}),
                                   "b": case.b.model_copy(update={"center": centres[1]})})


def size(case: ResponseCase) -> float:
    return max(abs(x) for x in (*case.a.center, *case.b.center, case.a.radius, case.b.radius))


def supported(adapter: Adapter, cases: list[ResponseCase]) -> list[ResponseCase]:
    """The finite cases ``adapter`` runs; for PyBullet only bodies of ordinary size (a
    dynamic body whose AABB overflows makes no contact: see test_adapter_pybullet.py)."""
    return [c for c in cases if adapter.unsupported(c) is None and finite(c)
            and (adapter.name not in PYBULLET
                 or pbe.ordinary(c, to3(c.a.center), to3(c.b.center), pbe.body_specs(c)))]


# --- task 1: resolved_at is where the engine first reported the contact -------------------------

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
    pair = adapter.prepare(case)
    try:
        m, cid = pair.motion, pair.cid
        assert m is not None
        for body, p, v in ((pair.a, m.pa, m.va), (pair.b, m.pb, m.vb)):
            bt.resetBasePositionAndOrientation(body, p, pbe.IDENTITY, physicsClientId=cid)
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
        adapter.release(pair)


@pytest.mark.parametrize("name", PYBULLET)
def test_pybullet_resolved_at_is_the_start_of_the_first_contact_step(name: str) -> None:
    adapter = adapters.get(name)
    assert isinstance(adapter, pbe.PyBulletTuned)
    for case in supported(adapter, RESPONSES):
        assert adapter.observe(case).resolved_at == replay_first_contact(adapter, case), case.id


# --- task 2: pymunk's moment does not depend on the radius -------------------------------------

@pytest.mark.parametrize("name", PYMUNK)
@pytest.mark.parametrize("case_id", ["resp-2d-zero-radius-touching",
                                     "resp-2d-zero-radius-touching.swapped"])
def test_pymunk_zero_radius_response_is_the_textbook_truth(name: str, case_id: str) -> None:
    # Exactly the truth where pymunk resolved the contact (tuned); within the declared
    # arithmetic precision with the default slop and bias (an ulp, measured).
    case = SUITE[case_id]
    assert isinstance(case, ResponseCase)
    adapter = adapters.get(name)
    obs = adapter.observe(case)
    assert obs.resolved_at is not None
    truth = oracle.truth(moved(case, obs.resolved_at))
    if name == "pymunk":
        assert (obs.v1, obs.v2) == (truth.v1, truth.v2)
    for got, want in ((obs.v1, truth.v1), (obs.v2, truth.v2)):
        assert isinstance(got, tuple) and isinstance(want, tuple)
        assert norm([x - y for x, y in zip(got, want, strict=True)]) <= adapter.conventions.rtol


@pytest.mark.parametrize("name", PYMUNK)
def test_pymunk_moment_is_positive_and_independent_of_the_radius(name: str) -> None:
    adapter = adapters.get(name)
    moments = set()
    for radius in (0.0, 0.5, 3.0):
        case = CASE_ADAPTER.validate_python({
            "id": "r", "description": "d", "kind": "sphere_response", "dim": 2,
            "a": {"center": [0.0, 0.0], "radius": radius, "mass": 2.0, "velocity": [1.0, 0.0]},
            "b": {"center": [5.0, 0.0], "radius": 0.5, "mass": 2.0, "velocity": [0.0, 0.0]}})
        prepared = adapter.prepare(case)
        try:
            moments |= {body.moment for body in prepared.bodies}
        finally:
            adapter.release(prepared)
    assert len(moments) == 1 and moments.pop() > 0


@pytest.mark.parametrize("name", PYMUNK)
def test_pymunk_nan_radius_no_longer_kills_the_worker(tmp_path: Path, name: str) -> None:
    cases = [SUITE["bad-resp-2d-nan-radius"], SUITE["bad-resp-2d-nan-radius.swapped"]]
    store = ResultsStore(tmp_path / name)
    run(cases, [adapters.get(name)], store, RunOptions(quick=True))
    store.close()
    frame = read_results(tmp_path / name)
    assert len(frame) == 4 and not set(frame["status"]) & {"crash", "error"}


# --- task 3: declared conventions --------------------------------------------------------------

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


# --- task 4: PyBullet detection of huge bodies --------------------------------------------------

HUGE = ["aabb-3d-scale-1e9-overlap", "aabb-2d-huge-overlap-1", "sphere-3d-scale-1e6-overlap-122",
        "sweep-aabb-3d-scale.scale=1e+06", "sweep-aabb-3d-scale.scale=1e+09"]


@pytest.mark.parametrize("name", PYBULLET)
@pytest.mark.parametrize("case_id", HUGE)
def test_pybullet_detects_contact_between_huge_bodies(name: str, case_id: str) -> None:
    case = SUITE[case_id]
    truth = oracle.truth(case)
    assert truth.hit is True
    assert adapters.get(name).observe(case).hit is True


@pytest.mark.parametrize("name", PYBULLET)
def test_huge_spheres_are_detected_as_exactly_as_small_ones(name: str) -> None:
    # Radii 2^29 (an AABB diagonal of 3.7e9, far beyond the dynamic limit of 1e6).
    k = 2.0**30
    case = sphere(0.0, 0.75 * k, ra=0.5 * k, rb=0.5 * k)
    obs, truth = adapters.get(name).observe(case), oracle.truth(case)
    assert (obs.hit, obs.distance) == (truth.hit, truth.distance)
