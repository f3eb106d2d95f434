"""Repro scripts: one standalone Python file per case x engine, to paste into a bug report.

A script uses only the engine's own API (``fcl``, ``pybullet``, ``pymunk``; numpy for the
textbook formula of ``reference`` and ``reference-f32``) and none of crosscheck.  Its inputs
are the stored case's exact binary64 values (``float.fromhex`` literals; ``float("nan")``,
``float("inf")`` for bad input), its calls are those the engine's adapter makes (the
engine parts are :mod:`crosscheck.studies.repro.engines` and
:mod:`crosscheck.studies.repro.pybullet`), so it reproduces the engine's answer bit for
bit.  It prints its inputs first (flushed: a crash still leaves them on screen), then
every quantity of the case as ``<quantity> = <text>``, where ``<text>`` is the JSON text
crosscheck writes in results.csv's ``value`` column, then the exact answer recorded for
the run (``expected <quantity> = ...``), the textbook formula in float64 when the run has
the ``reference`` engine (``textbook <quantity> = ...``) and one ``# convention: ...`` line
from the engine's declared conventions in run.json.

Everything comes from the stored run (:func:`crosscheck.results.store.read_run`): the
cases, the rows, the engines and their conventions.  ``sphere_scene`` cases have no
script (a scene is hundreds of bodies stepped by :mod:`adapters.pybullet_scene` and
:mod:`adapters.pymunk_scene`; reproduce a scene with ``crosscheck run``).

:func:`write_run_scripts` writes ``RUN_DIR/repro/<repro_name>.py`` for every case x
engine with a disagree, error, crash or timeout row; the report links them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import adapters
from adapters.fcl_engine import Fcl
from adapters.pybullet_engine import PyBulletDefault, PyBulletTuned
from adapters.pymunk_engine import PymunkDefault, PymunkTuned
from adapters.reference import ReferenceF32, ReferenceF64
from crosscheck.core.contract import TEXTBOOK_TOUCHING, Adapter
from crosscheck.core.model import Status, quantities_of
from crosscheck.core.schema import AabbCase, AnyCase, PairCase, ResponseCase, SceneCase
from crosscheck.results.store import StoredRun, read_run, repro_name, repro_path
from crosscheck.studies.repro.engines import EngineCode, fcl_code, pymunk_code, reference_code
from crosscheck.studies.repro.pybullet import pybullet_code

Writer = Callable[[Any, PairCase, frozenset[str]], EngineCode]
"""A script writer: (adapter, case, quantities the run recorded as a declared hang)."""
WRITERS: dict[type[Adapter], Writer] = {
    Fcl: lambda adapter, case, hung: fcl_code(case, hung),
    PyBulletTuned: lambda adapter, case, hung: pybullet_code(adapter, case),
    PyBulletDefault: lambda adapter, case, hung: pybullet_code(adapter, case),
    PymunkTuned: lambda adapter, case, hung: pymunk_code(adapter, case),
    PymunkDefault: lambda adapter, case, hung: pymunk_code(adapter, case),
    ReferenceF64: lambda adapter, case, hung: reference_code(adapter, case),
    ReferenceF32: lambda adapter, case, hung: reference_code(adapter, case),
}
"""The script writer of each adapter class (exact classes: a subclass may call otherwise)."""

ENCODE = '''\
def number(x):
    if math.isfinite(x):
        return float.__repr__(x)
    return '"NaN"' if x != x else ('"Infinity"' if x > 0 else '"-Infinity"')


def encode(value):
    # the strict JSON text crosscheck records for a value (results.csv): floats exactly
    if value is None or isinstance(value, str):
        return "null"  # no such quantity, or "undefined": no defined value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return number(value)
    return "[" + ", ".join(number(x) if isinstance(x, float) else encode(x)
                           for x in value) + "]"
'''


class ReproError(ValueError):
    """No script for this case x engine (unknown, a scene, skipped or no script writer)."""


@dataclass(frozen=True)
class Script:
    """One repro script: its case, engine and source text."""

    case_id: str
    engine: str
    text: str

    @property
    def name(self) -> str:
        """Its file name without ``.py`` (:func:`crosscheck.results.store.repro_name`)."""
        return repro_name(self.case_id, self.engine)


Row = dict[str, Any]


class RunRows:
    """A stored run's rows grouped by (case id, engine), read once."""

    def __init__(self, stored: StoredRun) -> None:
        self.stored = stored
        self.pairs: dict[tuple[str, str], list[Row]] = {}
        for record in stored.results.to_dict("records"):
            row = {str(k): v for k, v in record.items()}
            self.pairs.setdefault((str(row["case_id"]), str(row["engine"])), []).append(row)

    def rows(self, case_id: str, engine: str) -> list[Row]:
        return self.pairs.get((case_id, engine), [])

    def engine_info(self, engine: str) -> dict[str, Any]:
        return next((dict(e) for e in self.stored.info.engines if e.get("name") == engine), {})


