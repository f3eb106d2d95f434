"""Executing one case on one adapter: prepare (untimed), query, and the calibrated timing loop.

This is what a worker process does for each task (see :mod:`crosscheck.run.worker`):
:func:`execute` for the verdict pass, :func:`time_step` for each step of the timing
phase's rounds (:mod:`crosscheck.run.rounds`);
it also runs in-process for tests and for ``--no-isolation``, where Ctrl-C waits for
the cases in flight (:func:`stop_between_items`).  An exception
raised by the engine becomes an ``error`` outcome with its reason.  With ``skip``
(quantities an adapter declares as hanging, see
:meth:`~crosscheck.core.contract.Adapter.hanging_quantities`) the query is
:meth:`~crosscheck.core.contract.Adapter.query_without` them.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import threading
import time
import traceback
import types
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, Protocol, TypeVar, runtime_checkable

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Observation, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.run.timing import Timing, calibration, measure, one_sample, yardstick


@dataclass(frozen=True, slots=True)
class Outcome:
    """What executing one case on one adapter gave: an observation, or a status and reason.

    ``hung``: quantities that a declared known hang kept from being answered (recorded
    ``hang_status`` with ``hang_reason``: ``timeout`` when the probe timed out, ``skip``
    when the run is in-process and never starts them); the others are in ``observation``
    or share ``status``.
    """

    observation: Observation | None
    status: Status | None = None
    reason: str = ""
    setup_s: float = math.nan
    timing: Timing | None = None
    hung: frozenset[str] = frozenset()
    hang_reason: str = ""
    hang_status: Status = Status.TIMEOUT
    lines: str | None = None
    """The pair's rows as JSON lines, when the worker scored it (:class:`Judged`; None: the
    parent scores it)."""


SCENE_TIMEOUT_S = 300.0
"""Time limit for one scene x engine (the run's --timeout if larger)."""


def case_options(case: AnyCase, options: RunOptions) -> RunOptions:
    """The options ``case`` runs under: the run's, with a scene's time limit at least
    :data:`SCENE_TIMEOUT_S` (stepping takes seconds, not microseconds).  The one place the
    time limit of a case is set: the verdict pass and the timing phase both ask it.

    >>> from crosscheck.testing.samples import sphere_pair
    >>> case_options(sphere_pair(0.0, 2.0), RunOptions(timeout_s=5.0)).timeout_s
    5.0
    """
    if isinstance(case, SceneCase) and options.timeout_s < SCENE_TIMEOUT_S:
        return replace(options, timeout_s=SCENE_TIMEOUT_S)
    return options


def execute(adapter: Adapter, case: AnyCase, options: RunOptions, timed: bool = False,
            skip: frozenset[str] = frozenset()) -> Outcome:
    """Prepare, query (without the quantities in ``skip``) and (if ``timed``) time ``case``
    on ``adapter``, in this process."""
    unable = _availability(adapter) or adapter.unsupported(case)
    if unable:
        return Outcome(None, Status.SKIP, unable)
    prepared: Any = None

    def query() -> Observation:
        return adapter.query_without(prepared, skip) if skip else adapter.query(prepared)

    try:
        start = time.perf_counter()
        prepared = adapter.prepare(case)
        setup = time.perf_counter() - start
        observation = query()
        if observation.wall_s is not None:  # a scene: its whole run is the measurement
            walls = [observation.wall_s]
            if timed:
                walls += _scene_runs(adapter, case, options.scene_repeats - 1)
            timing: Timing | None = Timing.of_runs(walls)
        else:
            timing = None if not timed else measure(
                query, min_sample_s=options.min_sample_s, samples=options.samples)
        return Outcome(observation, setup_s=setup, timing=timing)
    except Exception as exc:  # an engine fault is data, not a harness failure
        return Outcome(None, Status.ERROR, _fault(exc))
    finally:
        if prepared is not None:
            adapter.release(prepared)


def _fault(exc: Exception) -> str:
    """An engine's exception in words, with where it was raised."""
    where = traceback.extract_tb(exc.__traceback__)[-1]
    return f"{type(exc).__name__}: {exc} (at {where.name}:{where.lineno})"


def time_step(adapter: Adapter, case: AnyCase, options: RunOptions,
              calibrated: Timing | None) -> Outcome:
    """One step of the timing phase's rounds for ``case`` on ``adapter``, prepared anew
    (untimed) and released after.

    ``calibrated`` None (round 0): query once, then calibrate the query loop (its loops,
    one warm-up sample, the empty loop's cost): the outcome's timing has no values yet (a
    scene's one run is its warm-up: unit ``scene``, 1 loop).  Else: the outcome's timing
    is ``calibrated`` with one sample, taken with its loops (a scene: one whole run).
    """
    unable = _availability(adapter) or adapter.unsupported(case)
    if unable:
        return Outcome(None, Status.SKIP, unable)
    prepared: Any = None

    def query() -> Observation:
        return adapter.query(prepared)

    try:
        prepared = adapter.prepare(case)
        if calibrated is None:
            observation = query()
            if observation.wall_s is not None:
                return Outcome(observation, timing=Timing.of_runs(()))
            return Outcome(observation, timing=calibration(
                query, min_sample_s=options.min_sample_s))
        if calibrated.unit == "scene":
            wall = query().wall_s
            return Outcome(None, timing=Timing.of_runs([math.nan if wall is None else wall]))
        return Outcome(None, timing=one_sample(query, calibrated))
    except Exception as exc:  # an engine fault is data, not a harness failure
        return Outcome(None, Status.ERROR, _fault(exc))
    finally:
        if prepared is not None:
            adapter.release(prepared)


def _scene_runs(adapter: Adapter, case: AnyCase, repeats: int) -> list[float]:
    """The stepping loop's wall time of ``repeats`` more runs of a scene, each built anew."""
    walls = []
    for _ in range(max(0, repeats)):
        prepared = adapter.prepare(case)
        try:
            wall = adapter.query(prepared).wall_s
        finally:
            adapter.release(prepared)
        walls.append(float("nan") if wall is None else wall)
    return walls


@dataclass(frozen=True)
class Step:
    """A step of the timing phase's rounds, as a worker's task: :func:`time_step`."""

    case: AnyCase
    calibrated: Timing | None

    def take(self, adapter: Adapter, options: RunOptions) -> Outcome:
        return time_step(adapter, self.case, options, self.calibrated)


@dataclass(frozen=True)
class Judged:
    """A case to run and score in the worker, as a worker's task: the case with its exact
    truth (computed once in the parent).  The worker answers the outcome with its rows as
    JSON lines (``Outcome.lines``, :func:`crosscheck.run.scoring.answer_judged`) and, but for
    a scene (whose recorded trajectory the parent's energy series read), without its
    observation: the parent only appends the lines."""

    case: AnyCase
    truth: Observation


@dataclass(frozen=True)
class Yardstick:
    """The machine yardstick as a worker's task: ``samples`` per workload, with the loops of
    ``calibrated`` (None: calibrated there), see :func:`crosscheck.run.timing.yardstick`."""

    samples: int
    calibrated: Mapping[str, Timing] | None = None

    def measure(self, options: RunOptions) -> dict[str, Timing]:
        return yardstick(self.samples, self.calibrated, options.min_sample_s)


def probe_binding(adapter: Adapter, options: RunOptions) -> Timing | str:
    """The cost of the cheapest call into the adapter's engine binding, or why there is none."""
    call = adapter.binding_call()
    if call is None:
        return "no binding: the engine runs in Python"
    return measure(call, min_sample_s=options.min_sample_s, samples=options.samples)


_AVAILABLE: dict[int, tuple[Adapter, str | None]] = {}


def _availability(adapter: Adapter) -> str | None:
    """``adapter.available()``, asked once per adapter object (it cannot change in-process)."""
    known = _AVAILABLE.get(id(adapter))
    if known is None or known[0] is not adapter:
        known = _AVAILABLE[id(adapter)] = (adapter, adapter.available())
    return known[1]


class Executor(Protocol):
    """Runs one case on one adapter, timed or not, without the quantities in ``skip``:
    :func:`execute` in-process, or a worker pool's."""

    def __call__(self, adapter: Adapter, case: AnyCase, options: RunOptions,
                 timed: bool = False, skip: frozenset[str] = frozenset()) -> Outcome: ...


Call = tuple[Adapter, "AnyCase | Judged | Step", RunOptions, bool, frozenset[str]]
"""One task for an executor: the adapter, the case (or the case to score there, or a step of
the timing phase's rounds), the case's options, whether to time it, and the quantities to
skip."""


@runtime_checkable
class BatchExecutor(Executor, Protocol):
    """An executor that also runs many calls at once (a worker pool: each engine's calls in
    turn in its worker, the engines' workers side by side)."""

    def many(self, calls: Sequence[Call]) -> list[Outcome]: ...


def run_calls(executor: Executor, calls: Sequence[Call]) -> list[Outcome]:
    """Every call's outcome, in order: all at once on a :class:`BatchExecutor`, one after
    another on any other executor (in-process, or the Dask lanes' per-case calls)."""
    if isinstance(executor, BatchExecutor):
        return executor.many(calls)
    return [executor(adapter, _plain(case), options, timed, skip)
            for adapter, case, options, timed, skip in calls]


def _plain(case: AnyCase | Judged | Step) -> AnyCase:
    """The case of a call to a one-at-a-time executor (it is sent no other task)."""
    assert not isinstance(case, Judged | Step)
    return case


T = TypeVar("T")
R = TypeVar("R")


class Lanes(Protocol):
    """Where cases run: local lanes (:class:`~crosscheck.run.lanes.LocalLanes`) or a Dask
    cluster (:class:`~crosscheck.run.distributed.DaskLanes`).

    A context manager whose :meth:`map` applies ``fn(item, executor)`` to every
    item, each with an executor of the lane it runs in, and yields the results
    as they finish, holding only a bounded window of pending items.
    """

    def __enter__(self) -> Lanes: ...

    def __exit__(self, *exc: object) -> None: ...

    def map(self, fn: Callable[[T, Executor], R], items: Iterable[T]) -> Iterator[R]: ...


STOPPING = "stopping after the cases in flight (Ctrl-C again to stop at once)\n"
"""What the first Ctrl-C of an in-process run prints."""


@contextlib.contextmanager
def stop_between_items(defer: bool) -> Iterator[threading.Event]:
    """While ``defer`` (and in the main thread): the first SIGINT only sets the event yielded,
    and puts the previous handler back, so that a second one acts at once."""
    stop = threading.Event()
    previous = signal.getsignal(signal.SIGINT)
    if not defer or threading.current_thread() is not threading.main_thread() \
            or previous in (signal.SIG_IGN, None):
        yield stop
        return

    def first(signum: int, frame: types.FrameType | None) -> None:
        stop.set()
        signal.signal(signal.SIGINT, previous)
        os.write(2, STOPPING.encode())  # at once, from the handler: the cases may take a while

    signal.signal(signal.SIGINT, first)
    try:
        yield stop
    finally:
        signal.signal(signal.SIGINT, previous)
