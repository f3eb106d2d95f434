"""Fake adapters with known behaviour, to test the harness (and the kit) without any engine.

Shipped with the conformance kit so that an engine's own tests can drive the runner with
them too.  :class:`Conforming` passes :func:`crosscheck.testing.check_adapter` (its sources
are the harness's own oracle, so ``public_sources=False``); the others break one promise
each on purpose: wrong answers, answers that change from process to process, exceptions,
hangs, aborts, segfaults, missing quantities, slowness that ignores Ctrl-C, memory leaks and
runaway allocations.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import signal
import time
from dataclasses import replace
from typing import Any, ClassVar

from crosscheck.core.contract import Adapter, Capability, Conventions, all_capabilities
from crosscheck.core.model import Kind, Observation
from crosscheck.core.schema import AnyCase
from crosscheck.truth import oracle


class _Fake(Adapter):
    engine: ClassVar[str] = "fake"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(*Kind)
    conventions: ClassVar[Conventions] = Conventions()

    def version(self) -> str:
        return "0"

    def prepare(self, case: AnyCase) -> Any:
        return case


class AlwaysRight(_Fake):
    """Answers with the exact truth."""

    name: ClassVar[str] = "fake-right"

    def query(self, prepared: Any) -> Observation:
        return oracle.truth(prepared)


class OffByOne(_Fake):
    """Distance always 1.0 too large; everything else right."""

    name: ClassVar[str] = "fake-off"

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        assert isinstance(truth.distance, float)
        return Observation(hit=truth.hit, distance=truth.distance + 1.0, normal=truth.normal)


class DriftsWithEachQuery(_Fake):
    """Distance off by ``STEP`` times the number of queries its process has answered (a
    process-wide count), as an engine whose answer depends on its history: the same case
    answers differently in a fresh process.  Everything else right."""

    name: ClassVar[str] = "fake-drifts"
    STEP: ClassVar[float] = 1e-3
    asked: ClassVar[int] = 0

    def query(self, prepared: Any) -> Observation:
        DriftsWithEachQuery.asked += 1
        truth = oracle.truth(prepared)
        if not isinstance(truth.distance, float):
            return truth
        return replace(truth, distance=truth.distance + self.STEP * self.asked)


class Raises(_Fake):
    """Raises on every query."""

    name: ClassVar[str] = "fake-raises"

    def query(self, prepared: Any) -> Observation:
        raise RuntimeError("engine exploded")


class HitOnly(_Fake):
    """Reports only the verdict; distance and normal are absent."""

    name: ClassVar[str] = "fake-hit-only"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.AABB, Kind.SPHERE)

    def query(self, prepared: Any) -> Observation:
        return Observation(hit=oracle.truth(prepared).hit)


class TouchingIsContact(_Fake):
    """Declares that touching counts as contact, and reports spheres that way."""

    name: ClassVar[str] = "fake-touch"
    conventions: ClassVar[Conventions] = Conventions(touching={"sphere": True})

    def query(self, prepared: Any) -> Observation:
        truth = oracle.truth(prepared)
        return Observation(hit=truth.distance == 0.0 or truth.hit)


class Unavailable(_Fake):
    """An engine that is not installed."""

    name: ClassVar[str] = "fake-missing"

    def available(self) -> str | None:
        return "not installed here"

    def query(self, prepared: Any) -> Observation:
        raise AssertionError("must never be queried")


class SleepsForever(_Fake):
    """Hangs in query, as an engine stuck in a loop."""

    name: ClassVar[str] = "fake-hangs"

    def query(self, prepared: Any) -> Observation:
        while True:
            time.sleep(1.0)


class Aborts(_Fake):
    """Kills its own process with SIGABRT, as an engine failing an assertion in C."""

    name: ClassVar[str] = "fake-aborts"

    def query(self, prepared: Any) -> Observation:
        os.abort()


class CrashesOnSpheresAt(_Fake):
    """Segfault-like death (SIGSEGV) only on the case with id 'boom'; right otherwise."""

    name: ClassVar[str] = "fake-boom"

    def query(self, prepared: Any) -> Observation:
        if prepared.id == "boom":
            os.kill(os.getpid(), signal.SIGSEGV)
        return oracle.truth(prepared)


class ClaimsResponse(_Fake):
    """Claims sphere_response but cannot do it: answers with no velocities."""

    name: ClassVar[str] = "fake-claims"

    def query(self, prepared: Any) -> Observation:
        return Observation()


class DeclaresHangs(SleepsForever):
    """Hangs on 'boom', which it declares a known hang; declares 'after' too but answers."""

    name: ClassVar[str] = "fake-declared-hang"

    def known_hang(self, case: AnyCase) -> str | None:
        return "stuck in a loop" if case.id in ("boom", "after") else None

    def query(self, prepared: Any) -> Observation:
        if prepared.id == "boom":
            super().query(prepared)
        return oracle.truth(prepared)


class HangsOnDistance(_Fake):
    """Declares that only ``distance`` hangs on 'boom' (as FCL's signed distance does): its
    full query hangs there, while ``query_without`` the distance answers the rest."""

    name: ClassVar[str] = "fake-hangs-on-distance"

    def known_hang(self, case: AnyCase) -> str | None:
        return "distance loops" if case.id == "boom" else None

    def hanging_quantities(self, case: AnyCase) -> frozenset[str]:
        return frozenset({"distance"}) if self.known_hang(case) else frozenset()

    def query(self, prepared: Any) -> Observation:
        while prepared.id == "boom":
            time.sleep(1.0)
        return oracle.truth(prepared)

    def query_without(self, prepared: Any, skip: frozenset[str]) -> Observation:
        if "distance" not in skip:
            return self.query(prepared)
        return replace(oracle.truth(prepared), distance=None)


class HangsOnDistanceRestRaises(HangsOnDistance):
    """As HangsOnDistance, but answering without the distance raises."""

    name: ClassVar[str] = "fake-hangs-rest-raises"

    def query_without(self, prepared: Any, skip: frozenset[str]) -> Observation:
        raise RuntimeError("no verdict either")


class Conforming(_Fake):
    """Right on every two-body kind in 2-D and 3-D, with its source declared: passes the kit."""

    name: ClassVar[str] = "fake-conforming"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        Kind.AABB, Kind.SPHERE, Kind.SPHERE_RESPONSE)
    conventions: ClassVar[Conventions] = Conventions(
        sources=("crosscheck.truth.oracle: the exact oracle itself",))

    def query(self, prepared: Any) -> Observation:
        return oracle.truth(prepared)


class BusyLoop(_Fake):
    """Right answers at a known cost: a busy loop of ``ITERATIONS`` steps per query.

    The answer is computed once in ``prepare``, so the query's cost is the loop alone.  The
    loop allocates nothing (``itertools.repeat`` and a flag that stays a cached small int):
    a loop that made a new int per step had its instruction count depend on the worker's
    heap (pymalloc's state), 2% apart between two processes doing the same work.
    """

    name: ClassVar[str] = "fake-busy"
    ITERATIONS: ClassVar[int] = 20_000

    def prepare(self, case: AnyCase) -> Any:
        return oracle.truth(case)

    def query(self, prepared: Any) -> Observation:
        flag = 0
        for _ in itertools.repeat(None, self.ITERATIONS):
            flag ^= 1
        assert flag in (0, 1)
        result: Observation = prepared
        return result


class BusyLoopTwice(BusyLoop):
    """The same engine, twice as slow: for ``compare`` to catch (same name as BusyLoop)."""

    ITERATIONS: ClassVar[int] = 2 * BusyLoop.ITERATIONS


class BusyLoopFivePercent(BusyLoop):
    """The same engine doing 5% more work per query: for a cost ``compare`` to catch."""

    ITERATIONS: ClassVar[int] = BusyLoop.ITERATIONS * 105 // 100


class SlowWithDeclaredHang(_Fake):
    """Right answers after ``DELAY_S`` each (a slow engine); on the case with id 'stuck',
    which it declares a known hang, it loops and ignores Ctrl-C, as an engine stuck in C
    does (FCL's signed distance on coincident spheres)."""

    name: ClassVar[str] = "fake-slow"
    DELAY_S: ClassVar[float] = 0.1

    def known_hang(self, case: AnyCase) -> str | None:
        return "loops on 'stuck', deaf to Ctrl-C" if case.id == "stuck" else None

    def query(self, prepared: Any) -> Observation:
        while prepared.id == "stuck":
            with contextlib.suppress(KeyboardInterrupt):
                time.sleep(0.05)
        time.sleep(self.DELAY_S)
        return oracle.truth(prepared)


def _touched(mb: int) -> bytes:
    """``mb`` MB of memory, every page written (resident, not merely reserved)."""
    return b"\xa5" * (mb << 20)


class Leaks(_Fake):
    """Right answers after ``PAUSE_S`` (longer than the harness's memory watch), but each query
    then keeps ``LEAK_MB`` more memory for good, as an engine leaking case after case."""

    name: ClassVar[str] = "fake-leaks"
    LEAK_MB: ClassVar[int] = 100
    PAUSE_S: ClassVar[float] = 0.3
    kept: ClassVar[list[bytes]] = []

    def query(self, prepared: Any) -> Observation:
        time.sleep(self.PAUSE_S)
        self.kept.append(_touched(self.LEAK_MB))
        return oracle.truth(prepared)


class Hogs(_Fake):
    """Right answers, except on the case with id 'hog': there it allocates ``CHUNK_MB`` after
    ``CHUNK_MB`` without end (stopping with MemoryError at ``CEILING_MB``, so that a harness
    without a memory limit does not take the machine down)."""

    name: ClassVar[str] = "fake-hogs"
    CHUNK_MB: ClassVar[int] = 25
    CEILING_MB: ClassVar[int] = 3000

    def query(self, prepared: Any) -> Observation:
        held: list[bytes] = []
        while prepared.id == "hog":
            if len(held) * self.CHUNK_MB >= self.CEILING_MB:
                raise MemoryError(f"the fake stopped at its ceiling of {self.CEILING_MB} MB")
            held.append(_touched(self.CHUNK_MB))
            time.sleep(0.02)
        return oracle.truth(prepared)
