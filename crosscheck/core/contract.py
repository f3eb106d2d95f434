"""The adapter contract: what every engine adapter declares and does.

An adapter translates a Case into one engine's own API and the engine's
answer back into the harness's conventions (signed distance, gap positive;
unit normal from A to B).  ``prepare`` builds what the case needs and is not
timed; ``query`` does only the measured work.  An adapter declares:

- ``name`` (the report row; variants such as ``pybullet-default`` are separate
  adapters) and ``settings`` (what this variant configures);
- ``capabilities``: the (kind, dim) pairs it supports; anything else is a
  ``skip`` with the reason from :meth:`Adapter.unsupported`;
- ``conventions``: the engine's documented rules
  (:class:`~crosscheck.core.conventions.Conventions`, re-exported here).  They feed the
  report's conventions table and the category of every disagreement.

A built-in engine is a :class:`CallsAdapter`: its engine calls are a module of plain
functions of plain data (``adapters/<engine>/calls.py``, named by ``calls``), and the
adapter says, per kind family (the protocols :class:`Pairs`, :class:`Responses`,
:class:`Scenes`, :class:`Impacts`), which :class:`Call` a case is.  ``prepare`` and
``query`` dispatch on the case's kind once, here; a repro script is that module's source
with the call's exact inputs (:mod:`crosscheck.studies.repro`).
"""

from __future__ import annotations

import importlib
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from types import ModuleType
from typing import Any, ClassVar, Protocol, runtime_checkable

from crosscheck.core.claims import Claim
from crosscheck.core.conventions import (
    FEATURES,
    SPEED_CAP_STAGES,
    TEXTBOOK_TOUCHING,
    Conventions,
    Nature,
    nature_of,
)
from crosscheck.core.model import Kind, Observation, Undefined, Value, quantities_of
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SceneCase, SphereCase, ToiCase

__all__ = ["FEATURES", "HANG_PROBE_S", "SPEED_CAP_STAGES", "TEXTBOOK_TOUCHING", "Adapter",
           "Answer", "Call", "CallsAdapter", "Capability", "Conventions", "Impacts", "Nature",
           "Pairs", "Prepared", "Responses", "Scenes", "all_capabilities", "describe",
           "engine_info", "import_problem", "nature_of", "observation_of", "pair_inputs",
           "refused"]

Capability = tuple[Kind, int]

def all_capabilities(*kinds: Kind, dims: tuple[int, ...] = (2, 3)) -> frozenset[Capability]:
    """Every (kind, dim) pair for the given kinds."""
    return frozenset((k, d) for k in kinds for d in dims)


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
    claims: ClassVar[tuple[Claim, ...]] = ()
    supersedes: ClassVar[str] = ""
    """The variant of the engine's earlier major version this one replaces (``box2d3``:
    ``box2d``): a run holding both shows what changed from it to this one, by failure mode
    (the report's version section, ``crosscheck compare RUN --from OLD --to NEW``); "" for
    none."""
    """The engine's published accuracy claims (:mod:`crosscheck.core.claims`): checked
    against the measurement in the report and ``crosscheck engines --claims``, never used
    as an allowance."""
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
    """Everything a run records about an adapter (run.json, the conventions table; ``claims``:
    its published accuracy claims, :meth:`Claim.to_json` each)."""
    return {"name": adapter.name, "engine": adapter.engine, "version": adapter.version(),
            "settings": adapter.settings, "available": adapter.available() or "yes",
            "capabilities": describe(adapter.capabilities),
            "conventions": asdict(adapter.conventions),
            "touching_rule": adapter.conventions.touching_rule(),
            "supersedes": adapter.supersedes,
            "claims": [claim.to_json() for claim in adapter.claims]}


Answer = Mapping[str, Any]
"""A call's plain answer: quantity -> bool, float, tuple of floats (of tuples, per body), a
``str`` (no defined value: the reason) or None (the engine gives none); also
``resolved_at`` (a response's centres of A and B where it resolved the contact)."""


@dataclass(frozen=True)
class Call:
    """One case as calls into an engine's calls module, with plain inputs (floats, tuples).

    ``build(**inputs)`` makes the engine's objects (in ``prepare``, untimed);
    ``ask(built)`` is the measured call (in ``query``) and returns an :data:`Answer`;
    ``release(built)``, if named, frees what ``build`` made.  A repro script makes exactly
    these calls on exactly these inputs.

    ``partial``, if named, is the ask without the quantities the adapter declares hanging on
    the case (:meth:`Adapter.hanging_quantities`; the runner's :meth:`Adapter.query_without`).
    ``refusal``, if given, is the exception ``prepare`` raises instead of asking the engine (an
    input it would take without a word; a script raises it too, unless told to ask anyway:
    :func:`refused` makes one); ``undefined``, if
    given, is why it is not asked and every quantity is Undefined for that reason instead.
    """

    build: str
    ask: str
    inputs: Mapping[str, Any] = field(default_factory=dict)
    release: str = ""
    partial: str = ""
    refusal: Exception | None = None
    undefined: str = ""
    model: str = ""
    """The engine's own model text among the inputs (MuJoCo's MJCF), shown apart in a bug
    report; '' if none."""


