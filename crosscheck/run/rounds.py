"""The timing phase's interleaved rounds: every sampled pair timed once a round, beside the
machine yardstick, so that every engine shares the machine's drift.

On a shared machine the speed drifts within a run.  Timed one pair after
another, a drift falls on some pairs and not on others; timed in rounds, every
pair's samples span the whole phase, and each sample is stored with the
yardstick of its round, so that it can be read as a ratio to the machine's
speed at that moment (:attr:`crosscheck.results.timings.TimingRecord.normalised`).

- **Round 0**, per engine in run order: the cheapest call into its binding, then
  each of its pairs in suite order: prepared, queried once, its query loop
  calibrated, one warm-up sample discarded, the empty loop's cost measured (a
  scene's one run is its warm-up).
- **Rounds 1 to R** (R: ``samples``, or ``scene_repeats`` when a scene is timed and
  that is larger): every pair not yet complete takes one sample, prepared anew
  (untimed), with its calibrated loops; a scene, one whole run.
- **The yardstick**: a *mark* is the geometric mean of the medians of the two fixed
  workloads (:data:`crosscheck.run.timing.WORKLOADS`) over :data:`MARK_SAMPLES`
  samples each; one is measured before round 1 and after every round, and a
  round's yardstick is the geometric mean of the marks on either side of it (the
  machine's speed across the round, not only at one end).  The workloads are also
  timed with ``samples`` samples each at the start and the end of the phase.

**A pair is complete** when it has all its samples: after round ``samples`` for a
query, after round ``scene_repeats`` for a scene.  It is appended to
``timings.jsonl`` then, at once, with its rounds' yardsticks; a resumed run skips
the pairs stored.  So a phase killed midway keeps the pairs complete by then: the
scenes whose runs are done, and no query pair before the last round (the price of
samples that span the phase); a resumed run times the others anew, in rounds of
its own.  A pair whose step fails (an error, or a crash or timeout, isolated by the
engine's worker as in the verdict pass) leaves the rounds at once, its samples
discarded, and is counted in ``failed``.

Progress counts steps: per pair, its calibration and each of its samples
(:func:`steps`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results.store import ResultsStore
from crosscheck.results.timings import TimingRecord, geomean, spread
from crosscheck.run.execute import Outcome
from crosscheck.run.timing import Timing

MARK_SAMPLES = 5
"""Samples of each yardstick workload per mark (between two rounds); a mark is their median."""

Tick = Callable[[int], None]
Pair = tuple[AnyCase, Adapter]


class Sampler(Protocol):
    """What the rounds measure with: the engines' workers
    (:func:`crosscheck.run.timing_phase.time_phase`'s default) or, in tests, injected times."""

    def binding(self, adapter: Adapter) -> Timing | str:
        """The cheapest call into the adapter's binding, or why there is none."""
        ...

    def step(self, adapter: Adapter, case: AnyCase, calibrated: Timing | None) -> Outcome:
        """:func:`crosscheck.run.execute.time_step`: calibrate (None), or one more sample."""
        ...

    def yardstick(self, samples: int) -> dict[str, Timing] | str:
        """``samples`` samples of each yardstick workload, or why none."""
        ...

    def close(self) -> None:
        """Stop what it started (workers)."""
        ...


def wanted(case: AnyCase, options: RunOptions) -> int:
    """The samples a pair needs to be complete: ``scene_repeats`` for a scene, else ``samples``."""
    return options.scene_repeats if isinstance(case, SceneCase) else options.samples


def steps(pairs: Sequence[Pair], options: RunOptions) -> int:
    """The steps the rounds take on ``pairs``: per pair, its calibration and its samples."""
    return sum(1 + wanted(case, options) for case, _ in pairs)


def mark(found: dict[str, Timing] | str) -> float:
    """One reading of the yardstick, in seconds: the geometric mean of its workloads' medians
    (NaN: none).

    >>> mark({"numpy": Timing((2.0, 2.0, 9.0), 1, 0.0), "python": Timing((8.0,), 1, 0.0)})
    4.0
    """
    medians = [] if isinstance(found, str) else [t.median_s for t in found.values()]
    return geomean(medians) if medians and all(m > 0 for m in medians) else math.nan


def summary(found: dict[str, Timing] | str) -> dict[str, Any]:
    """Per yardstick workload: its median, quartiles and samples (run.json); {}: none."""
    if isinstance(found, str):
        return {}
    return {name: _spread(timing) for name, timing in found.items()}


def _spread(timing: Timing) -> dict[str, Any]:
    s = spread(timing.values)
    return {"median_s": s.median, "q1_s": s.q1, "q3_s": s.q3, "values": list(timing.values)}


def binding_entry(found: Timing | str) -> dict[str, Any]:
    """A binding probe's run.json entry: its spread, or ``none`` and why."""
    return {"none": found} if isinstance(found, str) else _spread(found)


@dataclass
class _Pair:
    """A pair in the rounds: its calibrated loop and the samples so far."""

    case: AnyCase
    adapter: Adapter
    wanted: int
    calibrated: Timing
    values: list[float] = field(default_factory=list)

    def record(self, yardsticks: Sequence[float]) -> TimingRecord:
        c = self.calibrated
        return TimingRecord(self.case.id, self.adapter.name, self.case.kind, c.unit, c.loops,
                            c.overhead_s, tuple(self.values), tuple(yardsticks[:self.wanted]))


@dataclass(frozen=True)
class Rounds:
    """What the rounds measured, beside the samples they stored."""

    failed: int
    binding: dict[str, dict[str, Any]]
    start: dict[str, Any]
    end: dict[str, Any]
    yardsticks: tuple[float, ...]
    """Per round, its yardstick in seconds (NaN: none measured either side of it)."""

    @property
    def drift(self) -> float | None:
        """The largest over the smallest round yardstick (None: fewer than one)."""
        known = [y for y in self.yardsticks if y > 0 and math.isfinite(y)]
        return max(known) / min(known) if known else None

    def section(self) -> dict[str, Any]:
        """Their part of run.json's ``timing``."""
        return {"failed": self.failed, "yardstick": {"start": self.start, "end": self.end},
                "rounds": {"count": len(self.yardsticks), "drift": self.drift,
                           "yardstick_s": [y if math.isfinite(y) else None
                                           for y in self.yardsticks]},
                "binding": self.binding}


class _Rounds:
    """One timing phase's rounds: the sampler, where complete pairs go, progress, failures."""

    def __init__(self, store: ResultsStore, options: RunOptions, sampler: Sampler,
                 tick: Tick) -> None:
        self.store, self.options, self.sampler, self.tick = store, options, sampler, tick
        self.failed = 0

    def _fail(self, remaining: int) -> None:
        self.failed += 1
        self.tick(remaining)

    def calibrate(self, pairs: Sequence[Pair],
                  engines: Sequence[Adapter]) -> tuple[list[_Pair], dict[str, dict[str, Any]]]:
        """Round 0: per engine, its binding probe, then each of its pairs calibrated."""
        live, binding = [], {}
        for adapter in engines:
            binding[adapter.name] = binding_entry(self.sampler.binding(adapter))
            for case in (case for case, owner in pairs if owner is adapter):
                outcome = self.sampler.step(adapter, case, None)
                if outcome.timing is None:
                    self._fail(1 + wanted(case, self.options))
                    continue
                live.append(_Pair(case, adapter, wanted(case, self.options), outcome.timing))
                self.tick(1)
        return live, binding

    def sample(self, pairs: list[_Pair]) -> list[_Pair]:
        """One round: one sample of each pair; the pairs that did not fail."""
        kept = []
        for pair in pairs:
            outcome = self.sampler.step(pair.adapter, pair.case, pair.calibrated)
            if outcome.timing is None or len(outcome.timing.values) != 1:
                self._fail(pair.wanted - len(pair.values))
                continue
            pair.values.append(outcome.timing.values[0])
            kept.append(pair)
            self.tick(1)
        return kept

    def mark(self) -> float:
        return mark(self.sampler.yardstick(MARK_SAMPLES))

    def run(self, pairs: Sequence[Pair], engines: Sequence[Adapter]) -> Rounds:
        start = summary(self.sampler.yardstick(self.options.samples))
        live, binding = self.calibrate(pairs, engines)
        marks, yardsticks = [self.mark()], []
        while live:
            live = self.sample(live)
            marks.append(self.mark())
            yardsticks.append(geomean(marks[-2:]))
            for pair in live:
                if len(pair.values) == pair.wanted:
                    self.store.append_timing(pair.record(yardsticks))
            live = [pair for pair in live if len(pair.values) < pair.wanted]
        end = summary(self.sampler.yardstick(self.options.samples))
        return Rounds(self.failed, binding, start, end, tuple(yardsticks))


def run_rounds(store: ResultsStore, pairs: Sequence[Pair], engines: Sequence[Adapter],
               options: RunOptions, sampler: Sampler, tick: Tick | None = None) -> Rounds:
    """Time ``pairs`` in rounds with ``sampler``, each pair appended to ``store`` once
    complete; ``tick(n)`` as steps are taken (:func:`steps` in all)."""
    return _Rounds(store, options, sampler, tick or (lambda n: None)).run(pairs, engines)
