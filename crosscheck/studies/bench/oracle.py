"""The batch oracle's figures: throughput of the exact batch paths against the naive float64
formula, and their agreement with the pure exact oracle (figure 1 of ``crosscheck bench``).

The batch paths themselves are formulas and oracles (:mod:`reference_impl.batch`: verdicts,
:mod:`reference_impl.batch_values`: correctly rounded sphere distances and normals); timing
them is the bench's, here.  The pairs are drawn by :func:`reference_impl.batch.near_pairs`:
``near_fraction`` of them within 3 ulps of touching along one axis, the rest at random.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from reference_impl.batch import (
    FloatArray,
    aabb_batch,
    naive_aabb_verdicts,
    naive_sphere_verdicts,
    near_pairs,
    oracle,
    sphere_batch,
)
from reference_impl.batch_values import naive_values, same_as_oracle, sphere_values


def best_of(f: Callable[[], object], repeat: int = 3) -> float:
    """The shortest of ``repeat`` wall-clock runs of ``f`` (seconds)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def interleaved(*fs: Callable[[], object], rounds: int = 5) -> list[float]:
    """Best wall time of each function over ``rounds`` interleaved repetitions."""
    best = [float("inf")] * len(fs)
    for _ in range(rounds):
        for k, f in enumerate(fs):
            best[k] = min(best[k], best_of(f, 1))
    return best


def mixed_pairs(kind: str, n: int, m: int, dim: int,
                rng: np.random.Generator) -> tuple[FloatArray, ...]:
    """``n`` pairs: ``m`` within 3 ulps of touching, then ``n - m`` at random."""
    near = near_pairs(kind, m, dim, rng)
    far = near_pairs(kind, n - m, dim, rng, max_ulps=0)
    far[2][:] = far[0] + rng.uniform(-15, 15, far[0].shape)
    return tuple(np.ascontiguousarray(np.concatenate([p, q]))
                 for p, q in zip(near, far, strict=True))


def verdicts_benchmark(n: int = 1_000_000, near_fraction: float = 0.01, seed: int = 0,
                       kind: str = "aabb", dim: int = 3) -> dict[str, float]:
    """Time the batch verdicts against the naive formula and check them against the oracle."""
    rng = np.random.default_rng(seed)
    m = int(n * near_fraction)
    x = mixed_pairs(kind, n, m, dim, rng)
    batch = aabb_batch if kind == "aabb" else sphere_batch
    naive = naive_aabb_verdicts if kind == "aabb" else naive_sphere_verdicts
    t_batch = best_of(lambda: batch(*x))
    t_naive = best_of(lambda: naive(*x))
    result = batch(*x)
    sample = np.concatenate([np.arange(m), rng.choice(np.arange(m, n), min(10_000, n - m),
                                                      replace=False)])
    agree = sum(bool(result.hit[i]) == oracle(kind, x, i) for i in sample.tolist())
    naive_hit = naive(*x)
    return {"batch_pairs_per_s": n / t_batch, "naive_pairs_per_s": n / t_naive,
            "ratio": t_naive / t_batch, "fallbacks": result.fallbacks,
            "refined": result.refined,
            "checked": len(sample), "agreement": agree / len(sample),
            "naive_wrong_near": float(sum(bool(naive_hit[i]) != oracle(kind, x, i)
                                          for i in range(m)))}


def values_benchmark(n: int = 1_000_000, seed: int = 0, near_fraction: float = 0.01,
                     dim: int = 3, sample: int = 20_000) -> dict[str, float]:
    """Throughput of :func:`~reference_impl.batch_values.sphere_values` against
    :func:`~reference_impl.batch_values.naive_values`, in one process.

    Pairs as in :func:`verdicts_benchmark`.  Every near pair and ``sample`` others are
    checked against the pure oracle.
    """
    rng = np.random.default_rng(seed)
    m = int(n * near_fraction)
    x = mixed_pairs("sphere", n, m, dim, rng)
    t_naive, t_batch = interleaved(lambda: naive_values(*x), lambda: sphere_values(*x))
    v = sphere_values(*x)
    rows = np.concatenate([np.arange(m), m + rng.choice(n - m, min(sample, n - m), replace=False)])
    identical = sum(same_as_oracle(v, x, i) for i in rows.tolist())
    return {"batch_pairs_per_s": n / t_batch, "naive_pairs_per_s": n / t_naive,
            "ratio": t_naive / t_batch, **{f"stage_{k}": float(c) for k, c in v.stages.items()},
            "checked": float(len(rows)), "identical": float(identical), "near": float(m)}
