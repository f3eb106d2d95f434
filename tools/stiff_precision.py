"""The precision of the stiff MuJoCo contact (variant ``mujoco``), measured off the suite.

    python -m tools.stiff_precision                 # 400 random cases, seed 0
    python -m tools.stiff_precision --cases 1000 --seed 3

The variant ``mujoco`` declares ``response_rtol``: how far its response velocities may
be from the textbook's, relative to the case's largest velocity component.  That number
must not be fitted to the suite it then judges, so this tool draws its own cases, none
of them in ``cases/``: two spheres touching exactly (in binary) along a rational
direction (Pythagorean triples and quadruples), centres within 10 of the origin, radii
0.125 to 8, masses 1 and 10^U(-3, 3), restitution in (0, 1], and an approach along the
line of centres of 0.01 to 10 plus a tangential slide of up to 3 times it (head-on to
grazing).  It prints the worst and the quantiles of ``|v - truth| / V`` over both
velocities, and the case that gave the worst.  The adapter's docstring states the
result and this command.
"""

from __future__ import annotations

import argparse
import math
import random
from collections.abc import Sequence
from typing import Any

import adapters
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.schema import CASE_ADAPTER, ResponseCase
from crosscheck.results.timings import quantiles
from crosscheck.truth import oracle
from crosscheck.truth.allowance import velocity_scale

DIRECTIONS_2D = ((3, 4, 5), (5, 12, 13), (8, 15, 17), (20, 21, 29), (1, 0, 1))
DIRECTIONS_3D = ((1, 2, 2, 3), (2, 3, 6, 7), (1, 4, 8, 9), (4, 4, 7, 9), (2, 6, 9, 11))


def _dyadic(rng: random.Random, low: float, high: float, bits: int = 6) -> float:
    """A random number in [low, high] with at most ``bits`` bits after the binary point."""
    return float(round(rng.uniform(low, high) * 2**bits) / 2**bits)


def _direction(rng: random.Random, dim: int) -> tuple[tuple[int, ...], int]:
    """A rational unit direction: integer components and their common length."""
    *parts, length = rng.choice(DIRECTIONS_2D if dim == 2 else DIRECTIONS_3D)
    signed = [p * rng.choice((-1, 1)) for p in parts]
    rng.shuffle(signed)
    return tuple(signed), length


def draw(rng: random.Random, index: int) -> ResponseCase:
    """One random touching pair (see the module docstring)."""
    dim = rng.choice((2, 3))
    parts, length = _direction(rng, dim)
    reach = length * 2.0 ** rng.randint(-3, 3) / 8  # ra + rb: a multiple of the length
    ra = reach * rng.randint(1, 7) / 8
    pa = [_dyadic(rng, -10.0, 10.0) for _ in range(dim)]
    pb = [x + reach / length * p for x, p in zip(pa, parts, strict=True)]
    n = [p / length for p in parts]
    tangent = [rng.gauss(0.0, 1.0) for _ in range(dim)]
    along = sum(t * k for t, k in zip(tangent, n, strict=True))
    tangent = [t - along * k for t, k in zip(tangent, n, strict=True)]
    size = math.hypot(*tangent) or 1.0
    approach = 10.0 ** rng.uniform(-2.0, 1.0)
    slide = approach * rng.uniform(0.0, 3.0)
    vb = [rng.uniform(-2.0, 2.0) for _ in range(dim)]
    va = [y + approach * k + slide * t / size for y, k, t in zip(vb, n, tangent, strict=True)]
    case = CASE_ADAPTER.validate_python({
        "id": f"stiff-{index}", "description": "random touching pair", "kind": "sphere_response",
        "dim": dim, "restitution": rng.choice((1.0, rng.uniform(0.01, 1.0))),
        "a": {"center": pa, "radius": ra, "mass": 1.0, "velocity": va},
        "b": {"center": pb, "radius": reach - ra, "mass": 10.0 ** rng.uniform(-3.0, 3.0),
              "velocity": vb}})
    assert isinstance(case, ResponseCase)
    return case


def relative_error(case: ResponseCase, adapter: Any) -> float:
    """The larger of the two velocity errors, over the case's largest velocity component."""
    got, want = adapter.observe(case), oracle.truth(case)
    errors = [norm([x - y for x, y in zip(g, w, strict=True)])
              for g, w in ((got.v1, want.v1), (got.v2, want.v2))
              if isinstance(g, tuple) and isinstance(w, tuple)]
    return max(errors) / velocity_scale(case)


def main(argv: Sequence[str] | None = None) -> int:
    """Measure and print (see the module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=400, help="random cases (default 400)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    args = parser.parse_args(argv)
    rng, adapter = random.Random(args.seed), adapters.get("mujoco")
    measured: list[tuple[float, ResponseCase]] = []
    for i in range(args.cases):
        case = draw(rng, i)
        measured.append((relative_error(case, adapter), case))
    errors = sorted(e for e, _ in measured)
    worst, case = max(measured, key=lambda m: m[0])
    print(f"{len(errors)} random touching pairs (seed {args.seed}): |v - truth| / V")
    print("  median {:.3g}, 90% {:.3g}, 99% {:.3g}, worst {:.3g}".format(
        *quantiles(errors, (0.5, 0.9, 0.99), nearest=True), worst))
    speeds: Vec = (norm(case.a.velocity), norm(case.b.velocity))
    print(f"  worst: {case.dim}-D, e = {case.restitution:.3g}, mass ratio "
          f"{case.b.mass / case.a.mass:.3g}, speeds {speeds[0]:.3g} and {speeds[1]:.3g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
