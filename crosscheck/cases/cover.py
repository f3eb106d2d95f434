"""Covering designs over the configuration space: ``[[cover]]`` blocks, and coverage counts.

A design is a list of cells such that every *required tuple* (every pair of levels of every
two dimensions; with strength 3, every triple of levels of the strong dimensions as well)
lies in at least one case.  It is built greedily, AETG-style: each new case starts from the
first tuple not yet covered and takes, dimension by dimension in a seeded order, the level
that completes the most uncovered tuples (after a miss, the tuple alone, every other
dimension at its default level, then greedily again).  Each case is then realised
(:mod:`crosscheck.cases.realize`) and placed back by its geometry
(:func:`crosscheck.cases.space.classify`): only what the realised case *is* counts as
covered.  A tuple that three realisations miss is reported as not reached: mostly out of
float64's reach (a gap of one ulp of the size at 10^15 from the origin, spheres touching
exactly on a diagonal of irrational length), never silently dropped.

The same tuples measure any suite: :func:`coverage` counts which of a space's tuples a list
of cases covers, whatever made them.

>>> from crosscheck.core.schema import CoverBlock
>>> block = CoverBlock(id="cv", description="d", kind="sphere", dim=2,
...                    dimensions=("direction", "gap"), levels={"gap": ("0", "+1")})
>>> [c.id for c in expand_cover(block).cases]  # doctest: +NORMALIZE_WHITESPACE
['cv.dir=+x,gap=+1', 'cv.dir=+x,gap=0', 'cv.dir=+y,gap=+1', 'cv.dir=+y,gap=0',
 'cv.dir=-x,gap=+1', 'cv.dir=-x,gap=0', 'cv.dir=-y,gap=+1', 'cv.dir=-y,gap=0',
 'cv.dir=diag-2,gap=+1', 'cv.dir=oblique,gap=+1', 'cv.dir=oblique,gap=0']
>>> expand_cover(block).unreachable
[(('direction', 'diag-2'), ('gap', '0'))]
"""

from __future__ import annotations

import itertools
import random
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field

from crosscheck.cases.realize import realize
from crosscheck.cases.space import SPACES, Cell, Space, classify, space_of
from crosscheck.core.model import Kind
from crosscheck.core.schema import CASE_ADAPTER, AnyCase, CoverBlock

Item = tuple[str, str]
"""One dimension at one level."""
Tuple = tuple[Item, ...]
"""Levels of two or three dimensions, in the space's dimension order."""
SHORT = {"direction": "dir", "gap": "gap", "size_ratio": "ratio", "aspect": "aspect",
         "scale": "scale", "offset": "off", "offset_axis": "axis", "mass_ratio": "mass",
         "speed": "speed", "restitution": "e", "angle": "angle", "duration": "t"}
"""The short name of each dimension in generated ids."""
CANDIDATES = 3
"""Greedy candidates built per case; the one completing most uncovered tuples is kept."""
MISSES = 3
"""Realisations that must miss a tuple before it is reported out of float64's reach."""


class CoverError(ValueError):
    """A ``[[cover]]`` block naming what its kind's space does not have; ``field`` says where."""

    def __init__(self, field: str, reason: str) -> None:
        super().__init__(reason)
        self.field = field


@dataclass(frozen=True, slots=True)
class Plan:
    """What a design must cover: its dimensions, their levels, strength and strong ones."""

    space: Space
    levels: dict[str, tuple[str, ...]]
    strength: int = 2
    strong: tuple[str, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.levels)

    def tuples(self) -> set[Tuple]:
        """Every required tuple (the pairs of offset 0 with an offset axis do not exist)."""
        out = set(_tuples(self.levels, 2))
        if self.strength == 3:
            out |= set(_tuples({n: self.levels[n] for n in self.strong}, 3))
        return out


def _tuples(levels: dict[str, tuple[str, ...]], t: int) -> Iterator[Tuple]:
    for names in itertools.combinations(levels, t):
        for combo in itertools.product(*(levels[n] for n in names)):
            items = tuple(zip(names, combo, strict=True))
            if _applies(dict(items)):
                yield items


def _applies(cell: Cell) -> bool:
    """An offset axis exists only off the origin."""
    return not ("offset_axis" in cell and cell.get("offset") == "0")


def plan_of(block: CoverBlock) -> Plan:
    """The plan of ``block``, checked against its kind's space (:class:`CoverError`)."""
    space = space_of(Kind(block.kind), block.dim)
    assert space is not None  # every kind a block may name has a space
    names = block.dimensions if block.dimensions is not None else space.names
    for name in names:
        if name not in space.names:
            raise CoverError("dimensions", f"{block.kind} in {block.dim}-D has no dimension "
                                           f"{name!r} (it has {', '.join(space.names)})")
    if len(set(names)) != len(names) or len(names) < 2:
        raise CoverError("dimensions", "name two or more dimensions, each once")
    levels = {n: space.dimension(n).levels for n in space.names if n in names}
    for name, chosen in (block.levels or {}).items():
        if name not in levels:
            raise CoverError(f"levels.{name}", f"{name!r} is not one of the block's dimensions")
        wrong = [x for x in chosen if x not in levels[name]]
        if wrong or not chosen:
            raise CoverError(f"levels.{name}", f"no level {wrong or '(none)'} of {name} "
                                               f"(its levels: {', '.join(levels[name])})")
        levels[name] = tuple(chosen)
    strong = block.strong if block.strong is not None else tuple(
        n for n in space.strong if n in levels)
    if block.strength == 3 and (len(strong) < 3 or not set(strong) <= set(levels)):
        raise CoverError("strong", f"strength 3 needs three or more of the block's dimensions "
                                   f"(got {list(strong)})")
    return Plan(space, levels, block.strength, strong)


