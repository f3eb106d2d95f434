"""The value types that flow through the harness: kinds, outcomes, observations and records.

Everything here is small, typed and immutable.  A :class:`Observation` is what
an engine (or the exact oracle) says about one case; a :class:`Record` is one
tidy row of the results table: one case x engine x quantity.  :class:`Kind`,
:func:`quantities_of` and the kind lists are those of :mod:`crosscheck.core.kinds` (one spec
per kind), named here too for the modules that import them with the other values.

>>> obs = Observation(hit=True, distance=-0.25, normal=(1.0, 0.0, 0.0))
>>> obs.get("distance")
-0.25
>>> obs.get("v1") is None
True
>>> quantities_of(Kind.SPHERE_RESPONSE)
('v1', 'v2')
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from enum import StrEnum
from typing import Literal, get_args

from crosscheck.core.geometry import Vec
from crosscheck.core.kinds import NEW_CASE_KINDS, PAIR_KINDS, Kind, quantities_of
from reference_impl.types import Undefined

__all__ = [
    "NEW_CASE_KINDS",
    "PAIR_KINDS",
    "Category",
    "Kind",
    "Observation",
    "Record",
    "Status",
    "Undefined",
    "Value",
    "quantities_of",
]


class Status(StrEnum):
    """Outcome of one case x engine x quantity, and the classes every module judges it by.

    - *scored*: compared with the truth (agree, disagree); the row has an error;
    - *failed*: the engine gave no answer (error, crash, timeout);
    - *neutral*: neither right nor wrong (skip, undefined);
    - *breaking*: the answer is wrong or missing (disagree or failed);
    - *judged*: counted in an agreeing share (agree or breaking: not neutral);
    - *failed_or_skipped*: no answer to time (failed, or skip: not asked);
    - ``severity``: 0 for the worst (crash) to 6 for agree, the report's order.

    Modules ask these classes here, at the call site (``status.failed``, or
    ``frame["status"].isin(Status.members("failed"))`` for a column of values); none
    keeps a copy of its own.

    >>> Status.TIMEOUT.failed, Status.TIMEOUT.breaking, Status.SKIP.neutral
    (True, True, True)
    >>> Status.members("breaking")
    ('disagree', 'error', 'crash', 'timeout')
    >>> Status.members("judged"), Status.members("failed_or_skipped")
    (('agree', 'disagree', 'error', 'crash', 'timeout'), ('skip', 'error', 'crash', 'timeout'))
    >>> sorted(Status, key=lambda s: s.severity)[:3]
    [<Status.CRASH: 'crash'>, <Status.TIMEOUT: 'timeout'>, <Status.ERROR: 'error'>]
    """

    AGREE = "agree"
    DISAGREE = "disagree"
    UNDEFINED = "undefined"
    SKIP = "skip"
    ERROR = "error"
    CRASH = "crash"
    TIMEOUT = "timeout"

    @property
    def scored(self) -> bool:
        """Compared with the truth: the row carries an error and a tolerance."""
        return self in (Status.AGREE, Status.DISAGREE)

    @property
    def failed(self) -> bool:
        """The engine gave no answer: it raised, its worker died or it hung."""
        return self in (Status.ERROR, Status.CRASH, Status.TIMEOUT)

    @property
    def neutral(self) -> bool:
        """Neither right nor wrong: not asked (skip) or no defined value (undefined)."""
        return self in (Status.SKIP, Status.UNDEFINED)

    @property
    def breaking(self) -> bool:
        """Wrong or missing: what a disagreement list, a threshold or a finding counts."""
        return self is Status.DISAGREE or self.failed

    @property
    def judged(self) -> bool:
        """Counted in an agreeing share: agree, or wrong or missing (not neutral)."""
        return not self.neutral

    @property
    def failed_or_skipped(self) -> bool:
        """No answer to time: the engine failed, or was not asked (skip)."""
        return self.failed or self is Status.SKIP

    @property
    def severity(self) -> int:
        """0 (crash) ... 6 (agree): most severe first, as the report sorts rows."""
        return _SEVERITY.index(self)

    @classmethod
    def members(cls, kind: StatusClass) -> tuple[str, ...]:
        """The values of the statuses of one class, in declaration order (for ``isin`` and
        ``in``; computed once per class)."""
        return _MEMBERS[kind]


StatusClass = Literal["scored", "failed", "neutral", "breaking", "judged", "failed_or_skipped"]
"""The classes of :class:`Status` (each a property of it)."""

_SEVERITY = (Status.CRASH, Status.TIMEOUT, Status.ERROR, Status.DISAGREE, Status.UNDEFINED,
             Status.SKIP, Status.AGREE)
_MEMBERS: dict[str, tuple[str, ...]] = {
    kind: tuple(str(s) for s in Status if getattr(s, kind))
    for kind in get_args(StatusClass)}


class Category(StrEnum):
    """Why a ``disagree`` happened, judged from the adapter's declared conventions.

    ``severity`` ranks them, 0 for the worst: an unexplained ``error``, then ``timestep``
    (off by a discrete step's lag), ``convention`` (a declared convention) and ``tolerance``
    (within the engine's declared tolerance), the mildest.  It is the one order of
    categories: every module that sorts or colours disagreements by category asks it here.

    >>> [str(c) for c in sorted(Category, key=lambda c: c.severity)]
    ['error', 'timestep', 'convention', 'tolerance']
    """

    CONVENTION = "convention"
    TOLERANCE = "tolerance"
    TIMESTEP = "timestep"
    ERROR = "error"

    @property
    def severity(self) -> int:
        """0 (error, unexplained) ... 3 (tolerance): most severe first."""
        return _CATEGORY_SEVERITY.index(self)


_CATEGORY_SEVERITY = (Category.ERROR, Category.TIMESTEP, Category.CONVENTION, Category.TOLERANCE)


Value = bool | float | Vec | tuple[Vec, ...] | Undefined
"""One reported quantity: a verdict, a distance, a vector (or one per body), or Undefined."""


@dataclass(frozen=True, slots=True)
class Trajectory:
    """A scene's recorded states: every body's centre and velocity at ``times``.

    ``energy`` is the total energy at each time (kinetic plus ``-m g . (x - x0)``).
    """

    times: tuple[float, ...]
    positions: tuple[tuple[Vec, ...], ...]
    velocities: tuple[tuple[Vec, ...], ...]
    energy: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Observation:
    """What one engine (or the oracle) reports for one case, in the harness's conventions.

    Any quantity may be an explicit :class:`Undefined` (no defined value).
    ``distance`` is signed (gap positive), ``normal`` is a unit vector from A to
    B.  A quantity the engine cannot give is ``None`` (absent), never faked.
    """

    hit: bool | Undefined | None = None
    """Detection: the bodies collide; time of impact: they touch within the interval."""
    distance: float | Undefined | None = None
    normal: Vec | Undefined | None = None
    """Unit vector from A to B (time of impact: from A's centre to B's at the contact time)."""
    toi: float | Undefined | None = None
    """Time of impact: the first contact time in the case's interval (seconds from its start)."""
    v1: Vec | Undefined | None = None
    v2: Vec | Undefined | None = None
    resolved_at: tuple[Vec, Vec] | None = None
    """For responses: the centres of A and B at the start of the first step in which the
    engine reported a contact between A and B, the configuration its solver resolved
    (an engine that integrates positions before detecting, as pymunk does, reports the
    centres it detected at).  None when no step reported a contact.  Not the step where
    the bodies stopped approaching, which may come later.

    When given, the truth is also computed at these positions (with the case's
    velocities), so a discrete step that resolves the contact later than the touching
    configuration is told apart from an error."""
    positions: tuple[Vec, ...] | Undefined | None = None
    """Scenes: every body's final centre."""
    velocities: tuple[Vec, ...] | Undefined | None = None
    momentum: Vec | Undefined | None = None
    energy: float | Undefined | None = None
    wall_s: float | None = None
    """Scenes: wall-clock seconds of the stepping loop alone (the scene's timing)."""
    impacts: tuple[float, ...] | None = None
    """Scenes (the exact reference only): the times of the impacts the exact run resolved."""
    settle: Vec | Undefined | None = None
    """Scenes with a ground: every body's signed gap to the ground at the end (m)."""
    jitter: float | Undefined | None = None
    """Scenes with a ground: the largest speed of any body over the run's second half (m/s)."""
    energy_drift: float | Undefined | None = None
    """Scenes: the change of total energy (kinetic, plus potential under gravity) from the
    start to the end, per second, over the initial total energy (1/s)."""
    apex: Vec | Undefined | None = None
    """Scenes with a ground: body 0's apex heights above the ground between bounces (m)."""
    bounce_time: Vec | Undefined | None = None
    """Scenes with a ground: the times of body 0's bounces on the ground (s)."""
    divergence: float | Undefined | None = None
    """Scenes: the first recorded time at which a centre is further from the exact one than
    the stated tolerance (s; the simulated time when it never is)."""
    trajectory: Trajectory | None = None
    """Scenes: the recorded states the measures are read from (not a quantity, not stored)."""

    def get(self, quantity: str) -> Value | None:
        """The value of ``quantity`` (one of :func:`quantities_of`), or None if absent."""
        value: Value | None = getattr(self, quantity)
        return value

    @classmethod
    def undefined(cls, quantities: tuple[str, ...], reason: str) -> Observation:
        """An observation in which every quantity is Undefined for ``reason``."""
        values: dict[str, Value] = {q: Undefined(reason) for q in quantities}
        return cls(**values)  # type: ignore[arg-type]


@dataclass(frozen=True, slots=True)
class Record:
    """One tidy row of ``results.csv``: one case x engine x quantity.

    ``value`` and ``truth`` are JSON text (exact float round trip); missing
    numbers are NaN, never a sentinel.
    """

    case_id: str
    source: str
    kind: str
    dim: int
    tags: str
    engine: str
    quantity: str
    value: str
    truth: str
    error: float
    tolerance: float
    status: Status
    category: str
    reason: str
    setup_s: float
    query_s: float
    query_iqr_s: float
    loops: int
    unstable: bool
    origin: str = ""
    """The block the case was expanded from ('' for a plain block): a sweep or a scene."""
    coords: str = ""
    """The case's sweep (or scene step) coordinates as JSON text, e.g. '{"gap": 1e-09}'."""
    twin_of: str = ""
    """For an A/B-swapped twin, the id of the case it mirrors."""
    error_at_contact: float = math.nan
    """Responses: the error against the truth at the centres where the engine first reported
    the contact (NaN when it reported none elsewhere than the case's own centres)."""

    def row(self) -> dict[str, object]:
        """The record as a plain dict, ready for a DataFrame or CSV writer (its line in
        ``results.jsonl`` is :func:`crosscheck.results.rows.line`: this dict as json.dumps
        writes it)."""
        # every field is a scalar: no deep copy (asdict is ~20x slower, once per record)
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["status"] = str(self.status)
        return out


COLUMNS: tuple[str, ...] = tuple(Record.__dataclass_fields__)
"""The columns of results.csv, in order."""
