"""The pymunk adapters: pinned native behaviour of pymunk 7.3.1 and the translation.

These tests check the translation, not pymunk's correctness: each pins what the
engine was measured to do, with the engine fact named.  Nothing here builds a
``Body`` with mass <= 0, NaN or inf (that aborts the interpreter).
"""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

pymunk = pytest.importorskip("pymunk")

import adapters  # noqa: E402
from adapters.pymunk import PymunkDefault, PymunkTuned  # noqa: E402
from crosscheck.cases.load import load_paths  # noqa: E402
from crosscheck.core.contract import Adapter  # noqa: E402
from crosscheck.core.geometry import Vec, norm  # noqa: E402
from crosscheck.core.model import Observation  # noqa: E402
from crosscheck.core.options import RunOptions  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, ResponseCase  # noqa: E402
from crosscheck.results.run import read_results  # noqa: E402
from crosscheck.results.store import ResultsStore  # noqa: E402
from crosscheck.run.runner import run  # noqa: E402
from crosscheck.truth import oracle  # noqa: E402
from tests.conftest import ROOT, aabb, response, sphere  # noqa: E402

pytestmark = pytest.mark.engine

TUNED, DEFAULT = PymunkTuned(), PymunkDefault()
BOTH = pytest.mark.parametrize("adapter", [TUNED, DEFAULT], ids=["pymunk", "pymunk-default"])
PYMUNK = ("pymunk", "pymunk-default")
SUITE = {case.id: case for case in load_paths([ROOT / "cases"]).cases}


