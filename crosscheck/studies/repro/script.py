"""Repro scripts: one standalone Python file per case x engine, to paste into a bug report.

A script uses only the engine's own API (``fcl``, ``pybullet``, ``pymunk``, ``mujoco``,
``coal``, ``Box2D``, ``rapier3d``; ``reference_impl.formulas`` for the textbook formula of
``reference`` and ``reference-f32``) and none of crosscheck.  Its inputs are the stored
case's exact binary64 values (``float.fromhex`` literals; ``float("nan")``, ``float("inf")``
for bad input), its calls are those the engine's adapter makes (its calls module's source,
verbatim: :mod:`crosscheck.studies.repro.calls`), so it reproduces the engine's answer bit for
bit.  It prints first (flushed: a
crash, an exception or a hang still leaves it on screen) its inputs and what the run recorded
beside the answer (:mod:`crosscheck.studies.repro.verdicts`): the exact answer (``expected
<quantity> = ...``), each quantity's verdict with its error against the float64 bound, the
textbook formula in float64 when the run has the ``reference`` engine (``textbook <quantity> =
...``) and the engine's declared conventions; then it asks the engine and prints every
quantity of the case as ``<quantity> = <text>``, where ``<text>`` is the JSON text crosscheck
writes in results.csv's ``value`` column.

Scenes (``sphere_scene``, stepped by PyBullet, pymunk, Box2D, MuJoCo and Rapier) are calls
too: the engine's scene call builds the scene with its gravity and walls, steps it (recording
the states every ``scene_measures.record_every`` steps when it has gravity or walls) and
answers with the final ``positions`` and ``velocities``, the total ``momentum`` and ``energy``,
and the measures computed by the harness's own functions (:mod:`reference_impl.scene_measures`,
held as source): ``settle``, ``jitter``, ``energy_drift``, ``apex`` and ``bounce_time``, with a
comment on ``divergence`` (judged by crosscheck against the exact trajectory: the run's
value); in open space only ``energy_drift``, the others a comment.

Everything comes from the stored run (:func:`crosscheck.results.run.read_run`): the
cases, the rows, the engines and their conventions.  A run writes no script:
``crosscheck repro`` prints one on demand, and :func:`write_run_scripts` (``crosscheck repro
RUN_DIR --all``) writes ``RUN_DIR/repro/<repro_name>.py`` for every case x engine with a
disagree, error, crash or timeout row; the report links those it finds there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import adapters
from crosscheck.core.contract import Adapter, CallsAdapter
from crosscheck.core.model import Status, quantities_of
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SceneCase
from crosscheck.results.run import Run, read_run
from crosscheck.results.store import repro_name, repro_path
from crosscheck.run import envs, pinned
from crosscheck.studies.repro.calls import calls_code, has_call
from crosscheck.studies.repro.code import EngineCode, literal, vector
from crosscheck.studies.repro.verdicts import comment, conventions_line, truths, verdict_line
from crosscheck.truth.scene_measures import MEASURES, surrounded
from crosscheck.truth.scenes import QUANTITIES

__all__ = [
    "ReproError",
    "RunRows",
    "Script",
    "breaking_pairs",
    "build",
    "engine_part",
    "engines_for",
    "literal",
    "printed",
    "scripted",
    "scripts",
    "write_run_scripts",
]

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
    """No script for this case x engine (unknown, skipped, or an engine whose calls are not a
    module)."""


@dataclass(frozen=True)
class Script:
    """One repro script: its case, engine and source text, and the engine part it holds."""

    case_id: str
    engine: str
    text: str
    model: str = ""
    """The engine's own model text the script loads (MuJoCo's MJCF), '' if none."""

    @property
    def name(self) -> str:
        """Its file name without ``.py`` (:func:`crosscheck.results.store.repro_name`)."""
        return repro_name(self.case_id, self.engine)


Row = dict[str, Any]


class RunRows:
    """A stored run's rows grouped by (case id, engine), read once."""

    def __init__(self, stored: Run) -> None:
        self.stored = stored
        self.pairs: dict[tuple[str, str], list[Row]] = {}
        for record in stored.results.to_dict("records"):
            row = {str(k): v for k, v in record.items()}
            self.pairs.setdefault((str(row["case_id"]), str(row["engine"])), []).append(row)

    def rows(self, case_id: str, engine: str) -> list[Row]:
        return self.pairs.get((case_id, engine), [])

    def engine_info(self, engine: str) -> dict[str, Any]:
        return next((dict(e) for e in self.stored.info.engines if e.get("name") == engine), {})


