"""Fuzz case generation: random cases around the boundaries where engines fail.

Half the cases (every time-of-impact case) are drawn from the configuration space
(:mod:`crosscheck.cases.space`), family ``space``: a level on every dimension of the kind
(direction, gap from deep overlap to 1e3 sizes apart, size and aspect ratios, scale, offset
and its axis; responses' masses, speed, restitution and angle; times of impact's speed and
interval), the numbers jittered inside their level and oblique directions drawn at random;
with a *bias* (cells where an engine already failed, :func:`failing_cells`) half of those
start from a failing cell and keep most of its levels.  The others draw a set of parts; the
first is its *family* (the generator that drives it), the others modify it (its tags are
``fuzz`` and every part):

- ``near-touching``: a touching configuration (exact along a random axis, to
  within rounding along a random direction), then B moved by a relative gap of
  +-10^U(-16, -1) or by +-k ulps per coordinate (k = 1 ... 100);
- ``scaled``: every length (and velocity) times 10^U(-9, 9);
- ``offset``: both bodies translated by 10^U(0, 15) on some axes;
- ``mass-ratio`` (responses): masses in ratio 10^U(0, 12) instead of 10^U(0, 1).

Responses always draw an approach speed of 10^U(-3, 1), a restitution in
{0, 0.5, 1} and, half the time, tangential velocities.  Each family has a
*driving parameter*: the exact relative gap (signed distance / touching
distance, from the oracle), the scale, the offset or the mass ratio.

Cases come in chunks of :data:`CHUNK`: chunk ``k`` (cases ``k*CHUNK`` onwards)
draws from its own generator, seeded by ``(seed, k)``, case after case.  So a
seed gives the same cases byte for byte (and the first N of a longer run), and
any chunk can be generated alone, without the chunks before it: a campaign
generates them lazily, in parallel, and a resumed one regenerates exactly the
chunks it has not finished.

:mod:`crosscheck.studies.fuzz.campaign` runs them and :mod:`crosscheck.cases.writer` writes the
grouped findings.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from crosscheck.cases.load import semantic_problems
from crosscheck.cases.realize import realize
from crosscheck.cases.space import Cell, classify, relative_gap, space_of
from crosscheck.core.kinds import spec
from crosscheck.core.model import Kind
from crosscheck.core.schema import CASE_ADAPTER, AnyCase
from reference_impl import exact

Rng = np.random.Generator
Vec = list[float]

CHANCE = {"mass-ratio": 0.5, "near-touching": 0.6, "scaled": 0.4, "offset": 0.4}
DRIVER = {"mass-ratio": "mass ratio", "near-touching": "relative gap", "scaled": "scale",
          "offset": "offset", "space": "relative gap"}
SPACE_SHARE = 0.5
"""The share of cases of a kind with the families above drawn from the configuration space
(every case of a kind without them: times of impact)."""
BIAS_SHARE = 0.5
"""With a bias, the share of space cases that start from a failing cell."""
KEEP_LEVEL = 0.7
"""A case started from a failing cell keeps each of its levels with this chance."""
Bias = tuple[tuple[str, int, tuple[tuple[str, str], ...]], ...]
"""Failing cells: (kind, dim, ((dimension, level), ...)), in a stable order."""
NEAR_LIMIT = 0.1
"""A near-touching case has |exact relative gap| below this (else it is drawn again)."""


@dataclass(frozen=True, slots=True)
class Generated:
    """A generated case, its family (and modifying parts) and its driving parameter's value."""

    case: AnyCase
    family: str
    parts: tuple[str, ...]
    driver: str
    value: float
    index: int

    @property
    def decade(self) -> str:
        """``1e-09`` for a magnitude in [1e-9, 1e-8), ``0`` for zero."""
        if self.value == 0:
            return "0"
        return f"1e{math.floor(math.log10(abs(self.value))):+03d}"


def case_id(kind: Kind, seed: int, index: int) -> str:
    """The stable id ``fuzz-<kind>-s<seed>-<index>`` (``_`` written ``-``)."""
    return f"fuzz-{kind.value.replace('_', '-')}-s{seed}-{index}"


CHUNK = 1000
"""Cases per chunk.  Part of the definition of a seed's cases: changing it changes them."""