def disc(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A 2-D sphere case with centres anywhere in the plane."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": 2,
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def f32(x: float) -> float:
    """``x`` rounded to float32, as a C ``float`` literal."""
    value: float = struct.unpack("f", struct.pack("f", x))[0]
    return value


def observe(case: AnyCase, adapter: Adapter = TUNED) -> Observation:
    return adapter.observe(case)


# --- native behaviour (conformance) ----------------------------------------------------------

def test_face_touching_boxes_collide_with_zero_distance() -> None:
    # Munk2D PolyToPoly: contact when the GJK distance d - r1 - r2 <= 0 (touching counts).
    obs = observe(aabb([0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [1.0, 1.0]))
    assert (obs.hit, obs.distance, obs.normal) == (True, 0.0, (1.0, 0.0))


def test_edge_touching_boxes_collide_with_zero_distance() -> None:
    # Sides touching over part of their length: still a contact, normal across the shared side.
    obs = observe(aabb([0.0, 0.0], [1.0, 1.0], [0.5, -3.0], [2.0, 2.0]))
    assert (obs.hit, obs.distance, obs.normal) == (True, 0.0, (0.0, -1.0))


def test_corner_touching_boxes_collide_and_engine_picks_x() -> None:
    # Only a vertex touches: Munk2D reports a contact with normal (1, -0), distance 0.
    obs = observe(aabb([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [1.0, 1.0]))
    assert (obs.hit, obs.distance, obs.normal) == (True, 0.0, (1.0, 0.0))


def test_touching_circles_on_an_axis_do_not_collide() -> None:
    # Munk2D CircleToCircle: contact only when distsq < mindist^2 (strict).
    obs = observe(sphere(0.0, 1.0, dim=2))
    assert obs == Observation(hit=False)


def test_touching_circles_on_a_345_diagonal_do_not_collide() -> None:
    assert observe(disc([0.0, 0.0], 2.5, [3.0, 4.0], 2.5)) == Observation(hit=False)


def test_coincident_circles_collide_with_normal_plus_x() -> None:
    # CircleToCircle uses n = (1, 0) when the centres coincide; depth is ra + rb.
    obs = observe(disc([1.0, 1.0], 0.5, [1.0, 1.0], 0.5))
    assert (obs.hit, obs.distance, obs.normal) == (True, -1.0, (1.0, 0.0))


def test_coincident_boxes_collide_with_zero_normal_and_zero_depth() -> None:
    # EPA degenerates for coincident equal boxes: distance 0 and a zero-length normal (0, -0).
    obs = observe(aabb([0.0, 0.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0]))
    assert (obs.hit, obs.distance, obs.normal) == (True, 0.0, (0.0, 0.0))


def test_zero_size_boxes_apart_still_report_contact() -> None:
    # Two points 2^-30 apart: GJK on degenerate polygons reports a contact at distance 0.
    obs = observe(aabb([0.0, 0.0], [0.0, 0.0], [0.0, 2.0**-30], [0.0, 0.0]))
    assert (obs.hit, obs.distance) == (True, 0.0)


def test_separated_shapes_raise_assertion_error_natively() -> None:
    # pymunk asserts the point count while building the ContactPointSet: no contact raises.
    prepared = TUNED.prepare(sphere(0.0, 3.0, dim=2))
    with pytest.raises(AssertionError):
        prepared.built[0].shapes_collide(prepared.built[1])
    assert TUNED.query(prepared) == Observation(hit=False)


def test_shapes_outside_a_space_are_stale_until_cache_bb() -> None:
    # Why prepare calls cache_bb(): moving the body does not move an unattached shape.
    body = pymunk.Body(body_type=pymunk.Body.STATIC)
    shape = pymunk.Circle(body, 0.5)
    shape.cache_bb()
    far = pymunk.Circle(pymunk.Body(body_type=pymunk.Body.STATIC), 0.5)
    far.body.position = (5.0, 0.0)
    far.cache_bb()
    body.position = (5.0, 0.0)
    assert shape.bb.left == -0.5  # still where it was cached
    with pytest.raises(AssertionError):  # and collides from there
        shape.shapes_collide(far)
    shape.cache_bb()
    assert shape.bb.left == 4.5
    assert shape.shapes_collide(far).points[0].distance == -1.0


# --- translation -------------------------------------------------------------------------------

def test_boxes_get_full_extents_from_half_widths() -> None:
    prepared = TUNED.prepare(aabb([0.0, 0.0], [1.0, 0.5], [5.0, 0.0], [1.0, 1.0]))
    box = prepared.built[0]
    xs = sorted({v.x for v in box.get_vertices()})
    ys = sorted({v.y for v in box.get_vertices()})
    assert (xs, ys, box.radius) == ([-1.0, 1.0], [-0.5, 0.5], 0.0)
    # half-widths 1 and 1 at centres 1.5 apart overlap by 0.5 (they would not if read as full)
    assert observe(aabb([0.0, 0.0], [1.0, 1.0], [1.5, 0.0], [1.0, 1.0])).distance == -0.5


@pytest.mark.parametrize("kind", ["aabb", "sphere"])
def test_normal_points_from_a_to_b_and_distance_is_negative_in_overlap(kind: str) -> None:
    def case(xa: float, xb: float) -> AnyCase:
        if kind == "aabb":
            return aabb([xa, 0.0], [0.5, 0.5], [xb, 0.0], [0.5, 0.5])
        return sphere(xa, xb, dim=2)

    right, left = observe(case(0.0, 0.75)), observe(case(0.75, 0.0))
    assert (right.normal, left.normal) == ((1.0, 0.0), (-1.0, 0.0))
    assert right.distance == left.distance == pytest.approx(-0.25, abs=1e-15)
    assert isinstance(right.distance, float) and right.distance < 0


def test_observations_are_2d_vectors() -> None:
    obs = observe(disc([0.0, 0.0], 2.5, [3.0, 3.0], 2.5))
    assert isinstance(obs.normal, tuple) and len(obs.normal) == 2
    resp = observe(response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]))
    assert isinstance(resp.v1, tuple) and len(resp.v1) == 2 and resp.resolved_at is not None
    assert all(len(c) == 2 for c in resp.resolved_at)


def test_restitution_uses_the_product_trick() -> None:
    # Munk2D: arbiter e = a.e * b.e; the adapter gives A the case's e and B 1.0.
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0], restitution=0.5)
    prepared = TUNED.prepare(case)
    assert [s.elasticity for s in prepared.built["shapes"]] == [0.5, 1.0]
    obs = TUNED.query(prepared)
    assert obs.v1 == pytest.approx((0.25, 0.0), abs=1e-15)
    assert obs.v2 == pytest.approx((0.75, 0.0), abs=1e-15)


@pytest.mark.parametrize(("adapter", "dt"), [(TUNED, 1e-3), (DEFAULT, 1.0 / 60.0)])
def test_resolved_at_is_where_the_first_step_found_the_contact(adapter: Any, dt: float) -> None:
    # Positions are integrated before collision detection: touching bodies resolve one step later.
    obs = observe(response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]), adapter)
    assert obs.resolved_at == ((dt, 0.0), (1.0, 0.0))
    assert obs.v1 == pytest.approx((0.0, 0.0), abs=1e-15)
    assert obs.v2 == pytest.approx((1.0, 0.0), abs=1e-15)


def moved(case: ResponseCase, centres: tuple[Vec, Vec]) -> ResponseCase:
    """``case`` with A and B at ``centres`` (velocities as declared)."""
    return case.model_copy(update={"a": case.a.model_copy(update={"center": centres[0]}),
                                   "b": case.b.model_copy(update={"center": centres[1]})})


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
            moments |= {body.moment for body in prepared.built["bodies"]}
        finally:
            adapter.release(prepared)
    assert len(moments) == 1 and moments.pop() > 0