Input = tuple[str, str, str, str]
"""(constant, source, label, the value as Python prints it) of one input of a script."""


def pair_inputs(case: AnyCase) -> tuple[Input, ...]:
    """The inputs of a two-body case: centres, sizes, and for a response masses, velocities
    and the restitution."""
    assert not isinstance(case, SceneCase), "a scene's inputs are its call's"
    out = []
    for which in ("a", "b"):
        body = getattr(case, which)
        size = ("half", vector(body.half), body.half) if isinstance(case, AabbCase) else (
            "radius", literal(body.radius), body.radius)
        out += [(f"{which.upper()}_CENTER", vector(body.center), f"{which}.center",
                 repr(body.center)),
                (f"{which.upper()}_{size[0].upper()}", size[1], f"{which}.{size[0]}",
                 repr(size[2]))]
        if isinstance(case, ResponseCase):
            out += [(f"{which.upper()}_MASS", literal(body.mass), f"{which}.mass",
                     repr(body.mass)),
                    (f"{which.upper()}_VELOCITY", vector(body.velocity), f"{which}.velocity",
                     repr(body.velocity))]
    if isinstance(case, ResponseCase):
        out.append(("RESTITUTION", literal(case.restitution), "restitution",
                    repr(case.restitution)))
    return tuple(out)


def _header(case: AnyCase, info: dict[str, Any], rows: list[Row], run_id: str,
            notes: Sequence[str]) -> list[str]:
    engine = f"{info.get('engine', '')} {info.get('version', '')}".strip()
    title = comment(f"Reproduce crosscheck case {case.id} on engine {info.get('name')} "
                    f"({engine}).").replace("\\", "/").replace('"', "'")
    lines = [f"# Case: {case.description}", f"# Kind {case.kind}, {case.dim}-D; file "
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
              "(`<quantity> = <JSON text>`), after what", "# the run recorded beside it: the "
              "exact answer (expected), each verdict against its float64", "# bound, the "
              "textbook formula in float64 (textbook) and the engine's declared conventions.",
              *(f"# {note}" for note in notes)]
    return [f'"""{title}"""', *(comment(line) for line in lines)]


def _imports(engine: EngineCode) -> list[str]:
    standard = sorted({"import math", "import sys", *(
        i for i in engine.imports if i in ("import math", "import collections"))})
    third = [i for i in engine.imports if i not in standard]
    return [*standard, "", *third]


def _recorded(case: AnyCase, rows: list[Row], textbook: list[Row],
              info: dict[str, Any]) -> list[str]:
    """What the run recorded beside the answer: printed before the engine is asked, so that a
    crash, an exception or a hang still leaves it on screen."""
    lines = [f"EXPECTED = {truths(rows)!r}  # the exact answer (the harness's oracle)",
             'for quantity, text in EXPECTED.items():\n'
             '    print(f"expected {quantity} = {text}")',
             *(f"print({verdict_line(row)!r})" for row in rows)]
    if textbook:
        values = {str(r["quantity"]): str(r["value"]) for r in textbook}
        lines += [f"TEXTBOOK = {values!r}  # the reference engine's value in the run",
                  'for quantity, text in TEXTBOOK.items():\n'
                  '    print(f"textbook {quantity} = {text}")']
    elif not isinstance(case, SceneCase):
        lines.append('print("# textbook float64 answer: not in this run")')
    return [*lines, f"print({conventions_line(info, case)!r})",
            "sys.stdout.flush()  # all of it on screen before the engine is asked"]


MEASURED = ("settle", "jitter", "energy_drift", "apex", "bounce_time")
"""The measures a scene's call computes from the engine's states (every one but
``divergence``); in open space only ``energy_drift`` has a value."""


