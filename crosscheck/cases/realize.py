"""Bodies for one cell of the configuration space: the inverse of :func:`space.classify`.

A cell names a level per dimension; :func:`realize` builds a case's fields that
:func:`crosscheck.cases.space.classify` places back in that cell wherever float64 allows.
Numbers are dyadic stand-ins for the levels (1e-9 is 2^-30, 1e3 is 2^10, a gap of 1e-6 is
2^-20), so sizes, offsets and touching displacements are exact in binary; oblique directions
are Pythagorean (``(2, 3, 6) / 7``), so spheres can touch exactly off the axes.  A cell float64
cannot hold (a gap of one ulp of the size far from the origin, spheres touching exactly on a
diagonal of irrational length) is realised as near as rounding allows, and classifies
elsewhere: the covering design then records it as out of reach
(:mod:`crosscheck.cases.cover`).

>>> import random
>>> from crosscheck.cases.space import SPACES, classify
>>> from crosscheck.core.model import Kind
>>> from crosscheck.core.schema import CASE_ADAPTER
>>> cell = {"direction": "oblique", "gap": "0", "size_ratio": "1e3", "scale": "1e-6"}
>>> data = realize(SPACES[Kind.SPHERE, 3], cell, random.Random(1))
>>> case = CASE_ADAPTER.validate_python(data | {"id": "c", "description": "d"})
>>> {k: classify(case)[k] for k in cell}
{'direction': 'oblique', 'gap': '0', 'size_ratio': '1e3', 'scale': '1e-6'}
"""

from __future__ import annotations

import math
import random
from fractions import Fraction
from typing import Any

from crosscheck.cases.space import Space
from crosscheck.core.model import Kind
from reference_impl import exact

DYADIC = {"1e-12": 2.0 ** -40, "1e-9": 2.0 ** -30, "1e-6": 2.0 ** -20, "1e-3": 2.0 ** -10,
          "1e-1": 2.0 ** -3, "0.5": 0.5, "1": 1.0, "10": 8.0, "1e2": 128.0, "1e3": 2.0 ** 10,
          "1e4": 2.0 ** 13, "1e6": 2.0 ** 20, "1e9": 2.0 ** 30, "1e12": 2.0 ** 40,
          "1e15": 2.0 ** 50, "0": 0.0}
"""The binary number each level token is realised as (log10 within 0.1 of the token's)."""
PYTHAGOREAN = {2: ((3, 4, 5), (5, 12, 13), (8, 15, 17)),
               3: ((2, 3, 6, 7), (1, 4, 8, 9), (2, 6, 9, 11), (3, 4, 12, 13))}
"""Integer directions with an integer length (last entry): exact off-axis touching."""
DEFAULTS = {"direction": "+x", "gap": "0", "size_ratio": "1", "aspect": "1", "scale": "1",
            "offset": "0", "offset_axis": "x", "mass_ratio": "1", "speed": "1",
            "restitution": "1", "angle": "0", "duration": "1"}
"""A dimension a design leaves out is held at this level."""
TOI_DEFAULT_GAP = "+1"
DEEP = -0.75
"""The relative gap a ``deep`` overlap is realised at."""


def value(token: str) -> float:
    """The dyadic stand-in of a numeric level token (sign kept: ``-1e-6`` is -2^-20)."""
    if token == "deep":
        return DEEP
    if token[0] in "+-":
        return math.copysign(DYADIC[token[1:]], -1.0 if token[0] == "-" else 1.0)
    return DYADIC[token]