def pair_inputs(case: AabbCase | SphereCase) -> dict[str, Any]:
    """A detection case's bodies as a call's plain inputs: ``a_center`` with ``a_half`` (boxes)
    or ``a_radius`` (spheres), then B's; an engine adds its own settings beside them."""
    if isinstance(case, AabbCase):
        return {"a_center": case.a.center, "a_half": case.a.half,
                "b_center": case.b.center, "b_half": case.b.half}
    return {"a_center": case.a.center, "a_radius": case.a.radius,
            "b_center": case.b.center, "b_radius": case.b.radius}


def response_inputs(case: ResponseCase) -> dict[str, Any]:
    """A response case's bodies and restitution as a call's plain inputs: A's centre, radius,
    mass and velocity, then B's, then ``restitution``; an engine adds its own settings."""
    a, b = case.a, case.b
    return {"a_center": a.center, "a_radius": a.radius, "a_mass": a.mass,
            "a_velocity": a.velocity, "b_center": b.center, "b_radius": b.radius,
            "b_mass": b.mass, "b_velocity": b.velocity, "restitution": case.restitution}


def refused(why: str | None) -> Exception | None:
    """A :class:`Call`'s ``refusal``: ``ValueError(why)``, or None when ``why`` is empty.

    >>> refused(""), refused("negative radius")
    (None, ValueError('negative radius'))
    """
    return ValueError(why) if why else None


@runtime_checkable
class Pairs(Protocol):
    """Detection (``aabb``, ``sphere``): a call per pair of bodies at one instant."""

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """The call that detects ``case``'s pair."""


@runtime_checkable
class Responses(Protocol):
    """Collision response (``sphere_response``): a call that resolves one impact."""

    def response_call(self, case: ResponseCase) -> Call:
        """The call that resolves ``case``'s impact."""


@runtime_checkable
class Scenes(Protocol):
    """Scenes (``sphere_scene``): a call that steps a world of spheres."""

    def scene_call(self, case: SceneCase) -> Call:
        """The call that steps ``case``'s scene."""


@runtime_checkable
class Impacts(Protocol):
    """Times of impact (``sphere_toi``): a call for the first contact of two moving spheres."""

    def toi_call(self, case: ToiCase) -> Call:
        """The call that finds ``case``'s first contact."""


def observation_of(answer: Answer) -> Observation:
    """An :class:`Observation` of a plain answer (a ``str`` is an Undefined's reason).

    >>> seen = observation_of({"hit": True, "distance": -0.5, "normal": "coincident centres"})
    >>> seen.hit, seen.normal, seen.v1
    (True, Undefined(reason='coincident centres'), None)
    """
    values: dict[str, Value | None] = {
        q: Undefined(v) if isinstance(v, str) else v for q, v in answer.items()}
    return Observation(**values)  # type: ignore[arg-type]


@dataclass(frozen=True, slots=True)
class Prepared:
    """What :meth:`CallsAdapter.prepare` built: the call, the engine's objects, its ask."""

    call: Call
    built: Any
    ask: Callable[[Any], Answer]
    module: ModuleType


class CallsAdapter(Adapter):
    """An adapter whose engine calls are the plain functions of one module (``calls``).

    It implements the kind families it supports (:class:`Pairs`, :class:`Responses`,
    :class:`Scenes`, :class:`Impacts`); :meth:`call` picks the family by the case's kind,
    once, and ``prepare``/``query``/``release`` make the call's functions.
    """

    calls: ClassVar[str]
    """The dotted name of the module of engine calls (``adapters.pymunk.calls``): functions
    of plain data importing only the engine library, the standard library and numpy, and
    no ``from __future__`` import (a repro script includes its source verbatim)."""

    def call(self, case: AnyCase) -> Call:
        """The :class:`Call` of ``case``, from the protocol of its kind's family."""
        if isinstance(case, AabbCase | SphereCase) and isinstance(self, Pairs):
            return self.pair_call(case)
        if isinstance(case, ResponseCase) and isinstance(self, Responses):
            return self.response_call(case)
        if isinstance(case, SceneCase) and isinstance(self, Scenes):
            return self.scene_call(case)
        if isinstance(case, ToiCase) and isinstance(self, Impacts):
            return self.toi_call(case)
        raise NotImplementedError(f"{self.name} has no call for {case.kind}")

    def calls_module(self) -> ModuleType:
        """The module of engine calls (imported on first use: it imports the engine)."""
        return importlib.import_module(self.calls)

    def prepare(self, case: AnyCase) -> Any:
        call = self.call(case)
        if call.refusal is not None:
            raise call.refusal
        module = self.calls_module()
        if call.undefined:
            unasked = {q: call.undefined for q in quantities_of(case.kind_enum)}
            return Prepared(call, unasked, dict, module)
        return Prepared(call, getattr(module, call.build)(**call.inputs),
                        getattr(module, call.ask), module)

    def query(self, prepared: Any) -> Observation:
        return self.observation(prepared.ask(prepared.built))

    def query_without(self, prepared: Any, skip: frozenset[str]) -> Observation:
        """The call's ``partial`` ask, if it has one and ``skip`` is not empty."""
        if skip and isinstance(prepared, Prepared) and prepared.call.partial:
            partial = getattr(prepared.module, prepared.call.partial)
            return self.observation(partial(prepared.built))
        return self.query(prepared)

    def observation(self, answer: Answer) -> Observation:
        """The answer in the harness's terms (default: :func:`observation_of`)."""
        return observation_of(answer)

    def release(self, prepared: Any) -> None:
        if isinstance(prepared, Prepared) and prepared.call.release and not prepared.call.undefined:
            getattr(prepared.module, prepared.call.release)(prepared.built)
