"""The batch values (reference_impl.batch_values, batch_response) against the pure oracle.

Every value is compared bit for bit (signed zeros included) with
:mod:`reference_impl.exact`; the stage counters show which path settled each pair.
"""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from crosscheck.cases.load import load_paths
from crosscheck.truth import oracle
from reference_impl import batch_response, batch_values, ddouble, exact
from reference_impl.batch import near_pairs
from reference_impl.types import Response
from tests.conftest import ROOT


def bits(values: list[float]) -> list[int]:
    return np.asarray(values, dtype=np.float64).view(np.int64).tolist()


def assert_spheres(x: tuple[np.ndarray, ...]) -> batch_values.SphereValues:
    """Batch sphere values equal the oracle for every pair; returns them for the stages."""
    x = tuple(np.asarray(v, dtype=np.float64) for v in x)
    v = batch_values.sphere_values(*x)
    wrong = [i for i in range(len(x[0])) if not batch_values.same_as_oracle(v, x, i)]
    assert wrong == [], [tuple(c[i].tolist() for c in x) for c in [x] for i in wrong[:3]]
    assert sum(v.stages.values()) == len(x[0])
    return v


def assert_responses(*x: np.ndarray) -> batch_response.ResponseValues:
    x = tuple(np.asarray(v, dtype=np.float64) for v in x)
    r = batch_response.response_values(*x)
    for i in range(len(x[0])):
        pa, ma, va, pb, mb, vb, e = (v[i].tolist() for v in x)
        want = exact.sphere_response(pa, ma, va, pb, mb, vb, e)
        if isinstance(want, Response):
            assert bits([*r.v1[i], *r.v2[i]]) == bits([float(c) for c in (*want.v1, *want.v2)])
        else:
            assert r.undefined[i]
    assert sum(r.stages.values()) == len(x[0])
    return r


@pytest.mark.parametrize("module", [ddouble, batch_values, batch_response])
def test_doctests(module: object) -> None:
    assert doctest.testmod(module).failed == 0  # type: ignore[arg-type]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize(("scale", "offset"), [
    (1.0, 0.0), (1.0, 1e15), (1e-300, 0.0), (1e-150, 0.0), (1e-9, 0.0), (1e-9, 1e6),
    (1e100, 0.0), (1e300, 0.0), (2.0**-500, 0.0)])
def test_near_touching_at_every_scale(dim: int, scale: float, offset: float) -> None:
    rng = np.random.default_rng(int(dim * 1000 + math.log2(scale) + offset % 997))
    v = assert_spheres(near_pairs("sphere", 300, dim, rng, scale=scale, offset=offset))
    if scale == 1.0 and offset == 0.0:
        assert v.stages["numerator"] > 250  # near touching: the distance cancels in stage 1


@pytest.mark.parametrize("dim", [2, 3])
def test_random_pairs_settle_in_double_double(dim: int) -> None:
    rng = np.random.default_rng(dim)
    a = rng.uniform(-10, 10, (3000, dim))
    x = (a, rng.uniform(0.1, 5, 3000), a + rng.uniform(-15, 15, (3000, dim)),
         rng.uniform(0.1, 5, 3000))
    v = assert_spheres(x)
    assert v.stages["double_double"] >= 2990


def test_exact_ties_and_integer_distances() -> None:
    """3-4-5 triangles (exact sqrt), exact touching, and a distance exactly on a midpoint."""
    tie = 2.0**-54  # |d| = 1, r = 2**-54: D = 1 - 2**-54, halfway between two doubles
    x = ([[0, 0, 0], [0, 0, 0], [1, 2, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]],
         [1.0, 2.0, 1.5, tie, 0.0, 0.5],
         [[3, 4, 0], [3, 4, 0], [4, 6, 12], [1, 0, 0], [0, 3, 4], [0, 0, 5]],
         [1.5, 3.0, 0.25, 0.0, 2.0**-51, 4.5])  # 5 - 2**-51: also a midpoint
    v = assert_spheres(x)
    assert v.distance.tolist() == [2.5, 0.0, 11.25, 1.0, 5.0, 0.0]
    assert v.stages["exact"] >= 2  # the midpoints cannot be certified: the fallback runs
    assert v.stages["numerator"] >= 1  # exact touching: q == r**2 found by the exact sign