def realize(space: Space, cell: dict[str, str], rng: random.Random, *,
            jitter: bool = False) -> dict[str, Any]:
    """The fields of a case of ``space``'s kind in ``cell`` (``id`` and ``description`` aside).

    Levels missing from ``cell`` take :data:`DEFAULTS`; ``rng`` picks what no level fixes
    (which body is larger, the thin axis, the diagonal's axes and signs).  ``jitter`` (the
    fuzzer): every numeric level's number times 2^U(-1/2, 1/2), still nearest its level, a
    deep overlap anywhere in [-0.95, -0.35], and oblique directions drawn at random.
    """
    defaults = DEFAULTS | ({"gap": TOI_DEFAULT_GAP} if space.kind is Kind.SPHERE_TOI else {})
    at = defaults | cell
    dim = space.dim
    boxes = space.kind is Kind.AABB

    def shake(x: float) -> float:
        return x * 2.0 ** rng.uniform(-0.5, 0.5) if jitter else x

    big = shake(DYADIC[at["scale"]])
    small = big / shake(DYADIC[at["size_ratio"]])
    first, second = (big, small) if rng.random() < 0.5 else (small, big)
    v, length = _direction(at["direction"], dim, rng)
    if jitter and at["direction"] == "oblique":
        v, length = _random_direction(dim, rng), None
    if boxes:
        aspect = shake(DYADIC[at["aspect"]])
        sa, sb = _box(first, dim, aspect, rng), _box(second, dim, aspect, rng)
        sums = [Fraction(x) + Fraction(y) for x, y in zip(sa, sb, strict=True)]
        t = min(s / abs(Fraction(c)) for s, c in zip(sums, v, strict=True) if c)
        touch = [t * Fraction(c) for c in v]
    else:
        ra, rb, touch = _spheres(first, second, v, length)
        sa, sb = [ra], [rb]
    g = 0.0 if "ulp" in at["gap"] else value(at["gap"])
    g = rng.uniform(-0.95, -0.35) if jitter and at["gap"] == "deep" else (
        g if at["gap"] == "deep" else shake(g))
    offset = _offset(shake(DYADIC[at["offset"]]), at["offset_axis"], dim)
    a = offset
    b = [o + float((1 + Fraction(g)) * x) for o, x in zip(offset, touch, strict=True)]
    data: dict[str, Any] = {"kind": space.kind.value, "dim": dim}
    if "ulp" in at["gap"]:
        _nudge(b, touch, at["gap"][0] == "+")
    if boxes:
        data |= {"a": {"center": a, "half": sa}, "b": {"center": b, "half": sb}}
        return data
    data |= {"a": {"center": a, "radius": sa[0]}, "b": {"center": b, "radius": sb[0]}}
    u, p = _unit_and_normal([float(x) for x in touch])
    if space.kind is Kind.SPHERE_RESPONSE:
        _in_contact(data, touch)
        _response(data, at, u, p, rng)
    elif space.kind is Kind.SPHERE_TOI:
        _toi(data, at, u)
    return data


def _direction(level: str, dim: int, rng: random.Random) -> tuple[list[float], Fraction | None]:
    """An integer direction vector for ``level`` and its length (None: irrational)."""
    if level[0] in "+-":
        axis = "xyz".index(level[1])
        return [(1 if level[0] == "+" else -1) if i == axis else 0 for i in range(dim)], \
            Fraction(1)
    signs = [rng.choice((1, -1)) for _ in range(dim)]
    if level == "oblique":
        *parts, n = rng.choice(PYTHAGOREAN[dim])
        rng.shuffle(parts)
        return [s * p for s, p in zip(signs, parts, strict=True)], Fraction(n)
    count = int(level.split("-")[1])
    axes = sorted(rng.sample(range(dim), count))
    return [signs[i] if i in axes else 0 for i in range(dim)], None


def _random_direction(dim: int, rng: random.Random) -> list[float]:
    while True:
        v = [rng.gauss(0.0, 1.0) for _ in range(dim)]
        if math.hypot(*v) > 1e-3:
            return v


def _box(size: float, dim: int, aspect: float, rng: random.Random) -> list[float]:
    half = [size] * dim
    half[rng.randrange(dim)] = size / aspect
    return half


