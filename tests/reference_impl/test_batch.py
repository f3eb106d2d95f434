"""The vectorized batch verdicts (reference_impl.batch) against the exact oracle."""

from __future__ import annotations

import doctest
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reference_impl import batch
from reference_impl.expansion import sum_sign

KINDS = ["aabb", "sphere"]
FN = {"aabb": batch.aabb_batch, "sphere": batch.sphere_batch}
NAIVE = {"aabb": batch.naive_aabb_verdicts, "sphere": batch.naive_sphere_verdicts}


def oracle(kind: str, x: tuple[np.ndarray, ...]) -> list[bool]:
    return [batch.oracle(kind, x, i) for i in range(len(x[0]))]


def test_doctests() -> None:
    assert doctest.testmod(batch).failed == 0


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize(("scale", "offset"), [(1.0, 0.0), (1.0, 1e15), (1e-300, 0.0),
                                               (1e-150, 0.0), (1e-9, 0.0), (1e-9, 1e6)])
def test_near_touching_equals_oracle(kind: str, dim: int, scale: float, offset: float) -> None:
    rng = np.random.default_rng(hash((kind, dim, scale, offset)) % 2**32)
    x = batch.near_pairs(kind, 300, dim, rng, scale=scale, offset=offset)
    assert FN[kind](*x).hit.tolist() == oracle(kind, x)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("dim", [2, 3])
def test_exact_touching_and_one_ulp(kind: str, dim: int) -> None:
    rng = np.random.default_rng(1)
    for ulps in (0, 1):
        x = batch.near_pairs(kind, 200, dim, rng, max_ulps=ulps)
        assert FN[kind](*x).hit.tolist() == oracle(kind, x)


@pytest.mark.parametrize("kind", KINDS)
def test_mixed_magnitudes_and_random(kind: str) -> None:
    rng = np.random.default_rng(2)
    n, dim = 2000, 3
    mag = 10.0 ** rng.integers(-300, 300, (n, 1))
    a = mag * rng.uniform(-1, 1, (n, dim))
    b = a + mag * rng.uniform(-3, 3, (n, dim))
    size = (n, dim) if kind == "aabb" else (n,)
    m = mag if kind == "aabb" else mag[:, 0]
    h, k = m * rng.uniform(-0.1, 2, size), m * rng.uniform(0, 2, size)
    x = (a, h, b, k)
    assert FN[kind](*x).hit.tolist() == oracle(kind, x)


@pytest.mark.parametrize("kind", KINDS)
def test_non_finite_marked_undefined(kind: str) -> None:
    x = list(batch.near_pairs(kind, 4, 3, np.random.default_rng(3)))
    x[0][0, 0], x[2][1, 1] = np.nan, np.inf
    x[1][2] = -np.inf
    res = FN[kind](*x)
    assert res.undefined.tolist() == [True, True, True, False]
    assert res.hit.tolist()[:3] == [False] * 3
    assert res.hit.tolist() == oracle(kind, tuple(x))


@pytest.mark.parametrize("kind", KINDS)
def test_naive_differs_somewhere(kind: str) -> None:
    x = batch.near_pairs(kind, 500, 3, np.random.default_rng(4))
    assert NAIVE[kind](*x).tolist() != oracle(kind, x)


def test_verdict_and_distance_wrappers() -> None:
    x = batch.near_pairs("aabb", 20, 2, np.random.default_rng(5))
    assert batch.aabb_verdicts(*x).tolist() == oracle("aabb", x)
    assert batch.aabb_distances(*x).dtype == np.float64
    y = batch.near_pairs("sphere", 20, 3, np.random.default_rng(6))
    assert batch.sphere_verdicts(*y).tolist() == oracle("sphere", y)
    d = batch.sphere_distances(*y)
    assert ((d > 0) | (d == 0) | (d < 0)).all()


finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(KINDS), st.integers(2, 3), st.lists(finite, min_size=14, max_size=14),
       st.integers(-4, 4))
def test_hypothesis_nudged(kind: str, dim: int, vals: list[float], ulps: int) -> None:
    a = np.array([vals[:dim]])
    if kind == "aabb":
        h, k = np.abs(np.array([vals[3:3 + dim]])), np.abs(np.array([vals[6:6 + dim]]))
        b = a + np.array([vals[9:9 + dim]]) * 1e-3
        b[0, 0] = a[0, 0] + (h[0, 0] + k[0, 0])
    else:
        h, k = np.abs(np.array(vals[3:4])), np.abs(np.array(vals[4:5]))
        b = a.copy()
        b[0, 0] = a[0, 0] + (h[0] + k[0])
    for _ in range(abs(ulps)):
        b[0, 0] = np.nextafter(b[0, 0], np.inf if ulps > 0 else -np.inf)
    x = (a, h, b, k)
    assert FN[kind](*x).hit.tolist() == oracle(kind, x)


def test_sphere_exact_ties_need_no_fractions() -> None:
    """3-4-5 triangles touch exactly (q == r**2): not a hit, settled by the second stage."""
    scale = 2.0 ** np.arange(-40, 41, 8.0)
    pa = np.zeros((len(scale), 3))
    pb = np.stack([3 * scale, 4 * scale, 0 * scale], axis=1)
    ra, rb = 2 * scale, 3 * scale
    res = batch.sphere_batch(pa, ra, pb, rb)
    assert not res.hit.any()
    assert res.refined == len(scale) and res.fallbacks == 0
    nudged = batch.sphere_batch(pa, ra, pb, np.nextafter(rb, np.inf))
    assert nudged.hit.all() and nudged.fallbacks == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_sphere_near_pairs_settled_without_fractions(dim: int) -> None:
    x = batch.near_pairs("sphere", 2000, dim, np.random.default_rng(7))
    res = batch.sphere_batch(*x)
    assert res.refined > 1000 and res.fallbacks == 0
    assert res.hit.tolist() == oracle("sphere", x)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-1e200, 1e200, allow_nan=False, allow_infinity=False)
                | st.sampled_from([0.0, 2.0**-400, -(2.0**-400), 1.0, -1.0]),
                min_size=1, max_size=30))
def test_sum_sign_is_exact(values: list[float]) -> None:
    column = np.array(values)[:, None]
    cancel = np.concatenate([column, -column[::-1]])  # sums to exactly zero
    total = sum(Fraction(v) for v in values)
    expected = (total > 0) - (total < 0)
    assert sum_sign(column).tolist() == [expected]
    both = np.concatenate([np.concatenate([column, np.zeros_like(column)]), cancel], axis=1)
    assert sum_sign(both).tolist() == [expected, 0]
