"""The adapter contract: what every engine adapter declares and does.

An adapter translates a Case into one engine's own API and the engine's
answer back into the harness's conventions (signed distance, gap positive;
unit normal from A to B).  ``prepare`` builds what the case needs and is not
timed; ``query`` does only the measured work.  An adapter declares:

- ``name`` (the report row; variants such as ``pybullet-default`` are separate
  adapters) and ``settings`` (what this variant configures);
- ``capabilities``: the (kind, dim) pairs it supports; anything else is a
  ``skip`` with the reason from :meth:`Adapter.unsupported`;
- ``conventions``: the engine's documented rules.  They feed the report's
  conventions table and the category of every disagreement.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, ClassVar

from crosscheck.core.model import Kind, Observation, quantities_of
from crosscheck.core.schema import AnyCase

Capability = tuple[Kind, int]

TEXTBOOK_TOUCHING: dict[str, bool] = {"sphere": False, "face": True, "edge": True,
                                      "corner": True}
"""The textbook's rule: touching boxes overlap (any feature); touching spheres do not collide."""
FEATURES = tuple(TEXTBOOK_TOUCHING)
"""Where two bodies meet: a sphere, or a box's face, edge or corner."""
SPEED_CAP_STAGES = ("", "step", "before restitution")
"""Where a declared speed cap acts (see :class:`Conventions`; '': no cap)."""


def all_capabilities(*kinds: Kind, dims: tuple[int, ...] = (2, 3)) -> frozenset[Capability]:
    """Every (kind, dim) pair for the given kinds."""
    return frozenset((k, d) for k in kinds for d in dims)


