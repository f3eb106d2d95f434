"""The fcl adapter: pinned native behaviour of FCL 0.7.0 (python-fcl 0.7.0.11) and the translation.

These tests check the translation, not FCL's correctness: each pins what the engine was
measured to do, with the engine fact named.  Nothing here runs the signed distance of
coincident spheres in-process (it hangs: flexible-collision-library/fcl#346) or any NaN/inf
input (it crashes).
"""

from __future__ import annotations

import subprocess
import sys
from typing import Any

import pytest

fcl = pytest.importorskip("fcl")

import adapters  # noqa: E402
from adapters.fcl import Fcl, z_half  # noqa: E402
from adapters.fcl.ccd import CONTINUOUS  # noqa: E402
from crosscheck.cases.load import load_paths  # noqa: E402
from crosscheck.core.model import Category, Observation, Status  # noqa: E402
from crosscheck.core.schema import CASE_ADAPTER, AabbCase, AnyCase, ToiCase  # noqa: E402
from crosscheck.truth import oracle  # noqa: E402
from crosscheck.truth.score import judge  # noqa: E402
from tests.conftest import ROOT, aabb, response, sphere  # noqa: E402

pytestmark = pytest.mark.engine

FCL = Fcl()


def ball(ca: list[float], ra: float, cb: list[float], rb: float) -> AnyCase:
    """A sphere case (2-D or 3-D) with centres anywhere."""
    return CASE_ADAPTER.validate_python({
        "id": "d", "description": "d", "kind": "sphere", "dim": len(ca),
        "a": {"center": ca, "radius": ra}, "b": {"center": cb, "radius": rb}})


def observe(case: AnyCase) -> Observation:
    return FCL.observe(case)


def collide(a: Any, b: Any, enable_contact: bool) -> Any:
    """FCL's own collide on two objects, as the adapter does not call it."""
    result = fcl.CollisionResult()
    fcl.collide(a, b, fcl.CollisionRequest(enable_contact=enable_contact), result)
    return result


# --- native behaviour (conformance) ----------------------------------------------------------

def test_face_touching_boxes_collide_at_distance_zero() -> None:
    # boxBox2 separates only on s2 > 0: a face touch is a collision with one contact.
    obs = observe(aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 0.0, 0.0], [1.0, 1.0, 1.0]))
    assert obs == Observation(hit=True, distance=0.0, normal=(1.0, 0.0, 0.0))


def test_edge_touching_boxes_do_not_collide_and_give_no_direction() -> None:
    # boxBox2 clips no contact point; with enable_contact no Contact, so no collision.
    # The signed distance is -0.0 with coincident nearest points: no direction.
    obs = observe(aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0], [1.0, 1.0, 1.0]))
    assert obs == Observation(hit=False, distance=0.0, normal=None)


def test_corner_touching_boxes_do_not_collide_and_give_no_direction() -> None:
    obs = observe(aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [1.0, 1.0, 1.0]))
    assert obs == Observation(hit=False, distance=0.0, normal=None)


def test_edge_touching_boxes_collide_without_enable_contact() -> None:
    # The engine fact behind the two tests above: the verdict depends on enable_contact.
    a = fcl.CollisionObject(fcl.Box(2.0, 2.0, 2.0), fcl.Transform([0.0, 0.0, 0.0]))
    b = fcl.CollisionObject(fcl.Box(2.0, 2.0, 2.0), fcl.Transform([2.0, 2.0, 0.0]))
    assert collide(a, b, enable_contact=False).is_collision
    assert not collide(a, b, enable_contact=True).is_collision


def test_touching_spheres_on_an_axis_collide_at_distance_zero() -> None:
    # sphereSphereIntersect rejects only len > r1 + r2: touching is a collision.
    obs = observe(sphere(0.0, 1.0))
    assert obs == Observation(hit=True, distance=0.0, normal=(1.0, 0.0, 0.0))


def test_touching_spheres_on_a_345_diagonal_collide_with_a_gjk_distance() -> None:
    # Analytic verdict and normal; the signed distance is GJK on the spheres' support
    # functions (flexible-collision-library/fcl#345), 3.0e-8 off, within the declared 1e-6.
    obs = observe(ball([0.0, 0.0, 0.0], 2.5, [3.0, 4.0, 0.0], 2.5))
    assert (obs.hit, obs.normal) == (True, (0.6, 0.8, 0.0))
    assert isinstance(obs.distance, float)
    assert obs.distance == pytest.approx(3.035569508407856e-08, rel=1e-6)
    assert 0.0 < obs.distance < FCL.conventions.margin_for("sphere")


def test_overlapping_spheres_signed_distance_is_approximate() -> None:
    # EPA on spheres: a 0.5 overlap reads -0.49999958 (x-aligned centres).
    obs = observe(sphere(0.0, 0.5))
    assert isinstance(obs.distance, float)
    assert obs.distance == pytest.approx(-0.4999995778357785, abs=1e-15)


