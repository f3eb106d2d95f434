"""Load and validate case files: TOML -> pydantic models -> semantic checks -> Cases.

Every problem becomes a :class:`CaseError` naming the file, the case id, the
field and the reason; a bad block never stops the good ones from loading.  A file that
loaded without errors is kept in the case cache (:mod:`crosscheck.cases.cache`, keyed by
its bytes and the loader's code), so the next run does not validate it again.

>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "c.toml"
>>> _ = p.write_text('''[[case]]
... id = "s1"
... description = "negative radius"
... kind = "sphere"
... dim = 2
... a = { center = [0.0, 0.0], radius = -1.0 }
... b = { center = [1.0, 0.0], radius = 0.5 }
... ''')
>>> result = load_paths([p])
>>> print(result.errors[0].message.replace(str(p), "c.toml"))  # doctest: +ELLIPSIS
c.toml:6: case 's1': field a.radius: must be >= 0, got -1.0 (tag the case 'bad-input' ...)

Over 400 lines: loading, validation, expansion errors and the 2-D twin check share one
error type and one line-finding pass, and are kept in one module.
"""

from __future__ import annotations

import io
import itertools
import math
import tomllib
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from crosscheck.cases import cache as case_cache
from crosscheck.cases.cover import CoverError, expand_cover
from crosscheck.cases.expand import (
    AXIS_NAMES,
    PLANES,
    SweepError,
    TwinError,
    expand,
    flattened,
    with_swaps,
)
from crosscheck.cases.messages import plain
from crosscheck.cases.world_sweep import world_problems
from crosscheck.core.model import Undefined, Value, quantities_of
from crosscheck.core.schema import (
    CASE_ADAPTER,
    LOADER_FIELDS,
    AabbBody,
    AnyCase,
    CoverBlock,
    MovingSphere,
    Plane,
    ResponseCase,
    SceneCase,
    SphereBody,
    SphereCase,
    SweptSphere,
    ToiCase,
)
from crosscheck.truth import oracle


@dataclass(frozen=True, slots=True)
class CaseError:
    """A validation problem: where (file, case, field) and why."""

    file: str
    case_id: str
    field: str
    reason: str
    line: int = 0
    """The line in the file (0: not known, e.g. a sweep point made by expansion)."""

    @property
    def message(self) -> str:
        case = ("" if self.case_id == "-" else f"{self.case_id}: "
                if self.case_id.startswith("[[") else f"case {self.case_id}: ")
        where = f"field {self.field}: " if self.field else ""
        at = f"{self.file}:{self.line}" if self.line else self.file
        return f"{at}: {case}{where}{self.reason}"

    def __str__(self) -> str:
        return self.message


@dataclass
class LoadResult:
    """The cases that loaded and the errors of those that did not.

    ``blocks`` counts the curated ``[[case]]`` blocks that loaded; ``cases``
    is what runs: sweeps expanded and A/B-swapped twins added.
    """

    cases: list[AnyCase] = field(default_factory=list)
    errors: list[CaseError] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)
    blocks: int = 0


def case_files(paths: Iterable[Path | str]) -> list[Path]:
    """Expand files and directories into a sorted list of ``*.toml`` files."""
    out: list[Path] = []
    for raw in paths:
        path = Path(raw)
        out.extend(sorted(path.rglob("*.toml")) if path.is_dir() else [path])
    return out


def load_paths(paths: Iterable[Path | str], *, cache: bool = True) -> LoadResult:
    """Load every case under ``paths``; duplicate ids across files are errors.

    ``cache``: reuse (and store) the cases of files that loaded without errors before
    (:mod:`crosscheck.cases.cache`; also off with ``CROSSCHECK_NO_CACHE=1``).
    """
    result = LoadResult(files=case_files(paths))
    where = case_cache.folder() if cache else None
    seen: dict[str, str] = {}
    for path in result.files:
        blocks, cases, errors = _load_expanded(path, where)
        result.errors.extend(errors)
        result.blocks += blocks
        for case in cases:
            if case.id in seen:
                first = seen[case.id]
                if "swapped" not in case.tags:  # a duplicate's twin is a duplicate too
                    result.errors.append(CaseError(str(path), repr(case.id), "id",
                                                   f"duplicate id, first defined in {first}"))
                continue
            seen[case.id] = str(path)
            result.cases.append(case)
    return result


