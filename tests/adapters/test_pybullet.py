"""The PyBullet adapters: native behaviour pinned as measured, and the translation checked.

These tests pin what pybullet 3.2.7 does (each with the engine fact behind it), not
whether it is right; the harness scores rightness.  Every input here was first run in
a separate process: none crashes or hangs the engine.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

import adapters
from adapters.pybullet import BOX_MARGIN, PyBulletTuned, box_sizes, client, engine
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Adapter, all_capabilities
from crosscheck.core.model import Category, Kind, Observation, Status
from crosscheck.core.schema import CASE_ADAPTER, AabbCase, AnyCase
from crosscheck.truth import oracle
from crosscheck.truth.score import judge
from tests.conftest import ROOT, aabb, response, sphere

VARIANTS = ("pybullet", "pybullet-default")
EDGE_GAP = 2 * (math.sqrt(2) - 1) * BOX_MARGIN  # edges rounded by each box's margin
CORNER_GAP = 2 * (math.sqrt(3) - 1) * BOX_MARGIN
SUITE = {case.id: case for case in load_paths([ROOT / "cases"]).cases}

pytestmark = [pytest.mark.engine,
              pytest.mark.skipif(adapters.get("pybullet").available() is not None,
                                 reason="pybullet is not installed")]


def observe(name: str, case: AnyCase) -> Observation:
    return adapters.get(name).observe(case)


def spheres(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    return CASE_ADAPTER.validate_python({
        "id": "s", "description": "d", "kind": "sphere", "dim": len(ca),
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def close(value: Any, want: tuple[float, ...], tol: float = 1e-12) -> bool:
    return isinstance(value, tuple) and len(value) == len(want) and all(
        abs(x - y) <= tol for x, y in zip(value, want, strict=True))


def bodies(name: str) -> int:
    count: int = engine().getNumBodies(physicsClientId=client(name, {}))
    return count


# --- native behaviour (conformance) -------------------------------------------------------

@pytest.mark.parametrize("name", VARIANTS)
def test_face_touching_boxes_are_in_contact(name: str) -> None:
    # Bullet's box-box detector makes four points at distance -0.0 for touching faces.
    obs = observe(name, aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 0.0, 0.0], [1.0, 1.0, 1.0]))
    assert obs.hit is True
    assert isinstance(obs.distance, float) and abs(obs.distance) < 1e-15
    assert close(obs.normal, (1.0, 0.0, 0.0))


@pytest.mark.parametrize("name", VARIANTS)
def test_edge_touching_boxes_read_apart_by_the_margin(name: str) -> None:
    # The 0.001 collision margin rounds box edges: 2 (sqrt 2 - 1) 0.001 apart, no contact.
    obs = observe(name, aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0], [1.0, 1.0, 1.0]))
    assert obs.hit is False
    assert obs.distance == pytest.approx(EDGE_GAP, rel=1e-9)
    assert close(obs.normal, (math.sqrt(0.5), math.sqrt(0.5), 0.0), 1e-9)


@pytest.mark.parametrize("name", VARIANTS)
def test_corner_touching_boxes_read_apart_by_the_margin(name: str) -> None:
    # Rounded corners: 2 (sqrt 3 - 1) 0.001 apart, no contact.
    obs = observe(name, aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [1.0, 1.0, 1.0]))
    assert obs.hit is False
    assert obs.distance == pytest.approx(CORNER_GAP, rel=1e-9)
    assert PyBulletTuned.conventions.margin_for("corner") >= CORNER_GAP  # declared


@pytest.mark.parametrize("name", VARIANTS)
def test_touching_spheres_on_an_axis_are_in_contact(name: str) -> None:
    # btSphereSphereCollisionAlgorithm only rejects len > r0 + r1: touching is contact.
    obs = observe(name, sphere(0.0, 1.0))
    assert (obs.hit, obs.distance) == (True, 0.0)
    assert close(obs.normal, (1.0, 0.0, 0.0), 0.0)


@pytest.mark.parametrize("name", VARIANTS)
def test_touching_spheres_on_a_345_diagonal_are_in_contact(name: str) -> None:
    obs = observe(name, spheres([0.0, 0.0, 0.0], 2.0, [0.0, 3.0, 4.0], 3.0))
    assert (obs.hit, obs.distance) == (True, 0.0)
    assert close(obs.normal, (0.0, 0.6, 0.8), 1e-15)


@pytest.mark.parametrize("name", VARIANTS)
def test_coincident_sphere_centres_get_bullets_fallback_normal(name: str) -> None:
    # For len <= SIMD_EPSILON Bullet uses (1, 0, 0) on B, i.e. (-1, 0, 0) from A to B.
    obs = observe(name, spheres([1.0, -2.0, 3.0], 1.0, [1.0, -2.0, 3.0], 0.5))
    assert (obs.hit, obs.distance, obs.normal) == (True, -1.5, (-1.0, -0.0, -0.0))


@pytest.mark.parametrize("name", VARIANTS)
def test_identical_boxes_report_the_least_overlap(name: str) -> None:
    obs = observe(name, aabb([1.0, 2.0, 3.0], [0.5, 1.0, 2.0], [1.0, 2.0, 3.0], [0.5, 1.0, 2.0]))
    assert obs.hit is True
    assert obs.distance == pytest.approx(-1.0, abs=1e-15)
    assert close(obs.normal, (1.0, 0.0, 0.0))


def test_huge_dynamic_bodies_make_no_contact() -> None:
    # btCollisionWorld drops a dynamic body whose AABB diagonal reaches 1e6 ("Overflow in AABB"):
    # response bodies are dynamic, so an overlapping approach of radius-4e5 spheres is never
    # resolved (velocities kept).  Detection bodies are static, which skip that check.
    moving = CASE_ADAPTER.validate_python({
        "id": "r", "description": "d", "kind": "sphere_response", "dim": 3,
        "a": {"center": [0.0, 0.0, 0.0], "radius": 4e5, "mass": 1.0, "velocity": [1.0, 0.0, 0.0]},
        "b": {"center": [6e5, 0.0, 0.0], "radius": 4e5, "mass": 1.0, "velocity": [0.0, 0.0, 0.0]}})
    obs = observe("pybullet", moving)
    assert (obs.v1, obs.v2, obs.resolved_at) == ((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), None)
    overlap = spheres([0.0, 0.0, 0.0], 4e5, [6e5, 0.0, 0.0], 4e5)
    obs = observe("pybullet", overlap)
    assert obs.hit is True and obs.distance == -2e5


HUGE = ["aabb-3d-scale-1e9-overlap", "aabb-2d-huge-overlap-1", "sphere-3d-scale-1e6-overlap-122",
        "sweep-aabb-3d-scale.scale=1e+06", "sweep-aabb-3d-scale.scale=1e+09"]
"""Suite cases of huge bodies that overlap: detection bodies are static, so PyBullet sees them."""


@pytest.mark.parametrize("name", VARIANTS)
@pytest.mark.parametrize("case_id", HUGE)
def test_pybullet_detects_contact_between_huge_bodies(name: str, case_id: str) -> None:
    case = SUITE[case_id]
    truth = oracle.truth(case)
    assert truth.hit is True
    assert adapters.get(name).observe(case).hit is True


@pytest.mark.parametrize("name", VARIANTS)
def test_huge_spheres_are_detected_as_exactly_as_small_ones(name: str) -> None:
    # Radii 2^29 (an AABB diagonal of 3.7e9, far beyond the dynamic limit of 1e6).
    k = 2.0**30
    case = sphere(0.0, 0.75 * k, ra=0.5 * k, rb=0.5 * k)
    obs, truth = adapters.get(name).observe(case), oracle.truth(case)
    assert (obs.hit, obs.distance) == (truth.hit, truth.distance)


# --- translation ----------------------------------------------------------------------------

@pytest.mark.parametrize("name", VARIANTS)
def test_boxes_are_given_half_widths(name: str) -> None:
    obs = observe(name, aabb([0.0, 0.0, 0.0], [1.0, 0.5, 0.5], [2.5, 0.0, 0.0], [1.0, 0.5, 0.5]))
    assert obs.hit is False
    assert obs.distance == pytest.approx(0.5, abs=1e-12)  # full widths would overlap by 1.5


@pytest.mark.parametrize("kind", ["box", "sphere"])
@pytest.mark.parametrize(("direction", "offset"), [((1.0, 0.0, 0.0), 2.5), ((0.0, -1.0, 0.0), 1.5),
                                                   ((0.0, 0.0, 1.0), 1.0)])
def test_normal_points_from_a_to_b_and_distance_is_signed(
        kind: str, direction: tuple[float, ...], offset: float) -> None:
    cb = [offset * x for x in direction]
    case = (aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], cb, [1.0, 1.0, 1.0]) if kind == "box"
            else spheres([0.0, 0.0, 0.0], 1.0, cb, 1.0))
    obs = observe("pybullet", case)
    assert close(obs.normal, direction, 1e-12)
    assert obs.distance == pytest.approx(offset - 2.0, abs=1e-12)  # gap +, penetration -
    assert obs.hit is (offset < 2.0)


def test_2d_boxes_get_a_z_half_width_beyond_any_in_plane_overlap() -> None:
    case = aabb([10.0, 10.0], [5.0, 3.0], [11.0, 9.0], [1.0, 1.0])
    assert isinstance(case, AabbCase)
    assert box_sizes(case) == ((5.0, 3.0, 10.0), (1.0, 1.0, 10.0))
    obs = observe("pybullet", case)  # contained: least overlap is y (3), never z (20)
    assert obs.hit is True and obs.distance == pytest.approx(-3.0, abs=1e-12)
    assert close(obs.normal, (0.0, -1.0), 1e-12)


def test_2d_corner_touch_reads_as_a_3d_edge_touch() -> None:
    obs = observe("pybullet", aabb([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [1.0, 1.0]))
    assert obs.hit is False and obs.distance == pytest.approx(EDGE_GAP, rel=1e-9)
    assert isinstance(obs.normal, tuple) and len(obs.normal) == 2


def test_2d_discs_are_spheres_at_z_0() -> None:
    obs = observe("pybullet", spheres([0.0, 0.0], 2.5, [-3.0, 4.0], 2.5))
    assert (obs.hit, obs.distance) == (True, 0.0)
    assert close(obs.normal, (-0.6, 0.8), 1e-15)


# --- responses ------------------------------------------------------------------------------

def test_tuned_head_on_swaps_velocities_at_the_start() -> None:
    case = response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0])
    obs = observe("pybullet", case)
    assert (obs.v1, obs.v2) == ((-1.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert obs.resolved_at == ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))


def test_tuned_restitution_is_the_product_of_e_and_1() -> None:
    case = response([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0],
                    restitution=0.5)
    obs = observe("pybullet", case)
    assert close(obs.v1, (0.0, 0.0, 0.5), 1e-15) and close(obs.v2, (0.0, 0.0, 1.5), 1e-15)


def test_tuned_2d_response_stays_planar_and_matches_the_oracle() -> None:
    case = CASE_ADAPTER.validate_python({
        "id": "r", "description": "d", "kind": "sphere_response", "dim": 2,
        "a": {"center": [0.0, 0.0], "radius": 2.0, "mass": 2.0, "velocity": [1.0, 1.0]},
        "b": {"center": [4.0, 3.0], "radius": 3.0, "mass": 1.0, "velocity": [-1.0, 0.0]}})
    obs, truth = observe("pybullet", case), oracle.truth(case)
    assert isinstance(truth.v1, tuple) and isinstance(truth.v2, tuple)
    assert close(obs.v1, truth.v1) and close(obs.v2, truth.v2)
    assert obs.resolved_at == ((0.0, 0.0), (4.0, 3.0))


@pytest.mark.parametrize("name", VARIANTS)
def test_separating_spheres_get_no_impulse(name: str) -> None:
    # The normal impulse is clamped >= 0: no exchange, only default damping acts.
    case = response([0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    obs = observe(name, case)
    assert isinstance(obs.v1, tuple) and isinstance(obs.v2, tuple)
    assert obs.v1[0] == -obs.v2[0] and -1.0 <= obs.v1[0] < -0.999


def test_default_damping_and_slop_take_speed_off_a_bounce() -> None:
    # contactSlop 1e-5 keeps slop/dt = 0.0024 of the approach; damping 0.04 the rest.
    case = response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0])
    obs = observe("pybullet-default", case)
    assert isinstance(obs.v1, tuple)
    assert obs.v1[0] == pytest.approx(-0.9984666666741172, abs=1e-12)


def test_default_threshold_makes_a_slow_bounce_inelastic_a_step_late() -> None:
    # 0.1 < restitutionVelocityThreshold 0.2: e becomes 0; slop lets step 1 leave them approaching.
    case = response([0.0, 0.0], [0.1, 0.0], [1.0, 0.0], [0.0, 0.0])
    obs = observe("pybullet-default", case)
    assert isinstance(obs.v1, tuple) and isinstance(obs.v2, tuple)
    assert obs.v1[0] == pytest.approx(0.05, abs=1e-3) == obs.v2[0]
    # ... but step 1 reported the contact of the touching start: that is where it was resolved.
    assert obs.resolved_at == ((0.0, 0.0), (1.0, 0.0))


def test_declared_conventions_categorise_the_measured_disagreements() -> None:
    def category(name: str, case: AnyCase, quantity: str) -> tuple[Status, str]:
        v = judge(case, adapters.get(name).conventions, quantity,
                  observe(name, case).get(quantity), oracle.truth(case))
        return v.status, v.category

    assert category("pybullet", sphere(0.0, 1.0), "hit") == (Status.DISAGREE,
                                                            Category.CONVENTION)
    edge = aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0], [1.0, 1.0, 1.0])
    assert category("pybullet", edge, "hit") == (Status.DISAGREE, Category.TOLERANCE)
    slow = response([0.0, 0.0], [0.1, 0.0], [1.0, 0.0], [0.0, 0.0])
    assert category("pybullet", slow, "v1") == (Status.AGREE, "")
    assert category("pybullet-default", slow, "v1") == (Status.DISAGREE, Category.CONVENTION)


# --- contract -------------------------------------------------------------------------------

@pytest.mark.parametrize("name", VARIANTS)
@pytest.mark.parametrize("case", [
    aabb([0.0, 0.0], [1.0, 1.0], [1.5, 0.5], [1.0, 1.0]),
    sphere(0.0, 0.75),
    response([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 0.0]),
    response([0.0, 0.0], [0.1, 0.0], [1.0, 0.0], [0.0, 0.0]),
], ids=["aabb", "sphere", "response", "slow-response"])
def test_query_is_repeatable(name: str, case: AnyCase) -> None:
    adapter = adapters.get(name)
    prepared = adapter.prepare(case)
    try:
        first = adapter.query(prepared)
        assert all(adapter.query(prepared) == first for _ in range(3))
    finally:
        adapter.release(prepared)


def test_every_kind_and_dimension_is_supported() -> None:
    adapter = adapters.get("pybullet")
    assert adapter.capabilities == all_capabilities(
        *(k for k in Kind if k is not Kind.SPHERE_TOI))
    for dim in (2, 3):
        z = [0.0] * (dim - 1)
        one = [1.0] * dim
        for case in (sphere(0.0, 1.0, dim=dim), aabb([0.0, *z], one, [3.0, *z], one),
                     response([0.0, *z], [1.0, *z], [1.0, *z], [0.0, *z])):
            assert adapter.unsupported(case) is None

    class Only3d(PyBulletTuned):
        capabilities = all_capabilities(*Kind, dims=(3,))

    reason = Only3d().unsupported(sphere(0.0, 1.0, dim=2))
    assert reason is not None and "pybullet" in reason and "2-D" in reason


def test_invalid_radius_raises_the_engine_error_silently_and_leaves_no_body(
        capfd: pytest.CaptureFixture[str]) -> None:
    adapter: Adapter = adapters.get("pybullet")
    adapter.release(adapter.prepare(sphere(0.0, 1.0)))  # connect first
    capfd.readouterr()
    before = bodies("pybullet")
    with pytest.raises(engine().error):
        adapter.prepare(sphere(0.0, 1.0, rb=0.0))
    assert bodies("pybullet") == before
    assert capfd.readouterr() == ("", "")  # the b3Warning went to /dev/null


def test_version_is_the_pinned_release() -> None:
    assert adapters.get("pybullet").version() == "3.2.7"
    assert adapters.get("pybullet-default").version() == "3.2.7"