def test_coincident_boxes_collide_with_normal_x() -> None:
    # boxBox2 on a tie of least overlap keeps the first axis tested, x.
    obs = observe(aabb([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [1.0, 2.0, 3.0], [1.0, 1.0, 1.0]))
    assert obs == Observation(hit=True, distance=-2.0, normal=(1.0, 0.0, 0.0))


def test_coincident_spheres_collide_with_a_zero_normal() -> None:
    # sphereSphereIntersect in 0.7.0 normalises the zero centre difference: (0, 0, 0).
    a = fcl.CollisionObject(fcl.Sphere(1.0), fcl.Transform([1.0, -2.0, 3.0]))
    b = fcl.CollisionObject(fcl.Sphere(0.5), fcl.Transform([1.0, -2.0, 3.0]))
    result = collide(a, b, enable_contact=True)
    assert result.is_collision
    assert result.contacts[0].normal.tolist() == [0.0, 0.0, 0.0]
    assert result.contacts[0].penetration_depth == 1.5


def test_coincident_zero_radius_spheres_touch_with_a_zero_normal() -> None:
    # Two points: the signed distance returns -0.0 (no hang for radius 0).
    obs = observe(ball([1.0, 1.0], 0.0, [1.0, 1.0], 0.0))
    assert obs == Observation(hit=True, distance=0.0, normal=(0.0, 0.0))


def test_coincident_spheres_hang_the_signed_distance() -> None:
    # flexible-collision-library/fcl#346: EPA never ends for coincident centres.  In a
    # subprocess, killed.
    code = ("import fcl\n"
            "a = fcl.CollisionObject(fcl.Sphere(1.0), fcl.Transform([0.0, 0.0, 0.0]))\n"
            "b = fcl.CollisionObject(fcl.Sphere(0.5), fcl.Transform([0.0, 0.0, 0.0]))\n"
            "fcl.distance(a, b, fcl.DistanceRequest(True, True), fcl.DistanceResult())\n")
    with pytest.raises(subprocess.TimeoutExpired):
        subprocess.run([sys.executable, "-c", code], timeout=4, capture_output=True)


def test_only_the_distance_of_coincident_spheres_is_declared_hanging() -> None:
    # collide answers at once (above); so the adapter can answer without the distance.
    case = sphere(0.0, 0.0, ra=1.0, rb=0.5)
    assert FCL.known_hang(case) is not None
    assert FCL.hanging_quantities(case) == frozenset({"distance"})
    assert FCL.hanging_quantities(sphere(0.0, 0.5)) == frozenset()
    prepared = FCL.prepare(case)
    obs = FCL.query_without(prepared, frozenset({"distance"}))
    FCL.release(prepared)
    assert obs == Observation(hit=oracle.truth(case).hit, distance=None, normal=(0.0, 0.0, 0.0))


@pytest.mark.parametrize("case", [
    sphere(0.0, 0.75), sphere(0.0, 3.0), sphere(0.0, 1.0, dim=2),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 0.5, 0.0], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0], [1.0, 1.0], [3.0, 0.0], [1.0, 1.0]),
], ids=["overlap", "apart", "touching-2d", "boxes", "boxes-apart-2d"])
def test_query_without_the_distance_is_the_query_less_the_distance(case: AnyCase) -> None:
    # The verdict is collide's in both; the normal is the contact's when they collide and
    # absent otherwise (it came from the nearest points of the distance call).
    full = observe(case)
    prepared = FCL.prepare(case)
    try:
        part = FCL.query_without(prepared, frozenset({"distance"}))
        assert FCL.query_without(prepared, frozenset()) == full
    finally:
        FCL.release(prepared)
    assert (part.hit, part.distance) == (full.hit, None)
    assert part.normal == (full.normal if full.hit else None)


# --- translation -------------------------------------------------------------------------

def test_half_widths_become_full_side_lengths() -> None:
    # Half-widths 1 apart by 2.5: gap 0.5 (passing half-widths as sides would read 1.5).
    obs = observe(aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.5, 0.0, 0.0], [1.0, 1.0, 1.0]))
    assert obs == Observation(hit=False, distance=0.5, normal=(1.0, 0.0, 0.0))


@pytest.mark.parametrize("cb, want", [
    ([-1.5, 0.0, 0.0], Observation(hit=True, distance=-0.5, normal=(-1.0, 0.0, 0.0))),
    ([-2.5, 0.0, 0.0], Observation(hit=False, distance=0.5, normal=(-1.0, 0.0, 0.0))),
    ([0.0, 0.0, 2.5], Observation(hit=False, distance=0.5, normal=(0.0, 0.0, 1.0))),
], ids=["overlap", "gap", "gap-z"])
def test_box_normal_points_from_a_to_b_and_distance_is_signed(
        cb: list[float], want: Observation) -> None:
    assert observe(aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], cb, [1.0, 1.0, 1.0])) == want