def literal(x: float) -> str:
    """Python source for exactly ``x``: a ``float.fromhex`` literal, or ``float("nan")``...

    >>> literal(0.1), literal(-0.0), literal(float("-inf")), literal(-float("nan"))
    ('float.fromhex("0x1.999999999999ap-4")', 'float.fromhex("-0x0.0p+0")', \
'-float("inf")', '-float("nan")')
    """
    x = float(x)
    if math.isfinite(x):
        return f'float.fromhex("{x.hex()}")'
    sign = "-" if math.copysign(1.0, x) < 0 else ""
    return f'{sign}float("{"nan" if math.isnan(x) else "inf"}")'


def _vector(v: Sequence[float]) -> str:
    return "(" + ", ".join(literal(x) for x in v) + ")"


def _plain(name: str, case: PairCase) -> str:
    """The input called ``name`` (``A_CENTER`` ...) as Python prints it."""
    which, _, field = name.lower().partition("_")
    if which not in ("a", "b"):
        return repr(getattr(case, name.lower()))
    value = getattr(getattr(case, which), field)
    return repr(value)


def _inputs(case: PairCase) -> list[tuple[str, str, str]]:
    """(constant, source, label) of every input of the case."""
    out = []
    for which in ("a", "b"):
        body = getattr(case, which)
        out.append((f"{which.upper()}_CENTER", _vector(body.center), f"{which}.center"))
        if isinstance(case, AabbCase):
            out.append((f"{which.upper()}_HALF", _vector(body.half), f"{which}.half"))
        else:
            out.append((f"{which.upper()}_RADIUS", literal(body.radius), f"{which}.radius"))
        if isinstance(case, ResponseCase):
            out.append((f"{which.upper()}_MASS", literal(body.mass), f"{which}.mass"))
            out.append((f"{which.upper()}_VELOCITY", _vector(body.velocity),
                        f"{which}.velocity"))
    if isinstance(case, ResponseCase):
        out.append(("RESTITUTION", literal(case.restitution), "restitution"))
    return out


