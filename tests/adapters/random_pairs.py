"""Seeded random detection cases the adapter tests share."""

from __future__ import annotations

import random

from crosscheck.core.schema import PairCase
from tests.conftest import aabb


def random_box_pair(rng: random.Random, scale: float) -> PairCase:
    """Two boxes near touching along 1-3 axes, B on either side of A (relative gap or
    overlap 1e-8 to 1e-1)."""
    ha = [rng.uniform(0.1, 2.0) * scale for _ in range(3)]
    hb = [rng.uniform(0.1, 2.0) * scale for _ in range(3)]
    ca = [rng.uniform(-1.0, 1.0) * scale for _ in range(3)]
    axes = rng.sample(range(3), rng.choice([1, 1, 2, 3]))
    rel = 10 ** rng.uniform(-8, -1) * rng.choice([-1.0, 1.0])
    cb = [a + (rng.choice([-1.0, 1.0]) * (x + y) * (1 + rel) if i in axes
               else rng.uniform(-0.9, 0.9) * (x + y))
          for i, (a, x, y) in enumerate(zip(ca, ha, hb, strict=True))]
    case = aabb(ca, ha, cb, hb)
    assert isinstance(case, PairCase)
    return case