def test_sphere_normal_points_from_a_to_b_in_contact_and_apart() -> None:
    inside, apart = observe(sphere(0.0, -0.5)), observe(sphere(0.0, -2.0))
    assert (inside.hit, inside.normal) == (True, (-1.0, 0.0, 0.0))
    assert isinstance(inside.distance, float) and inside.distance < 0
    assert apart == Observation(hit=False, distance=1.0, normal=(-1.0, 0.0, 0.0))


def test_2d_boxes_get_a_z_extent_that_is_never_least_overlap() -> None:
    case = aabb([0.0, 0.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0])
    assert isinstance(case, AabbCase)
    assert z_half(case) == 2.0  # z overlap 4 > x and y overlaps 2
    assert observe(case) == Observation(hit=True, distance=-2.0, normal=(1.0, 0.0))


def test_2d_zero_size_boxes_get_z_half_width_one() -> None:
    case = aabb([3.0, 4.0], [0.0, 0.0], [3.0, 4.0], [0.0, 0.0])
    assert isinstance(case, AabbCase) and z_half(case) == 1.0


def test_2d_answers_are_2d() -> None:
    # A corner touch in 2-D is an edge touch in 3-D: no collision, as in 3-D.
    assert observe(aabb([0.0, 0.0], [1.0, 1.0], [0.0, 3.0], [1.0, 1.0])) == Observation(
        hit=False, distance=1.0, normal=(0.0, 1.0))
    assert observe(aabb([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [1.0, 1.0])).hit is False
    disc = observe(ball([0.0, 0.0], 2.5, [3.0, 4.0], 2.5))
    assert (disc.hit, disc.normal) == (True, (0.6, 0.8))


@pytest.mark.parametrize("case", [
    sphere(0.0, 0.7, dim=2), sphere(0.0, 3.0),
    ball([0.0, 0.0, 0.0], 1.0, [0.0, 0.0, 3.0], 1.0),
    aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 0.5, -0.25], [1.0, 1.0, 1.0]),
    aabb([0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [1.0, 1.0]),
], ids=["disc-overlap", "sphere-gap", "sphere-gap-z", "box-overlap", "box-corner-2d"])
def test_query_is_repeatable(case: AnyCase) -> None:
    prepared = FCL.prepare(case)
    first, second = FCL.query(prepared), FCL.query(prepared)
    FCL.release(prepared)
    assert first == second


def test_responses_are_unsupported_and_detection_is_supported() -> None:
    reason = FCL.unsupported(response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0]))
    assert reason is not None and "no dynamics" in reason
    for dim in (2, 3):
        assert FCL.unsupported(sphere(0.0, 1.0, dim=dim)) is None
        assert FCL.unsupported(aabb([0.0] * dim, [1.0] * dim, [1.0] * dim, [1.0] * dim)) is None


def test_registry_availability_and_declarations() -> None:
    assert isinstance(adapters.get("fcl"), Fcl)
    assert FCL.available() is None
    assert FCL.version() == "0.7.0.11"
    conv = FCL.conventions
    assert conv.box_extents.startswith("full")
    assert conv.touching_is_contact("sphere") and conv.touching_is_contact("face")
    assert not conv.touching_is_contact("edge") and not conv.touching_is_contact("corner")
    assert set(conv.margins.values()) == {1e-6} and len(conv.margins) == 4
    # No dynamics: no time step, damping or masses; negative sizes read literally.
    assert (conv.time_step, conv.damping, conv.zero_mass, conv.negative_extents) == (
        None, 0.0, "", "")


def test_touching_spheres_are_a_convention_disagreement() -> None:
    # The declared rule (touching is contact) is what categorises this disagreement.
    case = sphere(0.0, 1.0)
    verdict = judge(case, FCL.conventions, "hit", observe(case).hit, oracle.truth(case))
    assert (verdict.status, verdict.category) == (Status.DISAGREE, Category.CONVENTION)


@pytest.mark.parametrize("name", ["fcl-ccd-ray-shooting", "fcl-ccd-polynomial"])
def test_solvers_fcl_does_not_compute_for_spheres_skip_every_toi_case_citing_fcl(
        name: str) -> None:
    adapter = adapters.adapter_class(name)()
    assert not adapter.capabilities  # supports no case: none is asked, none scored wrong
    cases = [c for c in load_paths([ROOT / "cases" / "toi.toml"]).cases
             if isinstance(c, ToiCase)]
    assert cases
    for case in cases:
        reason = adapter.unsupported(case)
        assert reason is not None and reason.startswith(name) and CONTINUOUS in reason
    # the naive solver is computed: it is not skipped
    assert adapters.adapter_class("fcl-ccd-naive")().unsupported(cases[0]) is None