def _load_expanded(path: Path, where: Path | None) -> tuple[int, list[AnyCase], list[CaseError]]:
    """One file's block count, cases (sweeps expanded, twins and swaps added) and errors,
    from the cache when the same bytes loaded without errors under the same code."""
    try:
        data = path.read_bytes()
        text: str | None = io.TextIOWrapper(io.BytesIO(data), encoding="utf-8").read()
    except (OSError, UnicodeDecodeError):  # load_file below says so, with the reason
        data, text = b"", None
    name = case_cache.key(path, data) if where is not None and text is not None else None
    stored = case_cache.get(where, name) if where is not None and name is not None else None
    if stored is not None:
        return stored.blocks, stored.cases, []
    blocks, errors = load_file(path) if text is None else load_text(path, text)
    cases = list(with_swaps(_expanded(path, blocks, errors)))
    curated = sum(1 for block in blocks if not block.origin)  # not made by a [[cover]] block
    if where is not None and name is not None and not errors:
        case_cache.put(where, name, curated, cases)
    return curated, cases, errors


def _expanded(path: Path, blocks: list[AnyCase], errors: list[CaseError]) -> list[AnyCase]:
    """Every sweep point of every block; problems of a point become errors."""
    out: list[AnyCase] = []
    for block in blocks:
        try:
            points = expand(block)
        except SweepError as exc:
            errors.append(CaseError(str(path), repr(block.id), exc.field, str(exc)))
            continue
        by_id = {point.id: point for point in points}
        for point in points:
            problems = semantic_problems(point) if point is not block else []
            if point.from_3d and not problems:
                problems = twin_problems(by_id[point.from_3d], point)
            errors.extend(CaseError(str(path), repr(point.id), f, r) for f, r in problems)
            out += [] if problems else [point]
    return out


def twin_problems(original: AnyCase, twin: AnyCase) -> list[tuple[str, str]]:
    """A 2-D twin must have its 3-D case's exact answer, quantity by quantity.

    A vector of the 3-D answer (normal, velocity) must be 0 on the dropped axis and
    equal the twin's on the other two; two Undefined values are the same answer.
    """
    if original.twin_2d is None:
        return [("twin_2d", f"{original.id!r} has no 2-D twin")]
    axis = PLANES[original.twin_2d]
    want, got = oracle.truth(original), oracle.truth(twin)
    return [("twin_2d", f"dropping the {AXIS_NAMES[axis]} axis changes the exact "
                        f"{quantity}: {w!r} in 3-D, {g!r} in 2-D")
            for quantity in quantities_of(original.kind_enum)
            if not _same_answer(w := want.get(quantity), g := got.get(quantity), axis)]


def plane_of(case: AnyCase) -> Plane | None:
    """The first plane (xy, xz, yz) in which a 3-D case has a 2-D twin with its exact answer.

    None when it has none: a 2-D case, a scene, or a contact that needs all three axes
    (centres apart on every axis, boxes overlapping least along the only shared axis).
    """
    if isinstance(case, SceneCase) or case.dim != 3:
        return None
    for plane in PLANES:
        try:
            twin = flattened(case, plane)
        except TwinError:
            continue
        if not twin_problems(case.model_copy(update={"twin_2d": plane}), twin):
            return plane
    return None


def _same_answer(in_3d: Value | None, in_2d: Value | None, axis: int) -> bool:
    if isinstance(in_3d, Undefined) or isinstance(in_2d, Undefined):
        return isinstance(in_3d, Undefined) and isinstance(in_2d, Undefined)
    if isinstance(in_3d, tuple):
        kept = tuple(x for i, x in enumerate(in_3d) if i != axis)
        return in_3d[axis] == 0 and _equal(kept, in_2d)
    return _equal(in_3d, in_2d)


def _equal(x: object, y: object) -> bool:
    """Equal, counting NaN equal to NaN (also inside a vector)."""
    if isinstance(x, tuple) and isinstance(y, tuple):
        return len(x) == len(y) and all(_equal(a, b) for a, b in zip(x, y, strict=True))
    both_nan = isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y)
    return both_nan or x == y


