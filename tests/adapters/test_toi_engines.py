"""Times of impact (``sphere_toi``) on FCL (and its CCD variants), Box2D and Rapier.

Every expected value comes from the exact oracle (:func:`crosscheck.truth.toi.truth`, i.e.
``reference_impl.toi``) and the declared conventions, through the harness's own judge.
"""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from adapters.box2d import Box2dDefault, Box2dTuned
from adapters.fcl import Fcl, FclCcdNaive, FclCcdPolynomial, FclCcdRayShooting
from adapters.rapier import RapierDefault, RapierTuned
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Category, Kind, Status, Undefined
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import ToiCase
from crosscheck.run.execute import execute
from crosscheck.truth import toi
from crosscheck.truth.score import judge

C = 1.0123456789


def case(dim: int, ca: tuple[float, ...] = (-C, 0.0, 0.0), va: tuple[float, ...] = (1.0, 0.0, 0.0),
         cb: tuple[float, ...] = (C, 0.0, 0.0), vb: tuple[float, ...] = (-1.0, 0.0, 0.0),
         radius: float = 0.05, duration: float = 1.0) -> ToiCase:
    return ToiCase(id="toi", kind="sphere_toi", description="two spheres in linear motion",
                   dim=dim, duration=duration,
                   a={"center": list(ca[:dim]), "radius": radius, "velocity": list(va[:dim])},
                   b={"center": list(cb[:dim]), "radius": radius, "velocity": list(vb[:dim])})


HEAD_ON = (case(2), case(3))
FAST = case(3, ca=(-1.0, 0.0, 0.0), va=(2.0, 0.0, 0.0), cb=(1.0, 0.0, 0.0), vb=(-2.0, 0.0, 0.0))
"""Contact at t = 0.475, over by 0.525: between the naive solver's samples 4/9 and 5/9."""
MISS = case(3, ca=(-1.0, 0.5, 0.0), cb=(1.0, 0.0, 0.0))
"""The paths pass 0.5 apart: no contact."""


def verdicts(adapter: Adapter, c: ToiCase) -> dict[str, tuple[Status, str]]:
    truth = toi.truth(c)
    observed = adapter.observe(c)
    out = {}
    for q in ("hit", "toi", "normal"):
        v = judge(c, adapter.conventions, q, observed.get(q), truth, observed)
        out[q] = (v.status, v.category)
    return out


@pytest.mark.parametrize("adapter", [Fcl(), FclCcdNaive(), Box2dTuned(), Box2dDefault(),
                                     RapierTuned(), RapierDefault()], ids=lambda a: a.name)
def test_capabilities(adapter: Adapter) -> None:
    dims = {d for k, d in adapter.capabilities if k is Kind.SPHERE_TOI}
    assert dims == ({2} if isinstance(adapter, Box2dTuned) else {2, 3})
    assert adapter.unsupported(case(2)) is None
    assert adapter.conventions.sources


@pytest.mark.parametrize("c", HEAD_ON, ids=["2d", "3d"])
def test_fcl_conservative_advancement_is_exact_head_on(c: ToiCase) -> None:
    truth = toi.truth(c)
    observed = Fcl().observe(c)
    assert observed.hit is True
    assert isinstance(observed.toi, float) and isinstance(truth.toi, float)
    assert abs(observed.toi - truth.toi) <= toi.bound(c, "toi", truth)
    assert observed.normal == truth.normal
    assert all(s is Status.AGREE for s, _ in verdicts(Fcl(), c).values())


def test_fcl_reports_no_contact_for_a_miss() -> None:
    assert toi.truth(MISS).hit is False
    observed = Fcl().observe(MISS)
    assert observed.hit is False
    assert isinstance(observed.toi, Undefined) and isinstance(observed.normal, Undefined)
    assert verdicts(Fcl(), MISS)["hit"] == (Status.AGREE, "")


def test_fcl_naive_misses_a_contact_between_its_samples() -> None:
    truth = toi.truth(FAST)
    assert truth.hit is True and isinstance(truth.toi, float)
    assert 4 / 9 < truth.toi < 5 / 9  # between two of its ten samples
    assert Fcl().observe(FAST).hit is True
    assert FclCcdNaive().observe(FAST).hit is False
    # declared toi_samples 10: a contact between its samples is a timestep miss, not an error
    assert verdicts(FclCcdNaive(), FAST)["hit"] == (Status.DISAGREE, Category.TIMESTEP)


def test_fcl_naive_reports_the_first_sample_in_collision() -> None:
    c = HEAD_ON[1]
    observed = FclCcdNaive().observe(c)
    truth = toi.truth(c)
    assert isinstance(truth.toi, float)
    first = min(i / 9 for i in range(10) if i / 9 >= truth.toi)
    assert observed.hit is True and observed.toi == first * c.duration


def test_fcl_naive_reports_its_sample_as_the_judge_counts_it_on_a_long_interval() -> None:
    """On T = 1e6 the naive solver's sample 5, ``(5 / 9) T``, is an ulp above ``T * 5 / 9``:
    the judge's samples are the engine's own, so its first overlapping sample is timestep."""
    c = case(3, ca=(-1.0, 0.0, 0.0), va=(1e-6, 0.0, 0.0), cb=(1.0, 0.0, 0.0),
             vb=(-1e-6, 0.0, 0.0), radius=0.5, duration=1e6)
    truth = toi.truth(c)
    assert isinstance(truth.toi, float) and 4 / 9 < truth.toi / c.duration < 5 / 9
    observed = FclCcdNaive().observe(c)
    assert observed.toi in toi.sample_times(c, FclCcdNaive.conventions)
    assert verdicts(FclCcdNaive(), c)["toi"] == (Status.DISAGREE, Category.TIMESTEP)


