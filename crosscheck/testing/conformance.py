"""The conformance kit: does an adapter class honour the contract?  For any engine's own CI.

``check_adapter(MyAdapter)`` raises :class:`ConformanceError` listing every failure, each
with the adapter, the check, the case in words and what was expected;
:func:`conformance_failures` returns them.  The built-in adapters are checked the same way
(``tests/adapters/test_conformance.py``).  The checks, in order (a failure of the first three
stops the kit, since nothing else can be asked):

- ``declared``: a concrete Adapter subclass with a ``name`` (the registered name if one is
  given), ``engine`` and ``settings``, ``capabilities`` of (Kind, 2 or 3) (empty only for a
  registered variant that supports no case, each one a skip with its reason: FCL's
  solvers that FCL does not compute for spheres) and ``Conventions``;
- ``made``: the class is created with no arguments, as the runner's workers create it;
- ``available``: ``available()`` is None here and ``version()`` a non-empty string;
- ``conventions``: sources given (with ``public_sources``, at least one ``https://`` link
  and a module docstring that names its conventions and sources); ``zero_mass``,
  ``negative_extents``, ``damping``, ``time_step``, ``rtol``, ``margins``, ``touching``
  and the restitution threshold well formed;
- ``unsupported``: every (kind, dim) it lacks is skipped with a reason naming it (or "engine"),
  every one it claims is not;
- ``observe``: ``observe()`` returns an :class:`Observation` with only its kind's quantities
  (a quantity may be absent, None, where the engine cannot give it, but not the verdict
  ``hit``, the velocities ``v1``/``v2`` or a scene's ``positions``/``velocities``);
- ``overlap`` / ``gap``: on a clear overlap ``hit`` True and a negative distance, on clear
  gaps along +x and -y ``hit`` False and a positive distance where given; every normal
  given a unit vector from A to B; ``response``: after a head-on elastic impact A moves
  back and B on; ``scene``: two runs give the same bodies, moved as they should, timed;
- ``repeat``: prepare, query twice, ``query_without`` nothing, release, prepare and query
  again: one answer; ``hangs``: declared hanging quantities are the kind's, and declared
  exactly when ``known_hang`` names a reason;
- ``worker``: the class pickles by reference and, created in a worker process as the
  runner does (:class:`~crosscheck.run.worker.WorkerPool`), gives the same answer.

The class-level checks and the worker's are here; the checks of the answers, one
capability at a time, are :mod:`crosscheck.testing.answers`.  A check that raises is a
failure of that check, with the exception; a query that hangs hangs the kit (run it under
a test timeout if the engine may).
"""

from __future__ import annotations

import math
import pickle
import sys
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

from crosscheck.core.contract import FEATURES, Adapter, Conventions
from crosscheck.core.model import Kind
from crosscheck.core.options import RunOptions
from crosscheck.run.worker import WorkerPool
from crosscheck.testing import samples
from crosscheck.testing.answers import Answers, plain

WORKER_TIMEOUT_S = 60.0

CHECKS = ("declared", "made", "available", "conventions", "unsupported", "query", "observe",
          "overlap", "gap", "response", "impact", "scene", "repeat", "hangs", "worker")
"""Every check's name (a :class:`Failure`'s ``check``), in the order the kit runs them:
``query`` is an exception raised while the answers of a capability are checked, ``impact``
the check of a time of impact's answer (the pytest plugin makes one item of each)."""


@dataclass(frozen=True, slots=True)
class Failure:
    """One broken promise: which adapter, which check, on which case, expected what, got what."""

    adapter: str
    check: str
    case: str
    expected: str
    got: str

    def __str__(self) -> str:
        where = f" on {self.case}" if self.case else ""
        return f"{self.adapter}: {self.check}{where}: expected {self.expected}; got {self.got}"


class ConformanceError(AssertionError):
    """An adapter breaks the contract; ``failures`` lists how."""

    def __init__(self, failures: list[Failure]) -> None:
        self.failures = tuple(failures)
        lines = "\n".join(f"- {f}" for f in failures)
        super().__init__(f"{len(failures)} conformance failure(s):\n{lines}")


class _Stop(Exception):
    """Nothing more can be checked (the class cannot be created or its engine is missing)."""


def _label(cls: Any) -> str:
    name = getattr(cls, "name", None)
    where = f"{getattr(cls, '__module__', '?')}.{getattr(cls, '__qualname__', repr(cls))}"
    return f"{name} ({where})" if isinstance(name, str) and name else where


