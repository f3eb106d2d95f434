"""Shrinking a fuzz finding to a minimal case that still fails the same way (hypothesis-style).

Over 400 lines: the moves, the search and its sort key are one algorithm, kept together.

Fuzz cases are noisy by design (offsets of 1e6, 17-digit numbers, lengths of 1e-9).
:func:`shrink_case` greedily keeps simpler cases that still *fail the same way*: the engine,
run on the candidate as a campaign runs a case (:func:`~.lanes.fuzz_outcome`) and scored by
the harness's own rules (:func:`~.lanes.judge_chunk`), gives a record of the finding's
quantity, status and category (its :class:`Signature`).

*Simpler* is a sort key (:func:`complexity`): fewer non-zero numbers; then each group of
numbers (sizes, velocities, masses, duration) nearer 1, in whole binary orders of its mean
(before digits: scaling noisy lengths by a power of two, exact, changes their digit counts
by chance); then fewer significant digits (per number the fewer of its decimal and binary
ones: 0.1 and 0.375 are both round); then numbers nearer 1 (the sum of ``|log2|x||``).

The moves (:func:`moves`), round after round until none makes progress: *translate* both
bodies on one axis, *zero* a coordinate, *rescale* lengths, velocities, masses or time by
``2^k`` (exact), *cut* every number to fewer digits, *round* one number, *resize* a body
(B moved to keep the gap).  Sizes, masses and the duration stay positive: a zero size is a
degenerate body, another regime than the finding's.  Candidates are tried simplest first
(binary searches where a move has a range), only valid ones (``semantic_problems`` empty,
not bad-input; a response in contact stays in contact), none twice; a move that failed is
tried again once its numbers change, and a last round tries every move.

Engine calls go through an executor (a :class:`~crosscheck.run.worker.WorkerPool`), so a
candidate that crashes or hangs the engine only does not fail the same way (unless the
finding is a crash or a timeout), and the shrink goes on in a fresh worker.  A finding
gets at most :data:`MAX_CALLS` calls, and none once :data:`HANGS` candidates have hung.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from pydantic import ValidationError

from crosscheck.cases.load import semantic_problems
from crosscheck.core.contract import Adapter
from crosscheck.core.model import Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, ResponseCase, SceneCase
from crosscheck.run.execute import Executor
from crosscheck.studies.fuzz.findings import Signature
from crosscheck.studies.fuzz.lanes import fuzz_outcome, judge_chunk
from crosscheck.truth import oracle
from reference_impl import exact

MAX_CALLS = 300
"""Engine calls a finding may take to shrink (the first re-runs the finding itself)."""
HANGS = 8
"""A shrink stops once this many candidates hung (a timeout finding's too): each costs the
campaign's whole time limit, kept so that a slow answer is judged as in the campaign."""
LIMIT = 5
"""Candidates tried per move (those without a range), simplest first."""

Slot = tuple[str, str, int]
"""Where a number sits: body (``a``, ``b`` or ``""`` for the case), field, index (-1: scalar)."""
Numbers = dict[Slot, float]
GROUP = {"half": "size", "radius": "size", "velocity": "velocity", "mass": "mass",
         "duration": "duration"}
"""The scale group of each field (centres are offsets: translations move them)."""
ZEROABLE = ("center", "velocity", "restitution")
SIZES = ("half", "radius")


@dataclass(frozen=True)
class Shrunk:
    """A finding shrunk: the original case, the simplest found, and what it took."""

    engine: str
    signature: Signature
    original: AnyCase
    case: AnyCase
    record: Record | None
    """Its failing record; None: the original did not fail the same way again (not shrunk)."""
    calls: int
    crashed: int
    """Candidates that crashed or hung the engine."""
    steps: tuple[tuple[str, str], ...] = ()
    """The moves kept, in order: (kind, words)."""

    @property
    def changed(self) -> bool:
        return self.record is not None and self.case != self.original


def numbers(case: AnyCase) -> Numbers:
    """Every number of a two-body case, by slot."""
    found: Numbers = {}
    for side in ("a", "b"):
        body = getattr(case, side)
        for name in ("center", "half", "velocity", "radius", "mass"):
            value = getattr(body, name, None)
            if isinstance(value, tuple):
                found |= {(side, name, i): x for i, x in enumerate(value)}
            elif value is not None:
                found[(side, name, -1)] = value
    for name in ("restitution", "duration"):
        if hasattr(case, name):
            found[("", name, -1)] = getattr(case, name)
    return found


def build(template: AnyCase, values: Numbers) -> AnyCase | None:
    """``template`` with these numbers; None unless it is a valid case (not bad-input)."""
    data = template.model_dump()
    for (side, name, i), x in values.items():
        where = data[side] if side else data
        if i < 0:
            where[name] = x
        else:
            where[name] = [*where[name][:i], x, *where[name][i + 1:]]
    try:
        made = CASE_ADAPTER.validate_python(data)
    except ValidationError:
        return None
    if made.bad_input or semantic_problems(made) or (in_contact(template)
                                                     and not in_contact(made)):
        return None
    return made


def in_contact(case: AnyCase) -> bool:
    """A response whose spheres touch or overlap: a shrunk response stays one (spheres moved
    apart ask another question: an engine that steps them never collides them)."""
    if not isinstance(case, ResponseCase):
        return False
    contact = exact.sphere_contact(case.a.center, case.a.radius, case.b.center, case.b.radius)
    return not float(getattr(contact, "distance", math.inf)) > 0


def decimal_digits(x: float) -> int:
    """Significant decimal digits of ``x`` as written (its shortest repr); 0 for 0."""
    if x == 0 or not math.isfinite(x):
        return 0
    return len(repr(abs(x)).split("e")[0].replace(".", "").strip("0"))


def digits(x: float) -> int:
    """Significant digits of ``x``: the fewer of its decimal and binary ones.

    >>> [digits(x) for x in (0.0, 1e6, 0.375, 0.1, 1.0000000000000002)]
    [0, 1, 2, 1, 17]
    """
    if x == 0 or not math.isfinite(x):
        return 0
    n = abs(x).as_integer_ratio()[0]
    return min(decimal_digits(x), (n >> ((n & -n).bit_length() - 1)).bit_length())


def complexity(values: Numbers) -> tuple[int, int, int, float]:
    """The sort key of a case (smaller is simpler): non-zero numbers, whole binary orders of
    each group's mean from 1, significant digits, binary orders of every number from 1."""
    logs: dict[str, list[float]] = {}
    for (_, name, _), x in values.items():
        if x and name in GROUP:
            logs.setdefault(GROUP[name], []).append(math.log2(abs(x)))
    return (sum(x != 0 for x in values.values()),
            sum(int(abs(statistics.fmean(v))) for v in logs.values()),
            sum(digits(x) for x in values.values()),
            sum(abs(math.log2(abs(x))) for x in values.values() if x and math.isfinite(x)))


def _cut(x: float, k: int) -> float:  # to k significant decimal digits
    return float(f"{x:.{k}g}")


def specials(x: float) -> set[float]:
    """Round numbers near ``x`` of its sign: 1, its nearest integer and power of two, the
    1-2-5 values around it."""
    if x == 0 or not math.isfinite(x):
        return set()
    a = abs(x)
    decade = 10.0 ** math.floor(math.log10(a))
    steps = [m * decade for m in (1, 2, 5, 10)]
    found = {1.0, float(round(a)), math.ldexp(1.0, min(1023, round(math.log2(a)))),
             max((v for v in steps if v <= a), default=steps[0]),
             min((v for v in steps if v >= a), default=steps[-1])}
    return {math.copysign(c, x) for c in found if 0 < c < math.inf and c != a}


class Judge:
    """Runs candidates on the engine and says which fail the same way; counts the calls."""

    def __init__(self, adapter: Adapter, signature: Signature, executor: Executor,
                 options: RunOptions, max_calls: int) -> None:
        self.adapter, self.signature, self.executor = adapter, signature, executor
        self.options, self.max_calls = options, max_calls
        self.calls = self.crashed = self.hung = 0
        self.seen: dict[tuple[tuple[Slot, float], ...], Record | None] = {}

    @property
    def spent(self) -> bool:
        """No more calls: the budget is used, or too many candidates hung."""
        return self.calls >= self.max_calls or self.hung >= HANGS

    def __call__(self, case: AnyCase) -> Record | None:
        """The record that fails the same way on ``case``, or None (also once spent)."""
        key = tuple(sorted(numbers(case).items()))
        if key in self.seen or self.spent:
            return self.seen.get(key)
        self.calls += 1
        outcome = fuzz_outcome(self.adapter, case, self.options, self.executor)
        ran = self.adapter.known_hang(case) is None  # a declared hang is not run: no cost
        self.crashed += ran and outcome.status in (Status.CRASH, Status.TIMEOUT)
        self.hung += ran and outcome.status == Status.TIMEOUT
        records = judge_chunk([case], self.adapter, [outcome], [oracle.truth(case)])
        found = self.seen[key] = next((r for r in records if self.signature.matches(r)), None)
        return found


class Search:
    """The shrink in progress: the simplest case that fails the same way so far."""

    def __init__(self, template: AnyCase, judge: Judge, record: Record) -> None:
        self.template, self.judge, self.record = template, judge, record
        self.best = numbers(template)
        self.key = complexity(self.best)
        self.steps: list[tuple[str, str]] = []

    def attempt(self, values: Numbers, words: str, kind: str) -> bool:
        """Keep ``values`` if simpler and failing the same way."""
        key = complexity(values)
        if key >= self.key or self.judge.spent:
            return False
        case = build(self.template, values)
        record = None if case is None else self.judge(case)
        if record is None:
            return False
        self.best, self.key, self.record = values, key, record
        self.steps.append((kind, words))
        return True

    def first(self, candidates: Iterable[tuple[Numbers, str]], kind: str) -> bool:
        """Try the :data:`LIMIT` simplest candidates that are simpler than the best; keep the
        first that fails the same way."""
        ranked = sorted((c for c in candidates if complexity(c[0]) < self.key),
                        key=lambda c: complexity(c[0]))
        return any(self.attempt(values, words, kind) for values, words in ranked[:LIMIT])

    def least(self, lo: int, hi: int, make: Callable[[int], tuple[Numbers, str]],
              kind: str) -> bool:
        """Binary search for the least ``k`` in ``[lo, hi)`` whose candidate ``make(k)`` is
        kept (``hi``: the best as it is)."""
        found = False
        while lo < hi:
            mid = (lo + hi) // 2
            if self.attempt(*make(mid), kind):
                hi, found = mid, True
            else:
                lo = mid + 1
        return found


Move = Callable[[Search], bool]


def _name(slot: Slot) -> str:
    side, name, i = slot
    return ".".join(p for p in (side, name) if p) + (f"[{i}]" if i >= 0 else "")


def _translate(field: str, axis: int) -> Move:
    """Both bodies moved on ``axis`` so that a coordinate becomes 0; else (centres) A's the
    smallest power of two that still fails (a binary search over the exponent)."""
    def move(s: Search) -> bool:
        slots = (("a", field, axis), ("b", field, axis))
        a, b = (s.best[slot] for slot in slots)

        def shifted(t: float) -> Numbers:
            return s.best | {slots[0]: a - t, slots[1]: b - t}

        what = "centres" if field == "center" else "velocities"
        if s.first([(shifted(t), f"both {what} moved by {-t!r} on axis {axis}")
                    for t in sorted({a, b} - {0.0})], "translated"):
            return True
        top = math.frexp(a)[1] if field == "center" and a else 0
        return top != 0 and s.least(top - 60, top, lambda k: (
            shifted(a - math.copysign(math.ldexp(1.0, k), a)),
            f"both centres moved on axis {axis}: A's coordinate 2^{k}"), "translated")
    return move


def _zero(slot: Slot) -> Move:
    def move(s: Search) -> bool:
        x = s.best[slot]
        return x != 0 and s.attempt(s.best | {slot: 0.0}, f"{_name(slot)} {x!r} -> 0", "zeroed")
    return move


Fields = tuple[str, ...]


def _rescale(label: str, by: Fields, up: Fields, down: Fields) -> Move:
    """``up`` times ``2^k`` (``down`` divided by as much): ``by``'s mean brought to 1, else as
    near as still fails (a binary search over ``k``)."""
    def move(s: Search) -> bool:
        logs = [math.log2(abs(x)) for (_, name, _), x in s.best.items() if name in by and x]
        k0 = -round(statistics.fmean(logs)) if logs else 0

        def scaled(j: int) -> tuple[Numbers, str]:  # j in [-|k0|, 0): k = -j toward k0
            k = int(math.copysign(j, -k0))
            return (s.best | {slot: math.ldexp(x, k if slot[1] in up else -k)
                              for slot, x in s.best.items() if slot[1] in up + down},
                    f"{label} times 2^{k}")
        return k0 != 0 and s.least(-abs(k0), 0, scaled, "rescaled")
    return move


def _cut_all(s: Search) -> bool:
    start = dict(s.best)
    return s.least(1, max(map(decimal_digits, start.values())), lambda k: (
        {slot: _cut(x, k) for slot, x in start.items()},
        f"every number cut to {k} significant digits"), "rounded")


def _round(slot: Slot) -> Move:
    def move(s: Search) -> bool:
        x = s.best[slot]
        extra = {0.5, 1.0} if slot[1] == "restitution" else set()
        if s.first([(s.best | {slot: c}, f"{_name(slot)} {x!r} -> {c!r}")
                    for c in sorted(specials(x) | extra)], "rounded"):
            return True
        return x != 0 and s.least(1, decimal_digits(x), lambda k: (
            s.best | {slot: _cut(x, k)}, f"{_name(slot)} {x!r} cut to {k} digits"), "rounded")
    return move


def _keep_gap(values: Numbers, slot: Slot, size: float) -> Numbers:
    """``values`` with the size at ``slot`` set to ``size`` and B moved to keep the gap."""
    delta, dim = size - values[slot], sum(1 for s in values if s[:2] == ("a", "center"))
    a = [values[("a", "center", i)] for i in range(dim)]
    b = [values[("b", "center", i)] for i in range(dim)]
    away = [y - x for x, y in zip(a, b, strict=True)]
    if slot[1] == "half":
        away = [math.copysign(1.0, d) if i == slot[2] and d else 0.0 for i, d in enumerate(away)]
    length = math.hypot(*away)
    moved = {("b", "center", i): y + d / length * delta
             for i, (y, d) in enumerate(zip(b, away, strict=True))} if length else {}
    return values | {slot: size} | moved


def _resize(slot: Slot) -> Move:
    def move(s: Search) -> bool:
        x = s.best[slot]
        return s.first([(_keep_gap(s.best, slot, c),
                         f"{_name(slot)} {x!r} -> {c!r}, B moved to keep the gap")
                        for c in sorted(specials(x))], "resized")
    return move


Watch = Callable[[Numbers], tuple[float, ...]]
"""The numbers a move reads: a move that failed is tried again only once they changed."""


def _watching(*slots: Slot) -> Watch:
    """A move's watch: these slots (none: every number)."""
    return lambda values: tuple(values[s] for s in slots) if slots else tuple(values.values())


def moves(values: Numbers) -> list[tuple[Move, Watch]]:
    """The moves of one round for a case with these slots, in the order they are tried, each
    with the numbers it reads."""
    dim = sum(1 for s in values if s[:2] == ("a", "center"))
    bs = [("b", "center", i) for i in range(dim)]
    fields = ["center"] + (["velocity"] if ("a", "velocity", 0) in values else [])
    found = [(_translate(f, i), _watching(("a", f, i), ("b", f, i)))
             for f in fields for i in range(dim)]
    found += [(_zero(s), _watching(s)) for s in values if s[1] in ZEROABLE]
    lengths, v = ("center", *SIZES), ("velocity",)
    if ("", "duration", -1) in values:  # times of impact: lengths with velocities, then time
        rescales = [_rescale("lengths and velocities", SIZES, (*lengths, *v), ()),
                    _rescale("velocities (duration inversely)", v, v, ("duration",))]
    else:
        rescales = [_rescale("lengths", SIZES, lengths, ())]
    if ("a", "mass", -1) in values:
        rescales += [_rescale("velocities", v, v, ()), _rescale("masses", ("mass",), ("mass",), ())]
    found += [(move, _watching()) for move in [*rescales, _cut_all]]
    found += [(_round(s), _watching(s)) for s in values]
    return found + [(_resize(s), _watching(s, *bs)) for s in values if s[1] in SIZES]


def shrink_case(case: AnyCase, adapter: Adapter, signature: Signature, executor: Executor,
                options: RunOptions, max_calls: int = MAX_CALLS) -> Shrunk:
    """``case`` shrunk to the simplest case found that fails the same way on ``adapter``."""
    judge = Judge(adapter, signature, executor, options, max_calls)
    valid = not isinstance(case, SceneCase) and build(case, numbers(case)) is not None
    record = judge(case) if valid else None
    if record is None:
        return Shrunk(adapter.name, signature, case, case, None, judge.calls, judge.crashed)
    search = Search(case, judge, record)
    rounds = moves(search.best)
    failed: dict[int, tuple[float, ...]] = {}  # move -> the numbers it read when it failed
    every = False  # a round that tries every move again: the last, unless it makes progress
    while not judge.spent:
        progress = False
        for n, (move, watch) in enumerate(rounds):
            if not every and failed.get(n) == watch(search.best):
                continue
            if move(search):
                progress = True
            else:
                failed[n] = watch(search.best)
        if every and not progress:
            break
        every = not progress
    shrunk = build(case, search.best)
    assert shrunk is not None
    return Shrunk(adapter.name, signature, case, shrunk, search.record, judge.calls,
                  judge.crashed, tuple(search.steps))