def test_fcl_naive_gives_no_normal_where_its_sample_has_the_centres_coincide() -> None:
    """Speed 1 over [0, 1] from 2 apart: the sample t = 1 finds the centres on each other, so
    the normal computed from them has no value: the declared no-value rule says so."""
    c = case(3, ca=(-1.0, 0.0, 0.0), cb=(1.0, 0.0, 0.0))
    observed = FclCcdNaive().observe(c)
    assert observed.hit is True and observed.toi == 1.0
    assert isinstance(observed.normal, Undefined)
    truth = toi.truth(c)
    verdict = judge(c, FclCcdNaive.conventions, "normal", observed.normal, truth, observed)
    assert verdict.category == Category.CONVENTION and "float64-centre-line" in verdict.reason
    bare = replace(FclCcdNaive.conventions, no_value=())
    assert judge(c, bare, "normal", observed.normal, truth, observed).category == Category.ERROR


@pytest.mark.parametrize("adapter", [FclCcdRayShooting(), FclCcdPolynomial()],
                         ids=lambda a: a.name)
def test_fcl_solvers_that_do_not_compute_spheres_skip_every_case(adapter: Adapter) -> None:
    """FCL returns -1, "not computed", for these solvers on two spheres: the variants
    declare no capability, and a run skips every case with FCL's source as the reason."""
    seen = adapter.observe(HEAD_ON[1])  # asked anyway, FCL does not compute it
    assert isinstance(seen.hit, Undefined) and "returned -1" in seen.hit.reason
    assert not adapter.capabilities
    for c in (*HEAD_ON, MISS):
        outcome = execute(adapter, c, RunOptions())
        assert outcome.status is Status.SKIP and outcome.observation is None
        assert "continuous_collision-inl.h" in outcome.reason and "-1" in outcome.reason


@pytest.mark.parametrize("adapter", [Box2dTuned(), Box2dDefault()], ids=lambda a: a.name)
def test_box2d_stops_at_its_declared_target(adapter: Adapter) -> None:
    c = HEAD_ON[0]
    observed = adapter.observe(c)
    assert observed.hit is True and isinstance(observed.toi, float)
    motion = toi.Motion.of(c)
    conv = adapter.conventions
    assert abs(motion.gap(observed.toi) - conv.toi_target) <= conv.toi_tolerance + 1e-6
    got = verdicts(adapter, c)
    assert got["hit"] == (Status.AGREE, "")
    assert got["toi"] == (Status.DISAGREE, Category.CONVENTION)
    assert got["normal"][0] is Status.AGREE


def test_box2d_duration_maps_onto_its_unit_sweep() -> None:
    """The same motion over [0, 2] with half the speeds: twice the time."""
    slow = case(2, va=(0.5, 0.0), vb=(-0.5, 0.0), duration=2.0)
    a, b = Box2dTuned().observe(HEAD_ON[0]), Box2dTuned().observe(slow)
    assert isinstance(a.toi, float) and isinstance(b.toi, float)
    assert b.toi == pytest.approx(2.0 * a.toi, rel=1e-6)


@pytest.mark.parametrize("adapter", [Box2dTuned(), RapierTuned()], ids=lambda a: a.name)
def test_no_contact(adapter: Adapter) -> None:
    c = case(2, ca=(-1.0, 0.5), va=(1.0, 0.0), cb=(1.0, 0.0), vb=(-1.0, 0.0))
    assert toi.truth(c).hit is False
    assert adapter.observe(c).hit is False
    assert verdicts(adapter, c)["hit"] == (Status.AGREE, "")


@pytest.mark.parametrize("c", [*HEAD_ON, FAST], ids=["2d", "3d", "fast"])
@pytest.mark.parametrize("adapter", [RapierTuned(), RapierDefault()], ids=lambda a: a.name)
def test_rapier_within_float32_of_touching(adapter: Adapter, c: ToiCase) -> None:
    observed = adapter.observe(c)
    truth = toi.truth(c)
    assert observed.hit is True and isinstance(observed.toi, float)
    assert isinstance(truth.toi, float)
    assert abs(observed.toi - truth.toi) <= 2.0**-20 * (1.0 + truth.toi)
    got = verdicts(adapter, c)
    assert got["hit"] == (Status.AGREE, "")
    assert got["toi"][0] is Status.AGREE or got["toi"] == (Status.DISAGREE, Category.TOLERANCE)
    assert isinstance(observed.normal, tuple) and len(observed.normal) == c.dim
    assert math.isclose(observed.normal[0], 1.0, rel_tol=1e-4)
    # parry's d / R is not renormalised: a float32 length, judged by its direction
    assert got["normal"][0] is Status.AGREE or got["normal"] == (Status.DISAGREE,
                                                                Category.TOLERANCE)


def test_overlapping_at_the_start_is_contact_at_zero() -> None:
    c = case(3, ca=(0.0, 0.0, 0.0), cb=(0.05, 0.0, 0.0))
    assert toi.truth(c).toi == 0.0
    for adapter in (Fcl(), RapierTuned()):
        observed = adapter.observe(c)
        assert observed.hit is True and observed.toi == 0.0


@pytest.mark.parametrize("adapter", [Fcl(), Box2dTuned(), RapierTuned()], ids=lambda a: a.name)
def test_refuses_non_finite_input(adapter: Adapter) -> None:
    c = case(2, va=(math.nan, 0.0))
    with pytest.raises(ValueError, match="non-finite"):
        adapter.prepare(c)


@pytest.mark.parametrize("adapter", [Fcl(), Box2dTuned(), RapierTuned()], ids=lambda a: a.name)
def test_query_is_repeatable(adapter: Adapter) -> None:
    prepared = adapter.prepare(HEAD_ON[0])
    assert adapter.query(prepared) == adapter.query(prepared)