class Checker:
    """Runs the checks on one adapter class and collects every :class:`Failure`."""

    def __init__(self, cls: Any, name: str | None = None, public_sources: bool = True,
                 worker: bool = True) -> None:
        self.cls, self.name, self.public_sources, self.worker = cls, name, public_sources, worker
        self.failures: list[Failure] = []
        self.adapter: Adapter | None = None
        self.stopped = ""
        """The check whose failure stopped the kit ('' if it ran to the end)."""

    def fail(self, check: str, case: str, expected: str, got: object) -> None:
        """Record a failure."""
        self.failures.append(Failure(_label(self.cls), check, case, expected, str(got)))

    def run(self) -> list[Failure]:
        """Every check, in the order of the module docstring; the failures."""
        try:
            self.declared()
            adapter = self.made()
            self.available(adapter)
        except _Stop:
            self.stopped = self.failures[-1].check
            return self.failures
        self.guarded("conventions", "", lambda: self.conventions(adapter.conventions))
        self.guarded("unsupported", "", lambda: self.unsupported(adapter))
        for kind, dim in sorted(adapter.capabilities):
            self.guarded("query", samples.first(kind, dim).label,
                         partial(Answers(adapter, self.fail).capability, kind, dim))
        if self.worker:
            self.guarded("worker", "", lambda: self.in_worker(adapter))
        return self.failures

    def guarded(self, check: str, case: str, run: Callable[[], None]) -> None:
        """Run one check; an exception it raises is a failure of that check."""
        try:
            run()
        except Exception as exc:
            self.fail(check, case, "no exception", f"{type(exc).__name__}: {exc}")

    # --- the class ------------------------------------------------------------------------

    def declared(self) -> None:
        """A concrete Adapter subclass declaring name, engine, settings, capabilities,
        conventions."""
        cls = self.cls
        if not (isinstance(cls, type) and issubclass(cls, Adapter)):
            self.fail("declared", "", "a subclass of crosscheck.core.contract.Adapter", cls)
            raise _Stop
        if getattr(cls, "__abstractmethods__", None):
            self.fail("declared", "", "a concrete class (version, prepare and query defined)",
                      f"abstract methods {sorted(cls.__abstractmethods__)}")
            raise _Stop
        name = getattr(cls, "name", None)
        if not isinstance(name, str) or not name or (self.name and name != self.name):
            self.fail("declared", "", f"name {self.name or 'a non-empty string'!r}", repr(name))
        for attribute in ("engine", "settings"):
            value = getattr(cls, attribute, None)
            if not isinstance(value, str) or not value:
                self.fail("declared", "", f"{attribute} a non-empty string", repr(value))
        caps = getattr(cls, "capabilities", None)
        if not (isinstance(caps, frozenset) and all(
                isinstance(c, tuple) and len(c) == 2 and isinstance(c[0], Kind)
                and c[1] in (2, 3) for c in caps)):
            self.fail("declared", "", "capabilities a frozenset of (Kind, 2 or 3)",
                      repr(caps))
            raise _Stop
        if not isinstance(getattr(cls, "conventions", None), Conventions):
            self.fail("declared", "", "conventions a Conventions instance",
                      repr(getattr(cls, "conventions", None)))
            raise _Stop

    def made(self) -> Adapter:
        """The class created with no arguments, as a worker process creates it."""
        try:
            adapter: Adapter = self.cls()
        except Exception as exc:
            self.fail("made", "", "the class created with no arguments (as the runner's "
                      "workers create it)", f"{type(exc).__name__}: {exc}")
            raise _Stop from None
        return adapter

    def available(self, adapter: Adapter) -> None:
        """The engine runs here and has a version."""
        try:
            reason = adapter.available()
            version = adapter.version()
        except Exception as exc:
            self.fail("available", "", "available() and version() to answer",
                      f"{type(exc).__name__}: {exc}")
            raise _Stop from None
        if reason is not None:
            self.fail("available", "", "available() None (the engine installed here)", reason)
            raise _Stop
        if not isinstance(version, str) or not version:
            self.fail("available", "", "version() a non-empty string", repr(version))

    def conventions(self, conventions: Conventions) -> None:
        """Conventions declared with their sources, and well formed."""
        sources = conventions.sources
        if not sources or not all(isinstance(s, str) and s.strip() for s in sources):
            self.fail("conventions", "", "sources: where each convention is documented",
                      repr(sources))
        if self.public_sources:
            self.documented(sources)
        rules: list[tuple[bool, str, object]] = [
            (conventions.zero_mass in ("static", ""), "zero_mass 'static' or ''",
             conventions.zero_mass),
            (conventions.negative_extents in ("absolute", ""), "negative_extents 'absolute' or ''",
             conventions.negative_extents),
            (conventions.damping >= 0.0, "damping >= 0", conventions.damping),
            (conventions.time_step is None or conventions.time_step > 0.0,
             "time_step None or > 0", conventions.time_step),
            (math.isfinite(conventions.rtol) and conventions.rtol >= 0.0, "rtol finite, >= 0",
             conventions.rtol),
            (conventions.restitution_threshold >= 0.0, "restitution_threshold >= 0",
             conventions.restitution_threshold),
            (set(conventions.margins) <= set(FEATURES) and all(
                math.isfinite(m) and m >= 0.0 for m in conventions.margins.values()),
             f"margins finite, >= 0, by feature of {FEATURES}", conventions.margins),
            (set(conventions.touching) <= set(FEATURES), f"touching by feature of {FEATURES}",
             conventions.touching)]
        for ok, expected, got in rules:
            if not ok:
                self.fail("conventions", "", expected, repr(got))

    def documented(self, sources: tuple[str, ...]) -> None:
        """A public link among the sources, and a module docstring naming both."""
        if not any(str(s).startswith("https://") for s in sources):
            self.fail("conventions", "", "at least one public https:// link among the sources",
                      repr(sources))
        module = sys.modules.get(self.cls.__module__)
        doc = (getattr(module, "__doc__", None) or "").lower()
        if "conventions" not in doc or "sources" not in doc:
            self.fail("conventions", "", f"module {self.cls.__module__}'s docstring to state "
                      "its conventions and their sources", "no 'conventions' and 'sources' in it")

    def unsupported(self, adapter: Adapter) -> None:
        """What the adapter lacks is a skip with a reason; what it claims is not."""
        for kind in Kind:
            for dim in (2, 3):
                sample = samples.first(kind, dim)
                reason = adapter.unsupported(sample.case)
                claimed = (kind, dim) in adapter.capabilities
                if claimed and reason is not None:
                    self.fail("unsupported", sample.label, "no skip: it is a capability", reason)
                elif not claimed and not (isinstance(reason, str) and (
                        adapter.name.split("-")[0] in reason or "engine" in reason)):
                    self.fail("unsupported", sample.label, "a skip reason naming the adapter "
                              "(or 'engine'): it is not a capability", repr(reason))

    # --- the runner's way ------------------------------------------------------------------

    def in_worker(self, adapter: Adapter) -> None:
        """The class pickles by reference and answers in a worker process as in this one."""
        cls = type(adapter)
        try:
            same = pickle.loads(pickle.dumps(cls)) is cls
        except Exception as exc:
            same, why = False, f"{type(exc).__name__}: {exc}"
        else:
            why = "a different class"
        if not same or cls.__module__ == "__main__":
            self.fail("worker", "", "the class pickled by reference (defined at module level "
                      "in an importable module, not __main__): the runner sends it to worker "
                      "processes", why if not same else "defined in __main__")
            return
        if not adapter.capabilities:  # supports no case: nothing to ask a worker
            return
        kind, dim = sorted(adapter.capabilities)[0]
        sample = samples.first(kind, dim)
        options = RunOptions(timeout_s=WORKER_TIMEOUT_S)
        pool = WorkerPool(options)
        try:
            outcome = pool.execute(adapter, sample.case, options)
        finally:
            pool.close()
        here = adapter.observe(sample.case)
        if outcome.observation is None:
            self.fail("worker", sample.label, "an answer from a worker process",
                      f"{outcome.status}: {outcome.reason}")
        elif plain(outcome.observation) != plain(here):
            self.fail("worker", sample.label, f"the same answer as in this process ({here})",
                      outcome.observation)


def conformance_failures(cls: Any, *, name: str | None = None, public_sources: bool = True,
                         worker: bool = True) -> list[Failure]:
    """Every way ``cls`` breaks the contract (empty: none); see the module docstring.

    ``name``: the name the adapter is registered under (its ``name`` must be it);
    ``public_sources``: require a https:// source and a module docstring naming the
    conventions and sources (the harness's own formula cites files of its own);
    ``worker``: also run a case in a worker process (about a second to start one).
    """
    return Checker(cls, name, public_sources, worker).run()


def check_adapter(cls: Any, *, name: str | None = None, public_sources: bool = True,
                  worker: bool = True) -> None:
    """Raise :class:`ConformanceError` listing every way ``cls`` breaks the contract.

    >>> from crosscheck.testing.fakes import Conforming
    >>> check_adapter(Conforming, public_sources=False, worker=False)
    """
    failures = conformance_failures(cls, name=name, public_sources=public_sources,
                                    worker=worker)
    if failures:
        raise ConformanceError(failures)