@pytest.mark.parametrize("k", [-1000, -600, -60, 0, 60, 600, 1000])
def test_power_of_two_scaled_triangles(k: int) -> None:
    s = 2.0**k
    x = ([[0.0, 0.0], [s, -s]], [s, 2 * s], [[3 * s, 4 * s], [4 * s, 3 * s]], [1.5 * s, 2 * s])
    v = assert_spheres(x)
    assert bits(v.distance.tolist()) == bits([2.5 * s, 1.0 * s])


def test_subnormals_signed_zeros_and_coincident_centres() -> None:
    tiny = 5e-324
    x = ([[0.0, 0.0], [-0.0, 0.0], [0.0, -0.0], [1.0, 2.0], [tiny, 0.0], [0.0, -0.0]],
         [tiny, 0.0, -0.0, 1.0, 0.0, 1.0],
         [[3 * tiny, 4 * tiny], [0.0, -0.0], [-0.0, 0.0], [1.0, 2.0], [0.0, 3.0], [-0.0, 5.0]],
         [tiny, -0.0, -0.0, -1.0, 2 * tiny, 1.0])
    v = assert_spheres(x)
    assert v.coincident.tolist() == [False, True, True, True, False, False]
    assert bits(v.distance[1:4].tolist()) == bits([0.0, 0.0, 0.0])  # 0.0 - fl(ra + rb)
    assert bits(v.normal[5].tolist()) == bits([0.0, 1.0])  # +0.0, not -0.0
    assert v.stages["coincident"] == 3


def test_non_finite_inputs_fall_back() -> None:
    inf, nan = math.inf, math.nan
    x = ([[inf, 0.0], [0.0, 0.0], [0.0, 0.0], [1e308, 0.0]], [1.0, nan, 1.0, 1.0],
         [[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1e308, 0.0]], [1.0, 1.0, inf, 1.0])
    v = assert_spheres(x)
    assert v.undefined.tolist() == [True, True, True, False]
    assert v.distance[3] == math.inf and v.stages["exact"] == 4


finite = st.floats(allow_nan=False, allow_infinity=False)
coords = st.one_of(finite, st.floats(-100, 100), st.sampled_from([0.0, -0.0, 1.0, 3.0, 4.0]))


@settings(max_examples=300, deadline=None)
@given(st.integers(2, 3), st.data())
def test_hypothesis_pairs(dim: int, data: st.DataObject) -> None:
    vec = st.lists(coords, min_size=dim, max_size=dim)
    x = ([data.draw(vec)], [data.draw(coords)], [data.draw(vec)], [data.draw(coords)])
    assert_spheres(x)


@settings(max_examples=200, deadline=None)
@given(st.integers(2, 3), st.data())
def test_hypothesis_near_touching(dim: int, data: st.DataObject) -> None:
    seed = data.draw(st.integers(0, 2**32 - 1))
    scale = 2.0 ** data.draw(st.integers(-600, 600))
    assert_spheres(near_pairs("sphere", 20, dim, np.random.default_rng(seed), scale=scale))


@pytest.mark.parametrize("dim", [2, 3])
def test_responses_equal_the_oracle(dim: int) -> None:
    rng = np.random.default_rng(10 + dim)
    n = 1500
    pa = rng.uniform(-5, 5, (n, dim))
    x = (pa, rng.uniform(0.1, 10, n), rng.uniform(-3, 3, (n, dim)),
         pa + rng.uniform(-2, 2, (n, dim)), rng.uniform(0.1, 10, n), rng.uniform(-3, 3, (n, dim)),
         rng.uniform(0, 1, n))
    r = assert_responses(*x)
    assert r.stages["double_double"] >= n - 5