def comment(text: object) -> str:
    """``text`` made safe for one comment line (control characters escaped)."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


def convention(info: dict[str, Any], case: PairCase) -> str:
    """The one line of the engine's declared conventions that applies to the case's kind."""
    conv: dict[str, Any] = info.get("conventions") or {}
    if not conv:
        return "# convention: (the run does not record this engine's conventions)"
    if isinstance(case, ResponseCase):
        step = conv.get("time_step")
        parts = [f"restitution {conv.get('restitution', '')}",
                 f"restitution threshold {conv.get('restitution_threshold', 0.0):g}",
                 "bodies already separating get " + (
                     "the textbook exchange" if conv.get("resolves_separating", True)
                     else "no impulse")]
        parts += [f"time step {step:g} s"] if step else []
    else:
        features = ("sphere",) if case.kind == "sphere" else ("face", "edge", "corner")
        touching: dict[str, bool] = conv.get("touching") or {}
        margins: dict[str, float] = conv.get("margins") or {}
        rule = ", ".join(f"{f} {'contact' if touching.get(f, TEXTBOOK_TOUCHING[f]) else 'apart'}"
                         for f in features)
        margin = ", ".join(f"{f} {margins.get(f, 0.0):g}" for f in features)
        parts = [f"normal {conv.get('normal', '')}", f"touching: {rule}",
                 f"margin: {margin}", f"rtol {conv.get('rtol', 0.0):.3g}"]
    return comment(f"# convention ({info.get('name', '')}): " + "; ".join(parts))


def _values(rows: Iterable[Row], column: str) -> dict[str, str]:
    return {str(r["quantity"]): str(r[column]) for r in rows}


def _header(case: PairCase, info: dict[str, Any], rows: list[Row], run_id: str,
            notes: Sequence[str]) -> list[str]:
    engine = f"{info.get('engine', '')} {info.get('version', '')}".strip()
    title = comment(f"Reproduce crosscheck case {case.id} on engine {info.get('name')} "
                    f"({engine}).").replace("\\", "/").replace('"', "'")
    lines = [f'"""{title}"""',
             f"# Case: {case.description}", f"# Kind {case.kind}, {case.dim}-D; file "
             f"{case.source or '-'}", f"# Adapter settings: {info.get('settings', '')}",
             f"# Recorded in run {run_id}:"]
    lines += [f"#   {r['quantity']} = {r['value']}  [{r['status']}"
              + (f", {r['category']}" if r["category"] else "")
              + (f": {r['reason']}" if r["reason"] else "") + "]" for r in rows]
    if any(Status(r["status"]) in (Status.CRASH, Status.TIMEOUT) for r in rows):
        lines.append("# The engine's worker died or hung there: the script prints its inputs "
                     "first, then makes the same call.")
    lines += ["# Standalone: no crosscheck, only the imports below; the calls crosscheck's "
              "adapter makes.", "# It prints the engine's answer as crosscheck records it "
              "(`<quantity> = <JSON text>`),", "# then the exact answer (expected), the "
              "textbook formula in float64 (textbook) and the convention.",
              *(f"# {note}" for note in notes)]
    return [lines[0], *(comment(line) if line.startswith("#") else line
                        for line in lines[1:])]


def _imports(engine: EngineCode) -> list[str]:
    standard = sorted({"import json", "import math", "import sys",
                       *(i for i in engine.imports if i in ("import math",))})
    third = [i for i in engine.imports if i not in standard]
    return [*standard, "", *third]


def _prints(case: PairCase, engine: EngineCode, rows: list[Row], textbook: list[Row],
            info: dict[str, Any]) -> list[str]:
    quantities = quantities_of(case.kind_enum)
    lines = [f'print("{q} = " + encode({q}))' for q in quantities]
    if engine.resolved_at:
        lines.append('print("# resolved at (centres of A and B):", resolved_at)')
    lines.append(f"EXPECTED = {_values(rows, 'truth')!r}  # the exact answer, from the run")
    lines.append('for quantity, text in EXPECTED.items():\n'
                 '    print(f"expected {quantity} = {text}")')
    if textbook:
        lines.append(f"TEXTBOOK = {_values(textbook, 'value')!r}  # the reference engine's "
                     "value in the run")
        lines.append('for quantity, text in TEXTBOOK.items():\n'
                     '    print(f"textbook {quantity} = {text}")')
    else:
        lines.append('print("# textbook float64 answer: not in this run")')
    lines.append(f"print({convention(info, case)!r})")
    return lines


def script_text(case: PairCase, engine: EngineCode, info: dict[str, Any], rows: list[Row],
                textbook: list[Row], run_id: str) -> str:
    """The whole script of ``case`` with ``engine``'s statements (see the module docstring)."""
    inputs = _inputs(case)
    parts = [
        "#!/usr/bin/env python3", *_header(case, info, rows, run_id, engine.notes), "",
        *_imports(engine), "", "# The case's inputs: exact binary64 values.",
        *(f"{name} = {source}  # {_plain(name, case)}" for name, source, _ in inputs), "", "",
        ENCODE, "",
        f"print({comment('# case ' + case.id + ' on ' + str(info.get('name')))!r})",
        *(f'print("# {label} =", {name})' for name, _, label in inputs),
        "sys.stdout.flush()  # the inputs are on screen even if the engine crashes", "",
        engine.code, *_prints(case, engine, rows, textbook, info),
        *([engine.tail] if engine.tail else [])]
    return "\n".join(parts) + "\n"