def _spheres(first: float, second: float, v: list[float],
             length: Fraction | None) -> tuple[float, float, list[Fraction]]:
    """Radii and the exact touching displacement along ``v``.

    With an integer length n the displacement is ``q v`` with q a 48-bit number near
    (ra + rb) / n, and the second radius is adjusted (exactly) to ``q n - ra``.
    """
    if length is None:  # a diagonal: touching only within rounding
        norm = math.sqrt(sum(c * c for c in v))
        return first, second, [Fraction((first + second) / norm * c) for c in v]
    q = Fraction(first + second) / length
    bits = 47 - math.frexp(float(q))[1]
    q = Fraction(round(q * 2 ** bits), 2 ** bits)
    second = float(q * length - Fraction(first))
    return first, second, [q * Fraction(c) for c in v]


def _offset(size: float, axis: str, dim: int) -> list[float]:
    if axis == "many":
        return [size] * dim
    return [size if "xyz"[i] == axis else 0.0 for i in range(dim)]


def _nudge(b: list[float], touch: list[Fraction], outward: bool) -> None:
    """Move B one ulp per coordinate along the touching displacement ``touch``, away from A
    (``outward``) or towards it; equal components stay equal (a diagonal stays one)."""
    for i, x in enumerate(touch):
        if x:
            away = math.inf if x > 0 else -math.inf
            b[i] = math.nextafter(b[i], away if outward else -away)


def _unit_and_normal(d: list[float]) -> tuple[list[float], list[float]]:
    """The unit vector along ``d`` (the touching displacement) and one normal to it."""
    n = math.sqrt(sum(x * x for x in d))
    u = [x / n for x in d]
    if len(u) == 2:
        return u, [-u[1], u[0]]
    axis = min(range(3), key=lambda i: abs(u[i]))
    e = [1.0 if i == axis else 0.0 for i in range(3)]
    p = [u[1] * e[2] - u[2] * e[1], u[2] * e[0] - u[0] * e[2], u[0] * e[1] - u[1] * e[0]]
    m = math.sqrt(sum(x * x for x in p))
    return u, [x / m for x in p]


def _in_contact(data: dict[str, Any], touch: list[Fraction]) -> None:
    """A response's spheres in contact: touching exactly where binary allows (axes,
    Pythagorean directions), else overlapping by the fewest ulps (a diagonal)."""
    a, b = data["a"], data["b"]
    for _ in range(64):
        gap = exact.sphere_contact(a["center"], a["radius"], b["center"], b["radius"])
        if not float(getattr(gap, "distance", 0.0)) > 0:
            return
        _nudge(b["center"], touch, outward=False)


def _response(data: dict[str, Any], at: dict[str, str], u: list[float], p: list[float],
              rng: random.Random) -> None:
    """Masses, restitution and velocities: A approaches B at ``speed``, ``angle`` off the
    line of centres, each body taking half the relative velocity."""
    ratio = DYADIC[at["mass_ratio"]]
    masses = (1.0, ratio) if rng.random() < 0.5 else (ratio, 1.0)
    theta = math.radians(float(at["angle"]))
    speed = DYADIC[at["speed"]]
    w = [speed * (math.cos(theta) * x + math.sin(theta) * y) for x, y in zip(u, p, strict=True)]
    data["a"] |= {"mass": masses[0], "velocity": [x / 2 for x in w]}
    data["b"] |= {"mass": masses[1], "velocity": [-x / 2 for x in w]}
    data["restitution"] = float(at["restitution"])


def _toi(data: dict[str, Any], at: dict[str, str], u: list[float]) -> None:
    """Head-on approach at ``speed`` over an interval of ``duration``."""
    speed = DYADIC[at["speed"]]
    data["a"] |= {"velocity": [speed * x / 2 for x in u]}
    data["b"] |= {"velocity": [-speed * x / 2 for x in u]}
    data["duration"] = DYADIC[at["duration"]]