@dataclass(frozen=True, slots=True)
class Conventions:
    """An engine's documented rules, each with its source.

    ``touching`` maps a touching feature (``sphere``; ``face``, ``edge`` or
    ``corner`` for boxes) to whether the engine counts exact touching there as
    contact; a feature not listed follows the textbook (boxes touching
    overlap, spheres touching do not collide).  ``margins`` maps a feature to
    an absolute distance tolerance there (collision margin, GJK tolerance,
    slop); a feature not listed has none.  ``rtol`` is a relative tolerance
    (the engine's arithmetic precision), scaled by the case's size.
    ``restitution_threshold`` is the approach speed below which the engine
    makes a bounce perfectly inelastic (0: none); ``resolves_separating`` is
    False for engines that leave bodies which are already moving apart alone
    (the textbook formula exchanges momentum anyway).  ``time_step`` is the
    fixed step (s) in which the engine resolves a response (None: it does
    not step); ``damping`` a velocity damping the engine applies per second
    of simulated time in scenes (0: none).  ``zero_mass`` says how the engine
    reads a body of mass 0 (``"static"``: immovable, infinite mass; ``""``:
    as the textbook does), ``negative_extents`` how it reads a negative
    radius or half-width (``"absolute"``: as its magnitude; ``""``: rejects
    it or reads it literally, as the textbook does).  ``restitution_model``
    is ``"soft"`` for an engine with no coefficient of restitution, whose
    contact model sets the bounce (``""``: the case's e, as declared in
    ``restitution``); ``friction`` the Coulomb coefficient that acts between
    the bodies in responses (0: frictionless, as the textbook).  Both are read
    by :mod:`crosscheck.truth.contact_model`.

    What acts on which quantity (:mod:`crosscheck.truth.allowance`):
    ``verdict_margins`` maps a feature to a threshold that acts on the verdict
    alone (a prediction distance, a collision threshold, a polygon skin); None
    when the verdict has the same margins as lengths.  ``response_rtol`` is the
    precision of a response's velocities relative to the case's largest speed,
    where it is not the arithmetic ``rtol`` (a contact model solved to a
    measured precision; None: ``rtol``).  ``no_value`` names the declared
    configurations in which the engine gives no value (rules of
    :mod:`crosscheck.truth.no_value`): an answer without a value anywhere else
    is an ``error``.  ``max_speed`` is a speed cap (m/s; None: none) and
    ``max_speed_at`` where it acts: ``"step"`` on each body's velocity at the
    end of every step, ``"before restitution"`` after the contact solve and
    before the bounce is added.  ``sampled_contacts`` is True for an engine
    that looks for contacts only at the start of each step and pushes only
    bodies that overlap there (no continuous or predictive contact): a contact
    shorter than a step can fall between two steps.

    Times of impact (:mod:`crosscheck.truth.toi`): ``toi_target`` is the separation of
    the surfaces at which the engine's time-of-impact query stops (negative: an
    overlap; 0: touching, as the exact first contact), ``toi_tolerance`` how far from it
    the query may stop (its declared termination tolerance, a length) and
    ``toi_time_tolerance`` the same as a fraction of the interval (a solver that stops
    once its time step is that small); ``toi_min_centre_distance`` a distance between the
    centres closer than which the query never aims (Box2D: ``linearSlop``).  ``toi_samples``
    is 0 for a continuous query, or
    the number ``n`` of discrete tests at ``t = i T / (n - 1)`` that a sampling query makes
    (2: the interval's two ends); ``toi_end_excluded`` is True for a query that counts no
    contact exactly at the interval's end.

    Gravity and walls (:mod:`crosscheck.truth.scene_measures`): ``rest_gap`` is the band
    ``(lo, hi)`` of signed gaps (m; negative: penetration) at which the engine's contact
    model holds a sphere resting on a wall or on another sphere (its slop, skin or
    margin), from its documentation or source; ``rest_sink_steps`` how far below that band
    a resting sphere may sink because of the step, in units of ``|g| dt**2`` (an engine
    that integrates gravity before it resolves the contact); ``rest_sink_s2`` the same
    for a soft contact whose steady penetration is ``|g|`` times a time squared (s**2;
    MuJoCo's ``solref``).  ``sleeps`` is True for an engine that zeroes the velocity of a
    body at rest after a while (sleeping); ``wall_restitution`` says how a wall's bounce
    is set (``""``: with the scene's e, as between the spheres).
    """

    box_extents: str = "half"
    normal: str = "A to B"
    touching: dict[str, bool] = field(default_factory=dict)
    margins: dict[str, float] = field(default_factory=dict)
    rtol: float = 0.0
    restitution: str = "case value"
    restitution_threshold: float = 0.0
    resolves_separating: bool = True
    time_step: float | None = None
    damping: float = 0.0
    zero_mass: str = ""
    negative_extents: str = ""
    restitution_model: str = ""
    friction: float = 0.0
    verdict_margins: dict[str, float] | None = None
    response_rtol: float | None = None
    no_value: tuple[str, ...] = ()
    max_speed: float | None = None
    max_speed_at: str = ""
    sampled_contacts: bool = False
    toi_target: float = 0.0
    toi_tolerance: float = 0.0
    toi_time_tolerance: float = 0.0
    toi_min_centre_distance: float = 0.0
    toi_samples: int = 0
    toi_end_excluded: bool = False
    rest_gap: tuple[float, float] = (0.0, 0.0)
    rest_sink_steps: float = 0.0
    rest_sink_s2: float = 0.0
    sleeps: bool = False
    wall_restitution: str = ""
    notes: str = ""
    sources: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        if (self.max_speed is None) != (self.max_speed_at == ""):
            raise ValueError("max_speed and max_speed_at are declared together")
        if self.max_speed_at not in SPEED_CAP_STAGES:
            raise ValueError(f"max_speed_at {self.max_speed_at!r} not one of {SPEED_CAP_STAGES}")

    def margin_for(self, feature: str) -> float:
        """The declared distance tolerance at ``feature`` (0 where none is declared).

        >>> Conventions(margins={"face": 0.002}).margin_for("face")
        0.002
        >>> Conventions(margins={"face": 0.002}).margin_for("sphere")
        0.0
        """
        return self.margins.get(feature, 0.0)

    def verdict_margin_for(self, feature: str) -> float:
        """The declared threshold of the verdict at ``feature``: ``verdict_margins`` where
        declared, else the length margin.

        >>> Conventions(margins={"face": 1e-7}, verdict_margins={}).verdict_margin_for("face")
        0.0
        >>> Conventions(margins={"face": 1e-7}).verdict_margin_for("face")
        1e-07
        """
        if self.verdict_margins is None:
            return self.margin_for(feature)
        return self.verdict_margins.get(feature, 0.0)

    def touching_is_contact(self, feature: str) -> bool:
        """Whether the engine counts exact touching at ``feature`` as contact.

        >>> Conventions(touching={"sphere": True}).touching_is_contact("sphere")
        True
        >>> Conventions().touching_is_contact("edge")
        True
        """
        return self.touching.get(feature, TEXTBOOK_TOUCHING[feature])

    def touching_rule(self) -> str:
        """The touching rule in words, for the conventions table.

        >>> Conventions(touching={"edge": False}).touching_rule()
        'contact when touching: sphere no, face yes, edge NO, corner yes'
        """
        words = []
        for feature, textbook in TEXTBOOK_TOUCHING.items():
            rule = self.touching_is_contact(feature)
            word = "yes" if rule else "no"
            words.append(f"{feature} {word if rule == textbook else word.upper()}")
        return "contact when touching: " + ", ".join(words)


def describe(capabilities: frozenset[Capability]) -> list[str]:
    """Capabilities grouped by kind, e.g. ``['aabb 2-D/3-D', 'sphere 3-D']``.

    >>> describe(all_capabilities(Kind.SPHERE) | {(Kind.AABB, 3)})
    ['aabb 3-D', 'sphere 2-D/3-D']
    """
    dims: dict[str, list[int]] = {}
    for kind, dim in sorted(capabilities):
        dims.setdefault(str(kind), []).append(dim)
    return [f"{kind} {'/'.join(f'{d}-D' for d in ds)}" for kind, ds in dims.items()]


def import_problem(load: Callable[[], object], name: str) -> str | None:
    """Why an engine's module cannot be imported (None: it can), for :meth:`Adapter.available`.

    >>> import_problem(lambda: None, "fine") is None
    True
    >>> import_problem(lambda: __import__("no_such_engine_module"), "nosuch")
    "nosuch not importable: No module named 'no_such_engine_module'"
    """
    try:
        load()
    except ImportError as exc:
        return f"{name} not importable: {exc}"
    return None


