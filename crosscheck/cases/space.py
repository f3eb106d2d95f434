"""The configuration space: the dimensions that change an engine's answer, defined once.

For each two-body kind (``aabb``, ``sphere``, ``sphere_response``, ``sphere_toi``) and
dimension (2-D, 3-D), the space names the dimensions along which an engine's algorithm can
break and the levels each is asked at.  Three things read it:

- :mod:`crosscheck.cases.cover` expands a ``[[cover]]`` block into a covering design over it
  (every pair of levels of every two dimensions in at least one case);
- :func:`classify` places *any* case in its cell, measured from its geometry (curated,
  swept, generated or fuzzed alike), so coverage counts what a suite really asks;
- :mod:`crosscheck.cases.realize` builds the bodies of one cell.

Every level is a token (``"+1e-9"``, ``"diag-2"``) with, for numeric dimensions, the value it
stands for; a measured value is placed at the nearest level in log10 (sign kept).  The levels
and their meaning are the table of ``docs/coverage.md`` (written from :func:`table_rows`).

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> case = CASE_ADAPTER.validate_python({"id": "s", "description": "d", "kind": "aabb",
...     "dim": 3, "a": {"center": [0, 0, 0], "half": [1, 1, 1]},
...     "b": {"center": [0, 3, 0], "half": [1, 1, 1]}})
>>> cell = classify(case)
>>> cell["direction"], cell["gap"], cell["size_ratio"], cell["offset"]
('+y', '+1', '1', '0')
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from fractions import Fraction

from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SphereCase, ToiCase
from reference_impl import exact

Cell = dict[str, str]
"""A case's level on each dimension of its space (a dimension it has no level on is absent)."""


@dataclass(frozen=True, slots=True)
class Dimension:
    """One axis of the space: its levels, what it measures, and how a case is placed on it."""

    name: str
    levels: tuple[str, ...]
    doc: str
    values: tuple[float, ...] = ()
    """The value each level stands for (numeric dimensions; realised as nearby dyadics)."""

    def nearest(self, x: float) -> str:
        """The level whose value is nearest ``x`` in log10 (numeric dimensions, x > 0)."""
        return min(zip(self.levels, self.values, strict=True),
                   key=lambda lv: abs(math.log10(lv[1]) - math.log10(x)))[0]


@dataclass(frozen=True, slots=True)
class Space:
    """The dimensions of one kind in one dimension (2-D or 3-D)."""

    kind: Kind
    dim: int
    dimensions: tuple[Dimension, ...]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(d.name for d in self.dimensions)

    def dimension(self, name: str) -> Dimension:
        return next(d for d in self.dimensions if d.name == name)

    @property
    def strong(self) -> tuple[str, ...]:
        """The dimensions covered three at a time: :data:`STRONG`, or a response's."""
        return STRONG if set(STRONG) <= set(self.names) else RESPONSE_STRONG


def _numeric(name: str, tokens: Sequence[str], doc: str) -> Dimension:
    return Dimension(name, tuple(tokens), doc, tuple(float(t) for t in tokens))


DIRECTION_DOC = ("direction of B's centre from A's: along an axis (+x ... -z), a diagonal "
                 "of 2 or 3 axes with equal components, or oblique (any other)")
DIRECTIONS = {3: ("+x", "-x", "+y", "-y", "+z", "-z", "diag-2", "diag-3", "oblique"),
              2: ("+x", "-x", "+y", "-y", "diag-2", "oblique")}
OVERLAPS = ("-1e-1", "-1e-3", "-1e-6", "-1e-9", "-1e-12")
SEPARATIONS = ("+1e-12", "+1e-9", "+1e-6", "+1e-3", "+1e-1", "+1", "+10", "+1e3")
GAPS = ("deep", *OVERLAPS, "-ulp", "0", "+ulp", *SEPARATIONS)
GAP_DOC = ("signed gap relative to touching: B's centre at (1 + gap) times the touching "
           "displacement along its direction; deep: -0.3 or less (containment when sizes "
           "differ); +-ulp: within 10^-13.5 but not touching; 0: exact touching")
