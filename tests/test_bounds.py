"""``agree`` means as right as float64 allows: the float64 textbook formula stays within the
bound of :mod:`crosscheck.truth.bounds` on every case, except verdicts that flip at touching."""

from __future__ import annotations

import math

import pytest

from crosscheck.cases.load import load_paths
from crosscheck.core.model import Kind, Undefined, quantities_of
from crosscheck.core.schema import AabbCase, PairCase, SceneCase
from crosscheck.studies.fuzzgen import generate
from crosscheck.truth import oracle
from crosscheck.truth.bounds import U, bound, error_of
from tests.conftest import ROOT, aabb, sphere

SUITE = [c for c in load_paths([ROOT / "cases"]).cases
         if not isinstance(c, SceneCase) and not c.bad_input]
FUZZED = [g.case for kind in (Kind.AABB, Kind.SPHERE, Kind.SPHERE_RESPONSE)
          for g in generate(kind, 1500, 7)]


def _misses(cases: list[PairCase]) -> list[str]:
    """Every quantity where the float64 textbook answer is beyond the bound, but hit flips
    at touching (|true gap| within the distance bound)."""
    out = []
    for case in cases:
        truth, f64 = oracle.truth(case), oracle.textbook(case, "f64")
        gap = truth.distance if isinstance(truth.distance, float) else math.nan
        for quantity in quantities_of(case.kind_enum):
            want, got = truth.get(quantity), f64.get(quantity)
            if isinstance(want, Undefined) or isinstance(got, Undefined) or want is None:
                continue
            assert got is not None
            err = error_of(quantity, got, want)
            if quantity == "hit" and abs(gap) <= bound(case, "distance"):
                continue  # the verdict at touching: decided by rounding, as the README says
            limit = bound(case, quantity, gap)
            if not err <= limit:
                out.append(f"{case.id} {quantity}: error {err:.3g} > {limit:.3g}")
    return out


def test_the_float64_formula_agrees_on_the_whole_suite() -> None:
    assert len(SUITE) > 600
    assert _misses(SUITE) == []


def test_the_float64_formula_agrees_on_random_cases_near_failure_boundaries() -> None:
    assert _misses(FUZZED) == []


def test_the_bound_is_a_few_ulps_of_what_the_formula_combines() -> None:
    mixed = aabb([0.0, 0.0], [1e9, 1e-9], [0.0, 1e-9], [1e9, 1e-9])  # the mixed scale
    assert bound(mixed, "distance") < 1e-20  # PyBullet's -0.001 against -1e-9 cannot agree
    far = sphere(1e10, 1e10 + 1.001)  # f32's -1 against +0.001 cannot agree either
    assert bound(far, "distance") < 1e-12
    assert bound(sphere(0.0, 3.0), "distance") == pytest.approx(8 * U * 4.0)
    assert isinstance(mixed, AabbCase) and bound(mixed, "hit") == 0.0