HANG_PROBE_S = 0.25
"""Time limit for a case an adapter declares as a known hang (see Adapter.known_hang)."""


class Adapter(ABC):
    """Base class of every engine adapter (see the module docstring)."""

    name: ClassVar[str]
    engine: ClassVar[str]
    package: ClassVar[str] = ""
    """The distribution on the package index whose version the answers depend on (``pymunk``,
    ``mujoco-core``): ``crosscheck run --engine NAME@VERSION`` runs the variant with that
    version of it (:mod:`crosscheck.run.pinned`); "" for an engine that is not one."""
    settings: ClassVar[str] = "defaults"
    capabilities: ClassVar[frozenset[Capability]]
    conventions: ClassVar[Conventions]
    light_import: ClassVar[bool] = False
    """True when importing the adapter's module imports no engine library (the engine is
    imported by :meth:`available` or later): a run's engine workers are then forked from a
    process that imported the module already, so none pays for its imports again (a worker
    started per pair, as the repeat check's, costs tens of milliseconds less).  Leave it
    False unless sure: an engine imported there would be loaded in every engine's worker."""

    @abstractmethod
    def version(self) -> str:
        """The engine's version string."""

    def available(self) -> str | None:
        """None when the engine can run here, else the reason it cannot."""
        return None

    def unsupported(self, case: AnyCase) -> str | None:
        """The reason to skip ``case``, or None if the adapter supports it."""
        if (case.kind_enum, case.dim) in self.capabilities:
            return None
        return f"{self.name} does not support {case.kind} in {case.dim}-D"

    def known_hang(self, case: AnyCase) -> str | None:
        """Why the engine is known to hang on ``case`` (None: not known to).

        The case still runs, under :data:`HANG_PROBE_S` instead of the run's
        limit: a fixed engine answers in microseconds and its result is real,
        while a hang costs a fraction of a second instead of the full limit.
        If the probe times out, only :meth:`hanging_quantities` are recorded as
        ``timeout``; the others come from :meth:`query_without` them.
        """
        return None

    def hanging_quantities(self, case: AnyCase) -> frozenset[str]:
        """The quantities whose computation hangs on ``case`` (empty: none).

        By default every quantity of the case's kind when :meth:`known_hang` names a
        hang, else none.  An adapter that can answer the others without the hanging
        computation narrows this and overrides :meth:`query_without`.
        """
        if self.known_hang(case) is None:
            return frozenset()
        return frozenset(quantities_of(case.kind_enum))

    def query_without(self, prepared: Any, skip: frozenset[str]) -> Observation:
        """:meth:`query`, without computing the quantities in ``skip`` (reported absent).

        The default computes everything (:meth:`query`): an adapter that narrows
        :meth:`hanging_quantities` overrides it so that the skipped computations never
        start.  The runner calls it only after a declared hang timed out, and never with
        every quantity of the case skipped.
        """
        return self.query(prepared)

    binding_objects: ClassVar[tuple[str, ...]] = ()
    """The engine's shared objects, as patterns on their file names (``fnmatch``, such as
    ``"pybullet*.so"``), for the instruction-counting timer (``--timer instructions``).

    Under Valgrind's callgrind, a call from outside these objects into a function inside
    them is an entry point into the engine's binding; the instructions counted inside such
    calls (inclusive of what they call: the library, libc, allocations) are the engine's own
    work, and the rest of a query's count is the harness's Python path.  Empty: the adapter
    names no binding (pure Python), and only the whole query is counted.
    """

    def binding_call(self) -> Callable[[], object] | None:
        """The cheapest call into the engine's Python binding (None: no binding, pure Python).

        The timing phase times it beside every query, so the report can show how
        much of an engine's per-call time is crossing into the engine at all.
        """
        return None

    @abstractmethod
    def prepare(self, case: AnyCase) -> Any:
        """Build only what ``case`` needs (untimed)."""

    @abstractmethod
    def query(self, prepared: Any) -> Observation:
        """Do the measured work on a prepared case and report in harness conventions."""

    def release(self, prepared: Any) -> None:  # noqa: B027 - optional hook, empty by default
        """Free what :meth:`prepare` built (optional)."""

    def observe(self, case: AnyCase) -> Observation:
        """One untimed prepare, query and release, in this process (tests, exploration)."""
        prepared = self.prepare(case)
        try:
            return self.query(prepared)
        finally:
            self.release(prepared)


def engine_info(adapter: Adapter) -> dict[str, object]:
    """Everything a run records about an adapter (run.json, the conventions table)."""
    return {"name": adapter.name, "engine": adapter.engine, "version": adapter.version(),
            "settings": adapter.settings, "available": adapter.available() or "yes",
            "capabilities": describe(adapter.capabilities),
            "conventions": asdict(adapter.conventions),
            "touching_rule": adapter.conventions.touching_rule()}