ULP_LIMIT = 10 ** -13.5
"""A relative gap of smaller magnitude (not zero) is at the ``ulp`` level."""
DEEP_LIMIT = -0.3
"""A relative gap at or below this is ``deep``."""
TOI_GAPS = ("-1e-1", "-ulp", "0", "+ulp", "+1e-6", "+1e-1", "+1", "+10", "+1e3")

SIZE_RATIO = _numeric("size_ratio", ("1", "10", "1e3", "1e6"),
                      "larger body's size over the smaller's (size: radius, largest half-width)")
ASPECT = _numeric("aspect", ("1", "10", "1e2", "1e4"),
                  "boxes: largest half-width over smallest, the more elongated body")
SCALE = _numeric("scale", ("1e-9", "1e-6", "1e-3", "1", "1e3", "1e6", "1e9"),
                 "the larger body's size")
OFFSET = Dimension("offset", ("0", "1", "1e3", "1e6", "1e9", "1e12", "1e15"),
                   "distance of A's centre from the origin (largest |coordinate|)",
                   (0.0, 1.0, 1e3, 1e6, 1e9, 1e12, 1e15))
OFFSET_AXES = {3: ("x", "y", "z", "many"), 2: ("x", "y", "many")}
OFFSET_AXIS_DOC = ("the axes A's centre is off the origin on: one axis, or many (offset 0 has "
                   "no level here)")
MASS_RATIO = _numeric("mass_ratio", ("1", "10", "1e3", "1e6", "1e12"),
                      "responses: larger mass over smaller")
SPEED = _numeric("speed", ("1e-3", "1", "1e3"), "relative speed |va - vb|")
RESTITUTION = Dimension("restitution", ("0", "0.5", "1"), "responses: coefficient of "
                        "restitution (nearest level)", (0.0, 0.5, 1.0))
ANGLE = Dimension("angle", ("0", "30", "60", "85"), "responses: degrees between the approach "
                  "velocity (A relative to B) and the line of centres; 0 is head-on",
                  (0.0, 30.0, 60.0, 85.0))
DURATION = _numeric("duration", ("1e-3", "1", "1e3"), "times of impact: the interval's length, s")

STRONG = ("direction", "gap", "size_ratio")
"""The dimensions a strength-3 design covers three at a time (the rest two at a time)."""
RESPONSE_STRONG = ("direction", "size_ratio", "mass_ratio")
"""A response's (it has no gap: its bodies are in contact)."""


def _geometry(dim: int, gaps: tuple[str, ...]) -> tuple[Dimension, ...]:
    return (Dimension("direction", DIRECTIONS[dim], DIRECTION_DOC),
            Dimension("gap", gaps, GAP_DOC), SIZE_RATIO)


def _place(dim: int) -> tuple[Dimension, ...]:
    return (SCALE, OFFSET, Dimension("offset_axis", OFFSET_AXES[dim], OFFSET_AXIS_DOC))


def _spaces() -> Iterator[Space]:
    for dim in (3, 2):
        yield Space(Kind.AABB, dim, (*_geometry(dim, GAPS), ASPECT, *_place(dim)))
        yield Space(Kind.SPHERE, dim, (*_geometry(dim, GAPS), *_place(dim)))
        yield Space(Kind.SPHERE_RESPONSE, dim,
                    (Dimension("direction", DIRECTIONS[dim], DIRECTION_DOC), SIZE_RATIO,
                     *_place(dim), MASS_RATIO, SPEED, RESTITUTION, ANGLE))
        yield Space(Kind.SPHERE_TOI, dim, (*_geometry(dim, TOI_GAPS), *_place(dim), SPEED,
                                           DURATION))


SPACES: dict[tuple[Kind, int], Space] = {(s.kind, s.dim): s for s in _spaces()}
"""Every kind's space, by (kind, dimension)."""