@dataclass
class Design:
    """A block's cases, what they cover and what float64 cannot reach."""

    cases: list[AnyCase] = field(default_factory=list)
    required: int = 0
    unreachable: list[Tuple] = field(default_factory=list)


def expand_cover(block: CoverBlock, source: str = "") -> Design:
    """The cases of ``block`` (raises :class:`CoverError` on a block its space rejects)."""
    plan = plan_of(block)
    uncovered = plan.tuples()
    design = Design(required=len(uncovered))
    rng = random.Random(f"{block.id}:{block.seed}")
    misses: Counter[Tuple] = Counter()
    seen: set[str] = set()
    reached: set[Tuple] = set()
    while uncovered:
        target = min(uncovered)
        cell = dict(target) if misses[target] == 1 else max(
            (_candidate(plan, target, uncovered, rng) for _ in range(CANDIDATES)),
            key=lambda c: _gain(c, uncovered, plan))
        case = _case(block, plan, cell, source)
        got = set(_within(classify(case), plan)) if case.id not in seen else set()
        seen.add(case.id)
        if target not in got:
            misses[target] += 1
            if misses[target] >= MISSES:
                uncovered.discard(target)
                design.unreachable.append(target)
        if got & uncovered:
            uncovered -= got
            reached |= got
            design.cases.append(case)
    design.unreachable = sorted(set(design.unreachable) - reached)  # reached later after all
    return design


def _candidate(plan: Plan, target: Tuple, uncovered: set[Tuple], rng: random.Random) -> Cell:
    cell: Cell = dict(target)
    rest = [n for n in plan.names if n not in cell]
    rng.shuffle(rest)
    for name in rest:
        options = list(plan.levels[name])
        rng.shuffle(options)
        cell[name] = max(options, key=lambda level: _completes(cell, name, level, uncovered,
                                                               plan))
    return cell if _applies(cell) else {k: v for k, v in cell.items() if k != "offset_axis"}


def _completes(cell: Cell, name: str, level: str, uncovered: set[Tuple], plan: Plan) -> int:
    """How many uncovered tuples adding ``name = level`` to ``cell`` completes."""
    order = plan.names
    chosen = [(n, v) for n, v in cell.items() if n != name]
    count = 0
    for size in (1, 2) if plan.strength == 3 and name in plan.strong else (1,):
        for others in itertools.combinations(chosen, size):
            if size == 2 and not all(n in plan.strong for n, _ in others):
                continue
            items = tuple(sorted((*others, (name, level)), key=lambda it: order.index(it[0])))
            count += items in uncovered
    return count


def _gain(cell: Cell, uncovered: set[Tuple], plan: Plan) -> int:
    return len(set(_within(cell, plan)) & uncovered)


def _within(cell: Cell, plan: Plan) -> Iterator[Tuple]:
    """The required tuples a cell covers (only the plan's dimensions and levels)."""
    kept = {n: cell[n] for n in plan.names if cell.get(n) in plan.levels[n]}
    yield from _tuples({n: (v,) for n, v in kept.items()}, 2)
    if plan.strength == 3:
        yield from _tuples({n: (v,) for n, v in kept.items() if n in plan.strong}, 3)


def _case(block: CoverBlock, plan: Plan, cell: Cell, source: str) -> AnyCase:
    cid = block.id + "." + ",".join(f"{SHORT[n]}={cell[n]}" for n in plan.names if n in cell)
    rng = random.Random(f"{cid}:{block.seed}")
    data = realize(plan.space, cell, rng)
    words = ", ".join(f"{n.replace('_', ' ')} {cell[n]}" for n in plan.names if n in cell)
    case = CASE_ADAPTER.validate_python(data | {
        "id": cid, "source": source, "tags": ["cover", *block.tags], "swap": block.swap,
        "description": f"{block.description}: {words}"})
    return case.model_copy(update={"origin": block.id})


@dataclass(frozen=True, slots=True)
class Coverage:
    """How much of one space a list of cases covers, at one strength."""

    kind: Kind
    dim: int
    strength: int
    covered: int
    cells: int
    cases: int

    @property
    def share(self) -> float:
        return self.covered / self.cells if self.cells else 0.0


def full_plan(space: Space, strength: int) -> Plan:
    """Every dimension at every level (strength 3: also the triples of the space's strong
    dimensions)."""
    levels = {d.name: d.levels for d in space.dimensions}
    return Plan(space, levels, strength, space.strong)


def coverage(cases: Iterable[AnyCase], strength: int = 2,
             cell_of: Callable[[AnyCase], Cell] = classify) -> list[Coverage]:
    """Per space, the tuples of the given strength (3: the strong dimensions' triples only)
    that ``cases`` cover, placing each case by :func:`classify` (or ``cell_of``: the same
    cells, remembered)."""
    found: dict[tuple[Kind, int], set[Tuple]] = {}
    counts: Counter[tuple[Kind, int]] = Counter()
    for case in cases:
        space = space_of(case.kind_enum, case.dim)
        if space is None or case.bad_input:
            continue
        key = (space.kind, space.dim)
        counts[key] += 1
        plan = full_plan(space, strength)
        found.setdefault(key, set()).update(t for t in _within(cell_of(case), plan)
                                            if len(t) == strength)
    out = []
    for key, space in _spaces_in_order():
        wanted = {t for t in full_plan(space, strength).tuples() if len(t) == strength}
        out.append(Coverage(space.kind, space.dim, strength, len(found.get(key, set()) & wanted),
                            len(wanted), counts[key]))
    return out


def _spaces_in_order() -> Sequence[tuple[tuple[Kind, int], Space]]:
    return sorted(SPACES.items(), key=lambda kv: (list(Kind).index(kv[0][0]), -kv[0][1]))