@pytest.mark.parametrize("dim", [2, 3])
def test_responses_with_negative_masses_and_cancelling_kicks(dim: int) -> None:
    """Negative total mass flips the sign of ``M d.d`` (hypothesis found the bound's sign)."""
    rng = np.random.default_rng(20 + dim)
    n = 1000
    pa = rng.uniform(-1e8, 1e8, (n, dim))
    x = (pa, rng.uniform(-10, 10, n), rng.uniform(-3, 3, (n, dim)), np.zeros((n, dim)),
         rng.uniform(-10, 10, n), rng.uniform(-3, 3, (n, dim)), rng.uniform(-1, 1, n))
    assert_responses(*x)
    assert_responses([[124742543.0, 1.0]], [0.0], [[1.0, 0.0]], [[0.0, 0.0]], [-1.0],
                     [[0.0, 1.0]], [0.0])


def test_response_special_cases() -> None:
    """Head-on equal masses (exact zeros), signed zeros, undefined, extreme scales."""
    x = ([[0, 0], [0, 0], [0, 0], [0, 0], [1e200, 0], [0, 0]],
         [1.0, 1.0, 1.0, 1.0, 1.0, 2.0],
         [[1, 0], [-0.0, -0.0], [1, 1], [1, 0], [1, 0], [1e-200, 3]],
         [[1, 0], [0, 1], [0, 0], [1, 0], [0, 0], [0, 1]],
         [1.0, 1.0, 1.0, -1.0, 1.0, 3.0],
         [[0, 0], [0, -0.0], [0, 0], [0, 0], [0, 0], [0.5, -0.0]],
         [1.0, 0.5, 1.0, 1.0, 1.0, 0.25])
    r = assert_responses(*x)
    assert r.undefined.tolist() == [False, False, True, True, False, False]
    assert r.stages["exact"] >= 3  # the fallback runs


@settings(max_examples=200, deadline=None)
@given(st.integers(2, 3), st.data())
def test_hypothesis_responses(dim: int, data: st.DataObject) -> None:
    vec = st.lists(coords, min_size=dim, max_size=dim)
    x = ([data.draw(vec)], [data.draw(coords)], [data.draw(vec)], [data.draw(vec)],
         [data.draw(coords)], [data.draw(vec)], [data.draw(st.floats(0, 1))])
    arrays = [np.asarray(v, dtype=np.float64) for v in x]
    try:
        want = exact.sphere_response(*(v[0].tolist() for v in arrays))
        if isinstance(want, Response):
            [float(c) for c in (*want.v1, *want.v2)]
    except OverflowError:  # the pure oracle's float() overflows: so must the batch
        with pytest.raises(OverflowError):
            batch_response.response_values(*arrays)
        return
    assert_responses(*arrays)


def test_truth_batch_equals_truth_on_the_suite() -> None:
    # every case of the suite but the scenes of the other files: truth_batch hands a scene to
    # truth() as it is, so cases/scenes.toml (both dimensions, in the suite's order) shows
    # that they pass through in place; the gravity and gas scenes' exact runs (most of a
    # minute on 2 cores, 371 scenes in all) would only compare truth() with itself
    cases = [c for c in load_paths([ROOT / "cases"]).cases
             if c.kind != "sphere_scene" or c.source.endswith("scenes.toml")]
    assert {c.kind for c in cases} == {"aabb", "sphere", "sphere_response", "sphere_toi",
                                       "sphere_scene"}
    batch = oracle.truth_batch(cases)
    assert [repr(o) for o in batch] == [repr(oracle.truth(c)) for c in cases]


def test_results_do_not_depend_on_the_block_size(monkeypatch: pytest.MonkeyPatch) -> None:
    x = near_pairs("sphere", 1000, 3, np.random.default_rng(5))
    whole = batch_values.sphere_values(*x)
    monkeypatch.setattr(batch_values, "CHUNK", 7)
    small = batch_values.sphere_values(*x)
    assert bits(whole.distance.tolist()) == bits(small.distance.tolist())