def space_of(kind: Kind, dim: int) -> Space | None:
    """The space of ``kind`` in ``dim`` dimensions (None: scenes, which are not pairs)."""
    return SPACES.get((kind, dim))


# --- placing a case ------------------------------------------------------------------------

def classify(case: AnyCase) -> Cell:
    """The cell of ``case``: its level on each dimension it can be placed on.

    Non-finite numbers, zero sizes and (responses) separating bodies leave the dimensions
    they make meaningless out; a scene has no cell.
    """
    space = space_of(case.kind_enum, case.dim)
    if space is None or not isinstance(case, AabbCase | SphereCase | ResponseCase | ToiCase):
        return {}
    numbers = [*case.a.center, *case.b.center, *_sizes(case.a), *_sizes(case.b)]
    if not all(math.isfinite(x) for x in numbers):
        return {}
    cell: Cell = {}
    for dimension in space.dimensions:
        level = _MEASURES[dimension.name](case, dimension)
        if level is not None:
            cell[dimension.name] = level
    return cell


def _sizes(body: object) -> tuple[float, ...]:
    half = getattr(body, "half", None)
    return tuple(half) if half is not None else (float(getattr(body, "radius")),)  # noqa: B009


def _size(body: object) -> float:
    return max(_sizes(body))


def _direction(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, AabbCase | SphereCase | ResponseCase | ToiCase)
    d = [Fraction(b) - Fraction(a) for a, b in zip(case.a.center, case.b.center, strict=True)]
    nonzero = [x for x in d if x != 0]
    if not nonzero:
        return None
    if len(nonzero) == 1:
        axis = next(i for i, x in enumerate(d) if x != 0)
        return ("+" if nonzero[0] > 0 else "-") + "xyz"[axis]
    if len({abs(x) for x in nonzero}) == 1:
        return f"diag-{len(nonzero)}"
    return "oblique"


def relative_gap(case: AnyCase) -> float | None:
    """The signed gap over the touching displacement along the centres' direction.

    Boxes: ``max_i |dc_i| / (ha_i + hb_i) - 1`` (exact, then rounded); spheres: the exact
    distance over ``ra + rb``.  None when the touching displacement is 0 or undefined.
    """
    if isinstance(case, AabbCase):
        dc = [abs(Fraction(b) - Fraction(a)) for a, b in zip(case.a.center, case.b.center,
                                                               strict=True)]
        sums = [Fraction(x) + Fraction(y) for x, y in zip(case.a.half, case.b.half, strict=True)]
        ratios = [d / s if s else (math.inf if d else Fraction(0)) for d, s in zip(dc, sums,
                                                                                  strict=True)]
        worst = max(ratios)
        return None if math.isinf(worst) else float(worst - 1)
    if not isinstance(case, SphereCase | ResponseCase | ToiCase):
        return None
    touch = case.a.radius + case.b.radius
    contact = exact.sphere_contact(case.a.center, case.a.radius, case.b.center, case.b.radius)
    distance = getattr(contact, "distance", None)
    return None if distance is None or not touch > 0 else float(distance) / touch


def gap_level(g: float, levels: Sequence[str]) -> str | None:
    """The level of relative gap ``g`` among ``levels`` (a kind's gap levels)."""
    if g == 0:
        return "0" if "0" in levels else None
    if abs(g) < ULP_LIMIT:
        token = ("+" if g > 0 else "-") + "ulp"
        return token if token in levels else None
    if g <= DEEP_LIMIT and "deep" in levels:
        return "deep"
    signed = [t for t in levels if t[0] == ("+" if g > 0 else "-") and "ulp" not in t]
    if not signed:
        return None
    return min(signed, key=lambda t: abs(math.log10(abs(float(t))) - math.log10(abs(g))))


def _gap(case: AnyCase, dimension: Dimension) -> str | None:
    g = relative_gap(case)
    return None if g is None else gap_level(g, dimension.levels)