def load_file(path: Path) -> tuple[list[AnyCase], list[CaseError]]:
    """Parse one TOML file and validate each ``[[case]]`` block on its own; each
    ``[[cover]]`` block adds the cases of its design."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        return [], [CaseError(str(path), "-", "", f"cannot read file: {exc}")]
    return load_text(path, text)


def load_text(path: Path, text: str) -> tuple[list[AnyCase], list[CaseError]]:
    """:func:`load_file` of ``text``, the content of ``path`` as ``read_text`` reads it."""
    name = str(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        return [], [CaseError(name, "-", "", f"TOML syntax error: {exc}")]
    blocks, covers = data.pop("case", []), data.pop("cover", [])
    errors = [CaseError(name, "-", key, "unknown top-level key (expected only [[case]] and "
                                        "[[cover]])") for key in data]
    if not isinstance(blocks, list) or not isinstance(covers, list) or not blocks + covers:
        return [], [*errors, CaseError(name, "-", "case", "no [[case]] or [[cover]] blocks "
                                                          "in file")]
    cases: list[AnyCase] = []
    lines = text.splitlines()
    for header, entries in (("[[case]]", blocks), ("[[cover]]", covers)):
        starts = [i for i, line in enumerate(lines) if line.strip().replace(" ", "") == header]
        for index, block in enumerate(entries):
            span = _span(starts, index, len(lines))
            made, block_errors = (_validate_block(name, index, block) if header == "[[case]]"
                                  else _cover_cases(name, index, block))
            block_errors = [replace(e, line=_line(lines, span, e.field)) for e in block_errors]
            errors.extend(block_errors)
            cases += made if not block_errors else []
    return cases, errors


def _cover_cases(name: str, index: int, block: Any) -> tuple[list[AnyCase], list[CaseError]]:
    """The cases of one ``[[cover]]`` block, or why it is wrong (file, block, field, reason)."""
    label = "[[cover]] " + _label(index, block)
    try:
        design = expand_cover(CoverBlock.model_validate(block), name)
    except ValidationError as exc:
        return [], [_problem(name, label, dict(err)) for err in exc.errors()]
    except CoverError as exc:
        return [], [CaseError(name, label, exc.field, str(exc))]
    problems = [CaseError(name, repr(c.id), f, r) for c in design.cases
                for f, r in semantic_problems(c)]
    return design.cases, problems


def _span(starts: list[int], index: int, end: int) -> tuple[int, int]:
    """The 0-based line range of the ``index``-th ``[[case]]`` block."""
    if index >= len(starts):
        return (0, 0)
    return (starts[index], starts[index + 1] if index + 1 < len(starts) else end)


def _line(lines: list[str], span: tuple[int, int], field: str) -> int:
    """The 1-based line of ``field``'s top-level key within the block (else its header)."""
    key = field.split(".")[0].split("[")[0]
    first, last = span
    for i in range(first, last):
        if key and lines[i].split("=")[0].strip() == key:
            return i + 1
    return first + 1 if last > first else 0


def _problem(name: str, label: str, err: dict[str, Any]) -> CaseError:
    reason, where = plain(err)
    return CaseError(name, label, where, reason)


def _label(index: int, block: object) -> str:
    raw = block.get("id") if isinstance(block, dict) else None
    return repr(raw) if isinstance(raw, str) else f"#{index + 1} (no valid id)"


def _validate_block(name: str, index: int, block: Any) -> tuple[list[AnyCase], list[CaseError]]:
    label = _label(index, block)
    if isinstance(block, dict):
        loader_set = [key for key in LOADER_FIELDS if key in block]
        if loader_set:
            return [], [CaseError(name, label, key, "set by the loader (where the case comes "
                                    "from, its sweep coordinates, its swapped twin, its 3-D "
                                    "case), not in a case file") for key in loader_set]
        block = {**block, "source": name}
    try:
        case = CASE_ADAPTER.validate_python(block)
    except ValidationError as exc:
        return [], [_problem(name, label, dict(err)) for err in exc.errors()]
    return [case], [CaseError(name, label, f, r) for f, r in semantic_problems(case)]


def semantic_problems(case: AnyCase) -> list[tuple[str, str]]:
    """Rules beyond the schema: vector lengths always; value rules unless bad-input."""
    problems = list(_length_problems(case))
    if case.description.lstrip().upper().startswith("TODO"):
        problems.append(("description", "still the template's TODO: say in a few words what "
                                        "this case probes"))
    if not case.bad_input:
        problems += list(_value_problems(case))
    if not problems:
        problems += list(_expect_problems(case))
    return problems


def _expect_problems(case: AnyCase) -> Iterator[tuple[str, str]]:
    """An author's pinned ``expect`` must agree exactly with the oracle."""
    expect = getattr(case, "expect", None)
    if expect is None:
        return
    truth = oracle.truth(case)
    for name in ("hit", "distance"):
        pinned, exact = getattr(expect, name), truth.get(name)
        if pinned is not None and pinned != exact:
            yield f"expect.{name}", f"pinned {pinned!r} but the exact oracle says {exact!r}"