def chunk_count(n: int) -> int:
    """How many chunks ``n`` cases take (the last one may be short)."""
    return -(-n // CHUNK)


def chunk_rng(seed: int, chunk: int) -> Rng:
    """The generator of chunk ``chunk`` of ``seed``: independent of every other chunk."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(chunk,)))


def generate_chunk(kind: Kind, seed: int, chunk: int, n: int, bias: Bias = ()) -> list[Generated]:
    """Chunk ``chunk`` of the first ``n`` cases of ``seed``: indices ``chunk*CHUNK`` onwards."""
    rng = chunk_rng(seed, chunk)
    first = chunk * CHUNK
    return [_one(rng, kind, seed, index, bias) for index in range(first, min(n, first + CHUNK))]


def generate(kind: Kind, n: int, seed: int, bias: Bias = ()) -> list[Generated]:
    """``n`` valid cases of ``kind`` from ``seed``, each in its family's regime."""
    return [g for chunk in range(chunk_count(n))
            for g in generate_chunk(kind, seed, chunk, n, bias)]


def _one(rng: Rng, kind: Kind, seed: int, index: int, bias: Bias) -> Generated:
    for _ in range(1000):  # redraw the rare case out of regime (e.g. gap lost to the offset)
        cid = case_id(kind, seed, index)
        made = (_from_space(rng, kind, cid, index, bias)
                if not spec(kind).fuzz or rng.random() < SPACE_SHARE
                else _attempt(rng, kind, cid, index))
        if made is not None:
            return made
    raise RuntimeError(f"no case in regime after 1000 draws ({kind}, seed {seed}, #{index})")


def _from_space(rng: Rng, kind: Kind, cid: str, index: int, bias: Bias) -> Generated | None:
    """A case at a random level of every dimension of ``kind``'s space (2-D or 3-D), or near
    a failing cell of ``bias``; numbers jittered inside their levels."""
    dim = int(rng.integers(2, 4))
    space = space_of(kind, dim)
    assert space is not None  # every kind fuzz makes has a space
    cell: Cell = {d.name: d.levels[int(rng.integers(len(d.levels)))] for d in space.dimensions}
    near = [items for k, d, items in bias if k == kind.value and d == dim]
    started = bool(near) and rng.random() < BIAS_SHARE
    if started:
        failing = near[int(rng.integers(len(near)))]
        cell |= {name: level for name, level in failing if rng.random() < KEEP_LEVEL}
    data = realize(space, cell, random.Random(int(rng.integers(2 ** 63))), jitter=True)
    words = ", ".join(f"{n.replace('_', ' ')} {v}" for n, v in cell.items())
    start = " (near a failing cell)" if started else ""
    case = CASE_ADAPTER.validate_python(data | {
        "id": cid, "tags": ["fuzz", "space"],
        "description": f"fuzz space{start}: {words}"})
    if semantic_problems(case) or data["a"]["center"] == data["b"]["center"]:  # one point
        return None
    gap = relative_gap(case)
    return Generated(case, "space", ("space",), DRIVER["space"],
                     0.0 if gap is None else gap, index)


def failing_cells(cases: Sequence[AnyCase], failing: set[str]) -> Bias:
    """The cells of the cases whose ids are in ``failing`` (a bias for :func:`generate`)."""
    cells = {(c.kind, c.dim, tuple(sorted(classify(c).items()))) for c in cases
             if c.id in failing and not c.bad_input}
    return tuple(sorted(cells))


def _g(x: float) -> str:
    return f"{x + 0.0:.2g}"  # + 0.0: no "-0"


def _v(xs: Sequence[float]) -> str:
    return "(" + ", ".join(_g(x) for x in xs) + ")"


def _u(rng: Rng, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def _sign(rng: Rng) -> int:
    return 1 if rng.random() < 0.5 else -1


@dataclass
class _Draft:
    """A configuration being built: centres, sizes (radius or half-widths), touch direction."""

    pa: Vec
    pb: Vec
    sa: Vec
    sb: Vec
    u: Vec
    size: float
    words: list[str]
    exact_touch: bool


def _attempt(rng: Rng, kind: Kind, cid: str, index: int) -> Generated | None:
    parts: list[str] = []
    while not parts:
        parts = [p for p in spec(kind).fuzz if rng.random() < CHANCE[p]]
    dim = int(rng.integers(2, 4))
    scale = 10 ** _u(rng, -9, 9) if "scaled" in parts else 1.0
    shift, moved = _shift(rng, dim) if "offset" in parts else ([0.0] * dim, "")
    draft = (_boxes if kind is Kind.AABB else _spheres)(rng, dim, scale, shift)
    near = "near-touching" in parts
    if near:
        _perturb(rng, draft)
    elif kind is Kind.SPHERE_RESPONSE:
        draft.words.append(f"touching along {_v(draft.u)}")
    else:
        _move(draft, _u(rng, -0.5, 0.5))
    rel = _relative_gap(kind, draft)
    if near:
        draft.words[-1] += f" (exact relative gap {rel:.3g})"
    draft.words += [f"all lengths scaled by {_g(scale)}"] * ("scaled" in parts)
    draft.words += [moved] * bool(moved)
    data = _body_data(kind, draft)
    ratio = _dynamics(rng, data, draft, scale, "mass-ratio" in parts) \
        if kind is Kind.SPHERE_RESPONSE else 1.0
    title = parts[0] + (f" with {', '.join(parts[1:])}" if parts[1:] else "")
    case = CASE_ADAPTER.validate_python(data | {
        "id": cid, "kind": kind.value, "dim": dim, "tags": ["fuzz", *parts],
        "description": f"fuzz {title}: {'; '.join(draft.words)}"})
    if draft.pa == draft.pb or (near and not abs(rel) < NEAR_LIMIT) or semantic_problems(case):
        return None
    values = {"mass-ratio": ratio, "near-touching": rel, "scaled": scale,
              "offset": max(map(abs, shift))}
    return Generated(case, parts[0], tuple(parts), DRIVER[parts[0]], values[parts[0]], index)


def _shift(rng: Rng, dim: int) -> tuple[Vec, str]:
    size = 10 ** _u(rng, 0, 15)
    axes = [i for i in range(dim) if rng.random() < 0.5] or [int(rng.integers(dim))]
    signs = [_sign(rng) for _ in range(dim)]
    where = ", ".join(("-" if signs[i] < 0 else "") + "xyz"[i] for i in axes)
    return ([signs[i] * size if i in axes else 0.0 for i in range(dim)],
            f"both offset by {size:.3g} on {where}")


def _touch(pa: float, ra: float, rb: float, sign: float) -> tuple[float, float, bool]:
    """B's coordinate and size with |pb - pa| == ra + rb exactly, when rounding allows."""
    pb = pa + sign * (ra + rb)
    d = abs(Fraction(pb) - Fraction(pa))
    rb2 = float(d - Fraction(ra))
    if abs(rb2 - rb) <= 0.5 * rb and Fraction(ra) + Fraction(rb2) == d:
        return pb, rb2, True
    return pb, rb, False


def _ulps(x: float, k: int) -> float:
    for _ in range(abs(k)):
        x = math.nextafter(x, math.inf if k > 0 else -math.inf)
    return x


def _perturb(rng: Rng, d: _Draft) -> None:
    """Move B off touching along ``u``: by a relative gap, or by k ulps per coordinate."""
    sign = _sign(rng)
    if rng.random() < 0.5:
        gap = sign * 10 ** _u(rng, -16, -1)
        d.pb = [p + gap * d.size * x for p, x in zip(d.pb, d.u, strict=True)]
        d.words.append(f"B moved by relative gap {gap:.3g} along {_v(d.u)}")
    else:
        k = sign * round(10 ** _u(rng, 0, 2))
        d.pb = [_ulps(p, k if x > 0 else -k) if x else p for p, x in zip(d.pb, d.u, strict=True)]
        d.words.append(f"B moved {k:+d} ulps per coordinate along {_v(d.u)}")
    d.words[-1] += " from exact touching" if d.exact_touch else " from touching within rounding"


def _move(d: _Draft, gap: float) -> None:
    d.pb = [p + gap * d.size * x for p, x in zip(d.pb, d.u, strict=True)]
    d.words.append(f"B at relative gap {gap:.3g} along {_v(d.u)}")


def _direction(rng: Rng, dim: int) -> Vec:
    while True:
        v = rng.normal(size=dim)
        norm = float(np.linalg.norm(v))
        if norm > 1e-3:
            return [float(x) / norm for x in v]


def _spheres(rng: Rng, dim: int, scale: float, shift: Vec) -> _Draft:
    ra, rb = scale * _u(rng, 0.1, 1), scale * _u(rng, 0.1, 1)
    pa = [s + scale * _u(rng, -1, 1) for s in shift]
    if rng.random() < 0.5:  # along an axis: exact
        axis, sign = int(rng.integers(dim)), _sign(rng)
        pb = list(pa)
        pb[axis], rb, exact_touch = _touch(pa[axis], ra, rb, sign)
        u = [float(sign) if i == axis else 0.0 for i in range(dim)]
    else:  # along a direction: rb set to touch within one rounding
        u = _direction(rng, dim)
        pb = [p + (ra + rb) * x for p, x in zip(pa, u, strict=True)]
        dist = getattr(exact.sphere_contact(pa, ra, pb, rb), "distance", 0.0)
        rb, exact_touch = (rb + dist if abs(dist) <= 0.5 * rb else rb), False
    words = [f"{dim}-D spheres ra={_g(ra)} rb={_g(rb)}"]
    return _Draft(pa, pb, [ra], [rb], u, ra + rb, words, exact_touch)


def _boxes(rng: Rng, dim: int, scale: float, shift: Vec) -> _Draft:
    ha = [scale * _u(rng, 0.1, 1) for _ in range(dim)]
    hb = [scale * _u(rng, 0.1, 1) for _ in range(dim)]
    pa = [s + scale * _u(rng, -1, 1) for s in shift]
    signs = [_sign(rng) for _ in range(dim)]
    count = 1 if rng.random() < 0.5 else int(rng.integers(2, dim + 1))  # face, or edge/corner
    touching = sorted(int(i) for i in rng.permutation(dim)[:count])
    pb, exact_touch = list(pa), True
    for i in range(dim):
        if i in touching:
            pb[i], hb[i], ok = _touch(pa[i], ha[i], hb[i], signs[i])
            exact_touch = exact_touch and ok
        else:  # overlapping by at least half on the other axes
            pb[i] = pa[i] + signs[i] * _u(rng, 0, 0.5) * (ha[i] + hb[i])
    weights = [_u(rng, 0.2, 1) if i in touching else 0.0 for i in range(dim)]
    norm = math.sqrt(sum(w * w for w in weights))
    u = [signs[i] * w / norm for i, w in enumerate(weights)]
    where = ", ".join("xyz"[i] for i in touching)
    words = [f"{dim}-D boxes ha={_v(ha)} hb={_v(hb)} touching on {where}"]
    size = max(ha[i] + hb[i] for i in touching)
    return _Draft(pa, pb, ha, hb, u, size, words, exact_touch)


def _body_data(kind: Kind, d: _Draft) -> dict[str, Any]:
    if kind is Kind.AABB:
        return {"a": {"center": d.pa, "half": d.sa}, "b": {"center": d.pb, "half": d.sb}}
    return {"a": {"center": d.pa, "radius": d.sa[0]}, "b": {"center": d.pb, "radius": d.sb[0]}}


def _tangent(rng: Rng, u: Vec, speed: float) -> Vec:
    v = _direction(rng, len(u))
    dot = sum(x * y for x, y in zip(v, u, strict=True))
    t = [x - dot * y for x, y in zip(v, u, strict=True)]
    size = speed * 10 ** _u(rng, -2, 1) / (math.sqrt(sum(x * x for x in t)) or 1.0)
    return [size * x for x in t]


def _dynamics(rng: Rng, data: dict[str, Any], d: _Draft, scale: float, extreme: bool) -> float:
    """Masses, velocities and restitution of a response, into ``data``; the mass ratio."""
    ratio = 10 ** _u(rng, 0, 12 if extreme else 1)
    mass = 10 ** _u(rng, -3, 3)
    masses = (mass, mass * ratio) if rng.random() < 0.5 else (mass * ratio, mass)
    speed, share = scale * 10 ** _u(rng, -3, 1), _u(rng, 0, 1)
    va, vb = [share * speed * x for x in d.u], [(share - 1) * speed * x for x in d.u]
    tangential = rng.random() < 0.5
    if tangential:
        va = [x + t for x, t in zip(va, _tangent(rng, d.u, speed), strict=True)]
        vb = [x + t for x, t in zip(vb, _tangent(rng, d.u, speed), strict=True)]
    data["restitution"] = float(rng.choice([0.0, 0.5, 1.0]))
    data["a"] |= {"mass": masses[0], "velocity": va}
    data["b"] |= {"mass": masses[1], "velocity": vb}
    d.words += [f"masses {masses[0]:.3g} and {masses[1]:.3g} (ratio {ratio:.3g})",
                f"approach speed {speed:.3g}" + " with tangential velocities" * tangential,
                f"restitution {data['restitution']:g}"]
    return ratio


def _relative_gap(kind: Kind, d: _Draft) -> float:
    """The exact signed distance (oracle) over the touching distance."""
    contact = (exact.aabb_contact(d.pa, d.sa, d.pb, d.sb) if kind is Kind.AABB
               else exact.sphere_contact(d.pa, d.sa[0], d.pb, d.sb[0]))
    return float(getattr(contact, "distance", math.nan)) / d.size