def _size_ratio(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, AabbCase | SphereCase | ResponseCase | ToiCase)
    small, large = sorted((_size(case.a), _size(case.b)))
    return dimension.nearest(large / small) if small > 0 else None


def _aspect(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, AabbCase)
    ratios = [max(b.half) / min(b.half) if min(b.half) > 0 else math.inf
              for b in (case.a, case.b)]
    return None if math.isinf(max(ratios)) else dimension.nearest(max(ratios))


def _scale(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, AabbCase | SphereCase | ResponseCase | ToiCase)
    size = max(_size(case.a), _size(case.b))
    return dimension.nearest(size) if size > 0 else None


def _offset(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, AabbCase | SphereCase | ResponseCase | ToiCase)
    far = max(abs(x) for x in case.a.center)
    return "0" if far == 0 else min(dimension.levels[1:], key=lambda t: abs(
        math.log10(float(t)) - math.log10(far)))


def _offset_axis(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, AabbCase | SphereCase | ResponseCase | ToiCase)
    axes = [i for i, x in enumerate(case.a.center) if x != 0]
    if not axes:
        return None
    return "xyz"[axes[0]] if len(axes) == 1 else "many"


def _relative_velocity(case: AnyCase) -> list[float]:
    assert isinstance(case, ResponseCase | ToiCase)
    return [x - y for x, y in zip(case.a.velocity, case.b.velocity, strict=True)]


def _speed(case: AnyCase, dimension: Dimension) -> str | None:
    w = _relative_velocity(case)
    speed = math.hypot(*w)
    return dimension.nearest(speed) if speed > 0 and math.isfinite(speed) else None


def _angle(case: AnyCase, dimension: Dimension) -> str | None:
    """Degrees between A's velocity relative to B and the direction from A to B."""
    assert isinstance(case, ResponseCase)
    w = _relative_velocity(case)
    u = [b - a for a, b in zip(case.a.center, case.b.center, strict=True)]
    nw, nu = math.hypot(*w), math.hypot(*u)
    if not (nw > 0 and nu > 0 and math.isfinite(nw * nu)):
        return None
    cos = sum(x * y for x, y in zip(w, u, strict=True)) / (nw * nu)
    if cos <= 0:
        return None  # separating or sliding: no approach to place
    degrees = math.degrees(math.acos(min(1.0, cos)))
    return min(zip(dimension.levels, dimension.values, strict=True),
               key=lambda lv: abs(lv[1] - degrees))[0]


def _linear(attribute: str) -> Callable[[AnyCase, Dimension], str | None]:
    def measure(case: AnyCase, dimension: Dimension) -> str | None:
        x = float(getattr(case, attribute))
        return min(zip(dimension.levels, dimension.values, strict=True),
                   key=lambda lv: abs(lv[1] - x))[0] if math.isfinite(x) else None
    return measure


def _mass_ratio(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, ResponseCase)
    small, large = sorted((case.a.mass, case.b.mass))
    return dimension.nearest(large / small) if small > 0 and math.isfinite(large) else None


def _duration(case: AnyCase, dimension: Dimension) -> str | None:
    assert isinstance(case, ToiCase)
    return dimension.nearest(case.duration) if case.duration > 0 else None


_MEASURES: dict[str, Callable[[AnyCase, Dimension], str | None]] = {
    "direction": _direction, "gap": _gap, "size_ratio": _size_ratio, "aspect": _aspect,
    "scale": _scale, "offset": _offset, "offset_axis": _offset_axis, "speed": _speed,
    "mass_ratio": _mass_ratio, "restitution": _linear("restitution"), "angle": _angle,
    "duration": _duration,
}


def table_rows() -> Iterator[tuple[str, int, str, str, str]]:
    """(kind, dim, dimension, levels, meaning) for every dimension of every space."""
    for space in SPACES.values():
        for d in space.dimensions:
            yield space.kind.value, space.dim, d.name, ", ".join(d.levels), d.doc