def _pair_case(stored: StoredRun, case_id: str) -> PairCase:
    case: AnyCase | None = stored.cases.get(case_id)
    if case is None:
        raise ReproError(f"no case {case_id!r} in {stored.directory}")
    if isinstance(case, SceneCase):
        raise ReproError(f"{case_id}: sphere_scene cases have no repro script (run the scene "
                         "with crosscheck run)")
    return case


def _writer(engine: str) -> tuple[Adapter, Writer] | None:
    try:
        adapter = adapters.get(engine)
    except adapters.UnknownEngine:
        return None
    writer = WRITERS.get(type(adapter))
    return None if writer is None else (adapter, writer)


def hung(rows: list[Row]) -> frozenset[str]:
    """Quantities the run recorded as timeout while others of the pair answered (a declared
    hang of some quantities only, asked without them)."""
    timeouts = frozenset(str(r["quantity"]) for r in rows if r["status"] == Status.TIMEOUT)
    return timeouts if len(timeouts) < len(rows) else frozenset()


def _ran(rows: list[Row]) -> bool:
    """Whether the engine ran the case (a case it does not support is all skip rows)."""
    return any(Status(r["status"]) is not Status.SKIP for r in rows)


def build(runs: RunRows, case_id: str, engine: str) -> Script:
    """The script of ``case_id`` on ``engine`` in a run, or :class:`ReproError` why not."""
    case = _pair_case(runs.stored, case_id)
    rows = runs.rows(case_id, engine)
    if not rows:
        raise ReproError(f"engine {engine!r} has no rows for case {case_id!r} in this run")
    if not _ran(rows):
        raise ReproError(f"{engine} did not run {case_id}: {rows[0]['reason']}")
    found = _writer(engine)
    if found is None:
        raise ReproError(f"no repro script writer for engine {engine!r}")
    adapter, writer = found
    text = script_text(case, writer(adapter, case, hung(rows)), runs.engine_info(engine), rows,
                       runs.rows(case_id, "reference"), runs.stored.info.run_id)
    return Script(case_id, engine, text)


def engines_for(runs: RunRows, case_id: str) -> list[str]:
    """Engines to script for a case: those with a non-agree row, else every engine that ran it.

    Only engines that ran the case and have a script writer count.
    """
    ran = [e for e in runs.stored.info.engine_names
           if _ran(runs.rows(case_id, e)) and _writer(e) is not None]
    bad = [e for e in ran
           if any(Status(r["status"]) is not Status.AGREE for r in runs.rows(case_id, e))]
    return bad or ran


def scripts(stored: StoredRun, case_id: str, engine: str | None = None) -> list[Script]:
    """The scripts of ``case_id``: for ``engine``, or for :func:`engines_for` the case."""
    runs = RunRows(stored)
    _pair_case(stored, case_id)
    names = [engine] if engine else engines_for(runs, case_id)
    if not names:
        raise ReproError(f"no engine of this run ran case {case_id!r} with a script writer")
    return [build(runs, case_id, name) for name in names]


def breaking_pairs(runs: RunRows) -> list[tuple[str, str]]:
    """Every (case id, engine) with a disagree, error, crash or timeout row, in run order."""
    breaking = Status.members("breaking")
    return [pair for pair, rows in runs.pairs.items()
            if any(r["status"] in breaking for r in rows)]


def write_run_scripts(directory: Path) -> list[Path]:
    """Write ``directory/repro/<repro_name>.py`` for every breaking case x engine; the paths.

    Pairs without a script (scenes, engines without a writer) are left out.
    """
    runs = RunRows(read_run(directory))
    written = []
    for case_id, engine in breaking_pairs(runs):
        try:
            made = build(runs, case_id, engine)
        except ReproError:
            continue
        path = repro_path(directory, case_id, engine)
        path.parent.mkdir(exist_ok=True)
        path.write_text(made.text, encoding="utf-8")
        written.append(path)
    return written