def _vectors(case: AnyCase) -> Iterator[tuple[str, Sequence[float]]]:
    bodies: tuple[tuple[str, AabbBody | SphereBody], ...] = (
        tuple((f"bodies[{i}]", b) for i, b in enumerate(case.bodies))
        if isinstance(case, SceneCase) else (("a", case.a), ("b", case.b)))
    for side, body in bodies:
        yield f"{side}.center", body.center
        if isinstance(body, AabbBody):
            yield f"{side}.half", body.half
        if isinstance(body, MovingSphere | SweptSphere):
            yield f"{side}.velocity", body.velocity
    if isinstance(case, SceneCase):
        if case.gravity is not None:
            yield "gravity", case.gravity
        for k, wall in enumerate(case.walls):
            yield f"walls[{k}].normal", wall.normal


def _length_problems(case: AnyCase) -> Iterator[tuple[str, str]]:
    for where, vec in _vectors(case):
        if len(vec) != case.dim:
            yield where, f"expected {case.dim} components for dim = {case.dim}, got {len(vec)}"


def _scalars(case: AnyCase) -> Iterator[tuple[str, float]]:
    for where, vec in _vectors(case):
        for i, x in enumerate(vec):
            yield f"{where}[{i}]", x
    if isinstance(case, SphereCase | ResponseCase | ToiCase):
        yield "a.radius", case.a.radius
        yield "b.radius", case.b.radius
    if isinstance(case, ToiCase):
        yield "duration", case.duration
    if isinstance(case, ResponseCase):
        yield "a.mass", case.a.mass
        yield "b.mass", case.b.mass
        yield "restitution", case.restitution
    if isinstance(case, SceneCase):
        for i, body in enumerate(case.bodies):
            yield f"bodies[{i}].radius", body.radius
            yield f"bodies[{i}].mass", body.mass
        yield "restitution", case.restitution
        if case.duration is not None:
            yield "duration", case.duration
        if case.dt is not None:
            yield "dt", case.dt


_HINT = " (tag the case 'bad-input' to test engines on it)"


def _value_problems(case: AnyCase) -> Iterator[tuple[str, str]]:
    for where, x in _scalars(case):
        if not math.isfinite(x):
            yield where, f"must be finite, got {x!r}{_HINT}"
        elif where.endswith((".radius",)) or ".half[" in where:
            if x < 0:
                yield where, f"must be >= 0, got {x!r}{_HINT}"
        elif where.endswith(".mass") and x <= 0:
            yield where, f"must be > 0, got {x!r}{_HINT}"
        elif where == "restitution" and not 0 <= x <= 1:
            yield where, f"must be in [0, 1], got {x!r}"
        elif where in ("duration", "dt") and x <= 0:
            yield where, f"must be > 0, got {x!r}"
    if isinstance(case, SceneCase):
        yield from _scene_problems(case)


MAX_STEPS = 10_000_000
"""Most steps a scene case may ask of an engine (duration / dt)."""


def _scene_problems(case: SceneCase) -> Iterator[tuple[str, str]]:
    """Scene rules beyond the schema: two bodies or more, radii > 0, no overlap at the start."""
    fast = case.sweep is not None and (case.sweep.step_travel or case.sweep.phase)
    if case.duration is None and not fast:
        yield "duration", ("missing: this field is required (unless the block sweeps "
                           "step_travel or phase)")
    if fast and case.duration is not None and not case.origin:
        yield "duration", ("the block sweeps step_travel or phase: each case runs twice its "
                           "time to impact, so leave duration out")
    if len(case.bodies) < (1 if case.walls or case.gravity else 2):
        yield "bodies", ("a scene needs at least two bodies, or one with gravity or walls "
                         "(list them or give a generator)")
    yield from world_problems(case)
    for i, body in enumerate(case.bodies):
        if not body.radius > 0:
            yield f"bodies[{i}].radius", f"must be > 0 in a scene, got {body.radius!r}"
    for (i, p), (j, q) in itertools.combinations(enumerate(case.bodies), 2):
        d2 = sum((Fraction(x) - Fraction(y)) ** 2 for x, y in zip(p.center, q.center, strict=False))
        if d2 < (Fraction(p.radius) + Fraction(q.radius)) ** 2:
            yield f"bodies[{j}].center", f"overlaps bodies[{i}] at the start (touching is allowed)"
    if case.step_count > MAX_STEPS:
        yield "dt", f"{case.step_count} steps exceed {MAX_STEPS}: use a larger dt"
