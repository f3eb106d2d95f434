"""What a case asks, one spec per kind: its quantities and every fact the harness keeps of them.

A :class:`KindSpec` holds what the harness knows of a kind as data: the quantities scored for
it, each a :class:`Quantity` (the unit its error is measured in, whether its value scales with
the bodies, its column in ``summary.csv``, its chart labels, its unit in a reason's words); the
headline quantity of the stability study (and what to show when the headline has no verdict);
the panels of its speed-against-error chart; what the conformance kit requires of an
observation; the limits of ``advise``'s envelope that bound it; the families fuzz draws it
from; whether it is a pair kind and whether ``new-case`` writes it; and the names by which the
layers above find its case schema class (:func:`crosscheck.core.schema.case_class`), its exact
truth and its judge (:data:`crosscheck.truth.oracle.TRUTHS`, :data:`crosscheck.truth.score.JUDGES`,
one table each, keyed by these names).  :data:`SPECS` lists them in report order; every module
asks here (:func:`spec`, :func:`quantities_of`, :func:`quantity_named`) and keeps no table of
kinds of its own (``tests/core/test_kinds.py`` checks).  A new kind is this spec, its schema
class and, unless it shares one, its truth and judge; what differs in behaviour (its kit
samples, the bodies ``new-case`` writes, its configuration space) stays code where it runs.

The spec names the schema class instead of holding it: this module imports only the standard
library, because the CLI's parser (``crosscheck --help``) reads the kinds it offers here
(:data:`NEW_CASE_KINDS`) and must not load pydantic.

Two sets of "lengths" are kept apart on purpose: :attr:`Quantity.unit` is the unit of the
*error* (``advise`` judges it with the tolerance of that unit: a scene's ``positions`` error is
a share of the mean radius, so its unit is :data:`FRACTION`), while :attr:`Quantity.length` says
the *value* is in metres and scales with the bodies (a resized scene's ``positions`` are divided
by the scale before they are compared: :mod:`crosscheck.report.metamorphic`).

>>> quantities_of(Kind.SPHERE_RESPONSE)
('v1', 'v2')
>>> spec("sphere").headline, spec("sphere").fallback, spec(Kind.SPHERE_TOI).quantity("toi").unit
('distance', 'hit', 's')
>>> [str(s.kind) for s in SPECS]
['aabb', 'sphere', 'sphere_response', 'sphere_toi', 'sphere_scene']
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Literal

__all__ = [
    "ANGLE",
    "FRACTION",
    "KIND_ORDER",
    "LENGTH",
    "NEW_CASE_KINDS",
    "PAIR_KINDS",
    "SPECS",
    "TIME",
    "VELOCITY",
    "Kind",
    "KindSpec",
    "Quantity",
    "SpeedPanels",
    "error_columns",
    "every_quantity",
    "is_kind",
    "quantities_of",
    "quantity_named",
    "spec",
]


class Kind(StrEnum):
    """What a case asks: box overlap, sphere detection, sphere response, a stepped scene, or
    the first contact time of two spheres in linear motion (time of impact)."""

    AABB = "aabb"
    SPHERE = "sphere"
    SPHERE_RESPONSE = "sphere_response"
    SPHERE_SCENE = "sphere_scene"
    SPHERE_TOI = "sphere_toi"


LENGTH, ANGLE, VELOCITY, TIME, FRACTION = "m", "rad", "m/s", "s", "fraction"
"""The units of the quantities' errors: ``fraction`` is a share of the quantity's own scale (a
scene's positions in mean radii, its velocities of the largest initial speed, its energy drift
of the energy scale per second: :attr:`Quantity.words`)."""


@dataclass(frozen=True, slots=True)
class Quantity:
    """One quantity an observation carries, the same in every kind that scores it."""

    name: str
    unit: str
    """The unit its error is measured in (a ``hit`` verdict is judged by the pair's exact
    |gap|, a length): ``advise`` judges it with the tolerance of this unit."""
    length: bool = False
    """Its value is in metres and scales with the bodies (a resized scene's value is divided
    by the scale before it is compared with the origin's)."""
    error_column: str | None = None
    """Its column in the summary (``summary.csv``): one measure each, never mixed."""
    label: str = ""
    """Its name on the speed-against-error charts (empty: its name)."""
    relative_to: Literal["length", "velocity"] | None = None
    """The case's scale its error is divided by in the stability study (None: as is)."""
    relative_label: str = ""
    """The y axis of its stability charts: its error, as the study plots it."""
    words: str = ""
    """A scene's: the unit of its error in a reason, in words (its unit, or the scale it is a
    share of: ``mean radii``), as the scene rules write it (:mod:`crosscheck.truth.scenes`)."""
    absolute: str = ""
    """A scene's final state: the unit of its error where its scale is 0 (every body at rest at
    the start and no fall to speed it: the error is then absolute)."""

    @property
    def title(self) -> str:
        """Its name on a chart: :attr:`label`, else its name."""
        return self.label or self.name


@dataclass(frozen=True, slots=True)
class SpeedPanels:
    """What the speed-against-error chart of a kind plots: one panel per error quantity, and
    the quantities whose verdicts it counts."""

    errors: tuple[str, ...]
    verdicts: tuple[str, ...]
    verdict_label: str


HIT = Quantity("hit", LENGTH, error_column="wrong_verdicts")
DISTANCE = Quantity("distance", LENGTH, length=True, error_column="distance_error",
                    label="signed distance", relative_to="length",
                    relative_label="|distance error| / length scale")
NORMAL = Quantity("normal", ANGLE, error_column="normal_angle", label="normal (angle)",
                  relative_label="normal error (radians)")
TOI = Quantity("toi", TIME, label="time of impact", relative_label="|time of impact error| (s)")
V1, V2 = (Quantity(v, VELOCITY, error_column="velocity_error", label=f"velocity {v}",
                   relative_to="velocity", relative_label=f"|{v} error| / velocity scale")
          for v in ("v1", "v2"))
POSITIONS = Quantity("positions", FRACTION, length=True, error_column="position_error",
                     words="mean radii", absolute="m")
VELOCITIES = Quantity("velocities", FRACTION, words="of the largest initial speed",
                      absolute="m/s", relative_label="velocity error / largest initial speed")
MOMENTUM = Quantity("momentum", FRACTION, words="of sum m|v|", absolute="kg m/s")
ENERGY = Quantity("energy", FRACTION, words="of the initial kinetic energy", absolute="J")
SCENE_MEASURES = (Quantity("settle", LENGTH, length=True, words="m"),
                  Quantity("jitter", VELOCITY, words="m/s"),
                  Quantity("energy_drift", FRACTION, words="of the energy scale per s"),
                  Quantity("apex", FRACTION, length=True, words="(relative)"),
                  Quantity("bounce_time", TIME, words="s"),
                  Quantity("divergence", FRACTION, words="of the run"))


@dataclass(frozen=True, slots=True)
class KindSpec:
    """Everything the harness keeps of one kind (module docstring)."""

    kind: Kind
    case: str
    """The name of its case schema class in :mod:`crosscheck.core.schema`."""
    quantities: tuple[Quantity, ...]
    """The quantities scored, in report order."""
    truth: str
    """The name of its exact truth in :data:`crosscheck.truth.oracle.TRUTHS`."""
    judge: str
    """The name of its judge in :data:`crosscheck.truth.score.JUDGES`."""
    required: tuple[str, ...]
    """The quantities an observation of it always carries (the conformance kit checks)."""
    charted: tuple[str, ...]
    """The quantities the stability study charts, its headline (:attr:`headline`) first."""
    fallback: str | None = None
    """What the stability study's threshold table shows for an engine whose headline has no
    verdict on a walk (None: nothing else)."""
    speed: SpeedPanels | None = None
    """Its speed-against-error chart (None: it has none)."""
    extras: frozenset[str] = frozenset()
    """Observation fields besides its quantities that an adapter may set."""
    pair: bool = False
    """A two-body kind at one instant: what fuzz makes and the columnar scoring judges."""
    limits: tuple[str, ...] = ()
    """The dimensions of ``advise``'s envelope its cases have besides size and place (e.g.
    ``speed``, ``dt``): a limit on one bounds its cases (:mod:`crosscheck.report.advise.units`)."""
    fuzz: tuple[str, ...] = ()
    """The families fuzz draws its cases from besides the configuration space (empty: the
    space alone): :mod:`crosscheck.studies.fuzz.generator`."""
    new_case: bool = False
    """``crosscheck new-case`` writes it."""

    @property
    def names(self) -> tuple[str, ...]:
        """The names of its quantities, in report order."""
        return tuple(q.name for q in self.quantities)

    @property
    def headline(self) -> str:
        """The quantity the stability study's threshold table shows for it."""
        return self.charted[0]

    def quantity(self, name: str) -> Quantity:
        """Its quantity called ``name`` (KeyError: it scores none)."""
        for q in self.quantities:
            if q.name == name:
                return q
        raise KeyError(f"{self.kind} has no quantity {name!r}")


DETECTION = SpeedPanels(("distance", "normal"), ("hit",), "wrong hit verdicts")
SHAPES = ("near-touching", "scaled", "offset")

SPECS: tuple[KindSpec, ...] = (
    KindSpec(Kind.AABB, "AabbCase", (HIT, DISTANCE, NORMAL), truth="box contact",
             judge="pair", required=("hit",), charted=("distance", "normal"), fallback="hit",
             speed=DETECTION, limits=("touching_contact",), pair=True, fuzz=SHAPES,
             new_case=True),
    KindSpec(Kind.SPHERE, "SphereCase", (HIT, DISTANCE, NORMAL), truth="sphere contact",
             judge="pair", required=("hit",), charted=("distance", "normal"), fallback="hit",
             speed=DETECTION, limits=("touching_contact",), pair=True, fuzz=SHAPES,
             new_case=True),
    KindSpec(Kind.SPHERE_RESPONSE, "ResponseCase", (V1, V2), truth="response", judge="pair",
             required=("v1", "v2"), charted=("v2",),
             speed=SpeedPanels(("v1", "v2"), ("v1", "v2"),
                               "cases with a velocity beyond tolerance"),
             limits=("speed", "mass_ratio"), extras=frozenset({"resolved_at"}), pair=True,
             fuzz=("mass-ratio", *SHAPES), new_case=True),
    KindSpec(Kind.SPHERE_TOI, "ToiCase", (HIT, TOI, NORMAL), truth="time of impact",
             judge="time of impact", required=("hit",), charted=("toi", "normal"),
             speed=SpeedPanels(("toi", "normal"), ("hit",), "wrong contact verdicts"),
             limits=("speed", "interval"), new_case=True),
    KindSpec(Kind.SPHERE_SCENE, "SceneCase",
             (POSITIONS, VELOCITIES, MOMENTUM, ENERGY, *SCENE_MEASURES),
             truth="scene", judge="scene", required=("positions", "velocities"),
             charted=("velocities",),
             limits=("speed", "mass_ratio", "duration", "dt", "step_travel"),
             extras=frozenset({"wall_s", "impacts", "trajectory"})),
)
"""One spec per kind, in report order (the verdict block's columns)."""

_BY_KIND = {s.kind: s for s in SPECS}
_BY_NAME = {q.name: q for s in SPECS for q in s.quantities}
KIND_ORDER = tuple(str(s.kind) for s in SPECS)
"""The kinds in report order."""
PAIR_KINDS = tuple(str(s.kind) for s in SPECS if s.pair)
"""The two-body kinds at one instant: what fuzz makes."""
NEW_CASE_KINDS = tuple(str(s.kind) for s in SPECS if s.new_case)
"""The kinds ``crosscheck new-case`` writes: every two-body kind (scenes are written by hand)."""


def is_kind(name: str) -> bool:
    """Whether ``name`` is a kind's value.

    >>> is_kind("sphere"), is_kind("box")
    (True, False)
    """
    return name in KIND_ORDER


def spec(kind: Kind | str) -> KindSpec:
    """The spec of ``kind`` (a :class:`Kind` or its value; ValueError: no such kind)."""
    return _BY_KIND[Kind(kind)]


def quantities_of(kind: Kind | str) -> tuple[str, ...]:
    """The quantities scored for a kind, in report order."""
    return spec(kind).names


def every_quantity() -> tuple[Quantity, ...]:
    """Every quantity of every kind, once each, in report order."""
    return tuple(_BY_NAME.values())


def error_columns() -> dict[str, tuple[str, ...]]:
    """The summary's error columns, in report order, each with the quantities it measures.

    >>> error_columns()["velocity_error"], list(error_columns())[:2]
    (('v1', 'v2'), ['wrong_verdicts', 'distance_error'])
    """
    columns = dict.fromkeys(q.error_column for q in every_quantity() if q.error_column)
    return {c: tuple(q.name for q in every_quantity() if q.error_column == c) for c in columns}


def quantity_named(name: str) -> Quantity:
    """The quantity called ``name``, the same in every kind that scores it (KeyError: none
    does).

    >>> quantity_named("v2").relative_to, quantity_named("settle").length
    ('velocity', True)
    """
    return _BY_NAME[name]