def printed(case: AnyCase) -> tuple[str, ...]:
    """The quantities a script prints as ``<quantity> = <JSON text>``: every quantity of the
    case's kind, but of a scene only the final state and the measures its call computes
    (:data:`MEASURED`; open space: ``energy_drift`` only; the others are a comment)."""
    if isinstance(case, SceneCase):
        return (*QUANTITIES, *(MEASURED if surrounded(case) else ("energy_drift",)))
    return quantities_of(case.kind_enum)


def _scene_note(case: SceneCase, rows: list[Row]) -> str:
    """The comment on the measures a scene's script does not print."""
    if not surrounded(case):
        others = ", ".join(q for q in MEASURES if q != "energy_drift")
        return (f"# {others}: none in open space (no ground and no recorded trajectory); "
                "crosscheck records null")
    recorded = next((str(r["value"]) for r in rows if r["quantity"] == "divergence"),
                    "nothing (not in this run)")
    return ("# divergence: computed by crosscheck against the exact run's trajectory (the "
            f"first recorded time a centre is more than diverge_at = {case.diverge_at!r} mean "
            f"radii from the exact one), not by this script; the run recorded {recorded}")


def _answers(case: AnyCase, engine: EngineCode, rows: list[Row]) -> list[str]:
    """The engine's answer, one ``<quantity> = <JSON text>`` line per printed quantity (a
    scene's measures it does not print: a comment)."""
    lines = [f'print("{q} = " + encode({q}))' for q in printed(case)]
    if isinstance(case, SceneCase):
        return [*lines, f"print({_scene_note(case, rows)!r})"]
    if engine.resolved_at:
        lines.append('print("# resolved at (centres of A and B):", resolved_at)')
    return lines


def script_text(case: AnyCase, engine: EngineCode, info: dict[str, Any], rows: list[Row],
                textbook: list[Row], run_id: str) -> str:
    """The whole script of ``case`` with ``engine``'s statements (see the module docstring)."""
    inputs = engine.inputs or pair_inputs(case)
    parts = [
        "#!/usr/bin/env python3", *_header(case, info, rows, run_id, engine.notes), "",
        *_imports(engine), "", "# The case's inputs: exact binary64 values.",
        *(f"{name} = {source}  # {comment(plain)}" for name, source, _, plain in inputs), "",
        "", ENCODE, "",
        f"print({comment('# case ' + case.id + ' on ' + str(info.get('name')))!r})",
        *(f'print("# {label} =", {name})' for name, _, label, _ in inputs),
        "# What the run recorded: the exact answer, the verdicts, the declared conventions.",
        *_recorded(case, rows, textbook, info), "", "# The engine's calls.",
        engine.code, *_answers(case, engine, rows), *([engine.tail] if engine.tail else [])]
    return "\n".join(parts) + "\n"


def _case(stored: Run, case_id: str) -> AnyCase:
    case: AnyCase | None = stored.cases.get(case_id)
    if case is None:
        raise ReproError(f"no case {case_id!r} in {stored.directory}")
    return case


def _adapter(engine: str) -> Adapter | None:
    """The adapter of ``engine`` if it has scripts (a pinned ``NAME@VERSION``: its variant's,
    the script being the same code run by another interpreter)."""
    try:
        adapter = adapters.get(pinned.split(engine)[0])
    except adapters.UnknownEngine:
        return None
    return adapter if scripted(adapter) else None


def scripted(adapter: Adapter, case: AnyCase | None = None) -> bool:
    """Whether ``crosscheck repro`` writes scripts for ``adapter``: its engine calls are a
    module (a :class:`~crosscheck.core.contract.CallsAdapter`, a plug-in's too); given a
    ``case``, also that it runs the case (no skip) and makes it as calls
    (:func:`~.calls.has_call`)."""
    if case is not None:
        return adapter.unsupported(case) is None and has_call(adapter, case)
    return isinstance(adapter, CallsAdapter)