@pytest.mark.parametrize("name", PYMUNK)
def test_a_nan_radius_is_a_recorded_status_not_a_dead_worker(tmp_path: Path, name: str) -> None:
    cases = [SUITE["bad-resp-2d-nan-radius"], SUITE["bad-resp-2d-nan-radius.swapped"]]
    store = ResultsStore(tmp_path / name)
    run(cases, [adapters.get(name)], store, RunOptions(quick=True))
    store.close()
    frame = read_results(tmp_path / name)
    assert len(frame) == 4 and not set(frame["status"]) & {"crash", "error"}


@BOTH
def test_separating_overlap_is_left_alone(adapter: Any) -> None:
    # The impulse accumulator is clamped at 0 (jnAcc = max(old + jn, 0)).
    assert adapter.conventions.resolves_separating is False
    obs = observe(response([0.0, 0.0], [-1.0, 0.0], [0.5, 0.0], [1.0, 0.0]), adapter)
    assert (obs.v1, obs.v2) == ((-1.0, 0.0), (1.0, 0.0))
    assert obs.resolved_at is not None


@BOTH
def test_no_restitution_threshold_for_a_slow_approach(adapter: Any) -> None:
    # bounce = vrn * e with no threshold: an approach at 2^-20 still bounces elastically.
    assert adapter.conventions.restitution_threshold == 0.0
    obs = observe(response([0.0, 0.0], [2.0**-20, 0.0], [1.0, 0.0], [0.0, 0.0]), adapter)
    assert obs.v1 == (0.0, 0.0) and obs.v2 == (2.0**-20, 0.0)


@BOTH
def test_grazing_contact_is_missed_in_discrete_time(adapter: Any) -> None:
    # Normal approach 2^-10 against tangential speed 2: the discs never overlap at a step.
    case = response([0.0, 0.0], [2.0**-10, 1.0], [1.0, 0.0], [0.0, -1.0])
    obs = observe(case, adapter)
    assert (obs.v1, obs.v2, obs.resolved_at) == ((2.0**-10, 1.0), (0.0, -1.0), None)


@BOTH
@pytest.mark.parametrize("case", [
    aabb([0.0, 0.0], [1.0, 1.0], [1.5, 0.5], [1.0, 1.0]),
    sphere(0.0, 3.0, dim=2),
    response([0.0, 0.0], [1.0, 0.5], [0.8, 0.6], [-1.0, 0.0], mb=3.0),
    response([0.0, 0.0], [1.0, 0.0], [0.25, 0.0], [-1.0, 0.0]),  # deep: bias velocities
], ids=["boxes", "circles", "oblique", "deep-overlap"])
def test_query_is_repeatable(adapter: Any, case: AnyCase) -> None:
    fresh = observe(case, adapter)
    prepared = adapter.prepare(case)
    assert adapter.query(prepared) == adapter.query(prepared) == adapter.query(prepared) == fresh
    adapter.release(prepared)


def test_variant_settings_reach_the_space() -> None:
    case = response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0])
    tuned, default = TUNED.prepare(case).built["space"], DEFAULT.prepare(case).built["space"]
    assert (tuned.collision_slop, tuned.collision_bias, tuned.iterations) == (0.0, 1.0, 10)
    # Munk2D's defaults are float32 literals: slop 0.1f, bias pow(1.0f - 0.1f, 60).
    assert (default.collision_slop, default.iterations) == (f32(0.1), 10)
    assert default.collision_bias == f32(0.9) ** 60
    assert (tuned.gravity, tuned.damping, default.damping) == ((0.0, 0.0), 1.0, 1.0)
    assert (TUNED.dt, DEFAULT.dt) == (1e-3, 1.0 / 60.0)


# --- capabilities, registry -------------------------------------------------------------------

@BOTH
@pytest.mark.parametrize("case", [
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
    sphere(0.0, 1.0, dim=3),
    response([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
], ids=["aabb", "sphere", "response"])
def test_3d_cases_are_unsupported_as_2d_engine(adapter: Any, case: AnyCase) -> None:
    reason = adapter.unsupported(case)
    assert reason is not None and "2-D engine" in reason
    flat = {"aabb": aabb([0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [1.0, 1.0]),
            "sphere": sphere(0.0, 1.0, dim=2),
            "sphere_response": response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0])}
    assert adapter.unsupported(flat[case.kind]) is None


def test_unavailable_under_python_O_where_the_no_contact_assert_is_stripped() -> None:
    code = "import adapters; print(adapters.get('pymunk').available())"
    out = subprocess.run([sys.executable, "-O", "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout
    assert "python -O" in out


def test_registry_and_version() -> None:
    assert isinstance(adapters.get("pymunk"), PymunkTuned)
    assert type(adapters.get("pymunk-default")) is PymunkDefault
    assert TUNED.engine == DEFAULT.engine == "pymunk"
    assert TUNED.available() is None
    assert TUNED.version().startswith("7.3.1")
    assert TUNED.conventions.box_extents.startswith("full")
    assert TUNED.conventions.margins == DEFAULT.conventions.margins == {}