def engine_part(adapter: Adapter, case: AnyCase,
                hung: frozenset[str] = frozenset()) -> EngineCode:
    """The engine part of ``case``'s script on ``adapter``: its calls module's
    (:func:`~crosscheck.studies.repro.calls.calls_code`); :class:`ReproError` when it makes
    no call for the case's kind."""
    if not has_call(adapter, case):
        raise ReproError(f"{adapter.name} has no call for {case.kind}")
    return calls_code(adapter, case, hung)


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
    case = _case(runs.stored, case_id)
    rows = runs.rows(case_id, engine)
    if not rows:
        raise ReproError(f"engine {engine!r} has no rows for case {case_id!r} in this run")
    if not _ran(rows):
        raise ReproError(f"{engine} did not run {case_id}: {rows[0]['reason']}")
    adapter = _adapter(engine)
    if adapter is None:
        raise ReproError(f"engine {engine!r} makes no calls of a module (crosscheck repro "
                         "writes scripts for engines whose calls are a module: "
                         "adapters/<engine>/calls.py)")
    code = engine_part(adapter, case, hung(rows))
    textbook = runs.rows(case_id, "reference")
    text = script_text(case, code, runs.engine_info(engine), rows,
                       textbook if _ran(textbook) else [], runs.stored.info.run_id)
    return Script(case_id, engine, _with_interpreter(text, adapter, engine), code.model)


def _with_interpreter(text: str, adapter: Adapter, engine: str) -> str:
    """A pinned version's script says which interpreter has that version (its first line,
    the shebang, is the harness's python; the pinned one must be named to run it)."""
    version = pinned.split(engine)[1]
    if version is None:
        return text
    env = envs.find(adapter.package, version)
    first, _, rest = text.partition("\n")
    return (f"{first}\n# {engine}: run with {env.python} (the cached environment of "
            f"{adapter.package} {version}; `crosscheck run --engine {engine}` builds it)\n{rest}")


def disagrees(rows: list[Row]) -> bool:
    """Whether a pair has a row that is neither agree nor skip (disagree, undefined, failed)."""
    return any(Status(r["status"]) not in (Status.AGREE, Status.SKIP) for r in rows)


def engines_for(runs: RunRows, case_id: str) -> tuple[list[str], bool]:
    """Engines to script for a case, and whether they are the ones that disagree: those with a
    row that is neither agree nor skip, else (False) every engine that ran it.

    Only engines that ran the case and make it as calls of their module count.
    """
    ran = [e for e in runs.stored.info.engine_names
           if _ran(runs.rows(case_id, e)) and _adapter(e) is not None]
    bad = [e for e in ran if disagrees(runs.rows(case_id, e))]
    return (bad, True) if bad else (ran, False)


def scripts(stored: Run, case_id: str, engine: str | None = None) -> list[Script]:
    """The scripts of ``case_id``: for ``engine``, or for every engine :func:`engines_for`
    the case chooses."""
    runs = RunRows(stored)
    _case(stored, case_id)
    names = [engine] if engine else engines_for(runs, case_id)[0]
    if not names:
        raise ReproError(f"no engine of this run ran case {case_id!r} as calls of its module")
    return [build(runs, case_id, name) for name in names]


def breaking_pairs(runs: RunRows) -> list[tuple[str, str]]:
    """Every (case id, engine) with a disagree, error, crash or timeout row, in run order."""
    breaking = Status.members("breaking")
    return [pair for pair, rows in runs.pairs.items()
            if any(r["status"] in breaking for r in rows)]


def write_run_scripts(directory: Path, out: Path | None = None) -> list[Path]:
    """Write ``<repro_name>.py`` for every breaking case x engine of the run in
    ``directory`` into ``out`` (default: the run's ``repro/``, where the report links them);
    the paths.  A run writes none: ``crosscheck repro RUN_DIR --all`` calls this.

    Pairs without a script (an engine whose calls are not a module) are left out.
    """
    runs = RunRows(read_run(directory))
    written = []
    for case_id, engine in breaking_pairs(runs):
        try:
            made = build(runs, case_id, engine)
        except ReproError:
            continue
        path = (repro_path(directory, case_id, engine) if out is None
                else out / f"{made.name}.py")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(made.text, encoding="utf-8")
        written.append(path)
    return written
