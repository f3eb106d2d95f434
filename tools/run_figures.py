"""The figures of ``docs/generated/`` that come from one stored run, as Markdown bodies.

Each function takes the run (:class:`crosscheck.results.run.Run`) and returns the
body of one generated file; :mod:`tools.docs_figures` adds the provenance header and writes
it.  The numbers are the report's own: status counts from
:func:`crosscheck.report.summary_tables.summary`, the case-group matrix from
:func:`crosscheck.report.summary_tables.group_matrix`, agreeing shares from
:mod:`crosscheck.report.verdict`, times and their spreads from :mod:`crosscheck.report.speed`.

A run made with ``crosscheck run --timer instructions`` also has counted instructions per
query (``counts.jsonl``).  Where it does, the figures show them as the report does
(:mod:`crosscheck.report.cost`): the headline gives a profile's counted cost where every
ranked engine of it was counted (:attr:`~crosscheck.report.profiles.ProfileVerdict.by_counts`),
the advice tables each engine's median instructions per query before its wall-clock time,
and the query times a table of instructions per query beside the wall times.  A run without
counts gives exactly the figures it gave before counts existed.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from collections.abc import Iterable, Sequence
from datetime import datetime
from typing import Any

import pandas as pd

from crosscheck.core.model import Category, Status
from crosscheck.report import profiles, speed, summary_tables, verdict
from crosscheck.report.cost import column, cost_of
from crosscheck.report.text import instructions_iqr, with_iqr
from crosscheck.results.run import Run

DASH = "\u2013"
"""The kinds whose query is one detection call: the headline's time is theirs."""


def cell(value: object) -> str:
    """Text for a Markdown table cell: no pipes, no HTML, one line."""
    text = " ".join(str(value).split())
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace("|", "\\|")


def table(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A Markdown table (numbers right-aligned where a whole column is numeric)."""
    cells = [[cell(v) for v in row] for row in rows]

    def numeric(i: int) -> bool:
        return bool(cells) and all(r[i].replace(",", "").replace(".", "").isdigit()
                                   for r in cells)

    rule = ["---:" if numeric(i) else "---" for i in range(len(header))]
    lines = [list(header), rule, *cells]
    return "\n".join("| " + " | ".join(line) + " |" for line in lines) + "\n"


def count(n: int) -> str:
    """A count with thousands separators: 1654 -> '1,654'."""
    return f"{n:,}"


# --- the case suite -------------------------------------------------------------------------

def _block(case: Any) -> str | None:
    """The curated block a case was written as (its id, or its sweep's or scene's), None for
    a twin (A/B swap or 2-D twin), which comes from another case's block."""
    if case.twin_of or case.from_3d:
        return None
    return str(case.origin or case.id)


def _expansion(case: Any) -> str:
    if case.twin_of:
        return "A/B swaps"
    if case.from_3d:
        return "2-D twins"
    return "sweep or scene points" if case.origin else "as written"


EXPANSIONS = ("as written", "sweep or scene points", "2-D twins", "A/B swaps")


def _suite_rows(run: Run, key: str) -> list[list[object]]:
    blocks: dict[str, set[str]] = {}
    cases: dict[str, Counter[str]] = {}
    for case in run.cases.values():
        name = case.kind if key == "kind" else summary_tables.case_group(case.source)
        blocks.setdefault(name, set())
        block = _block(case)
        if block is not None:
            blocks[name].add(block)
        cases.setdefault(name, Counter())[_expansion(case)] += 1
    names = verdict.kinds_of(pd.DataFrame({"kind": list(blocks)})) if key == "kind" else list(
        blocks)
    rows: list[list[object]] = [
        [name, count(len(blocks[name])), count(sum(cases[name].values())),
         *(count(cases[name][e]) for e in EXPANSIONS)] for name in names]
    total = Counter[str]()
    for each in cases.values():
        total.update(each)
    rows.append(["all", count(sum(len(b) for b in blocks.values())),
                 count(sum(total.values())), *(count(total[e]) for e in EXPANSIONS)])
    return rows


def suite(run: Run) -> str:
    """The case suite of the run: curated blocks, cases in all, per kind and per case group,
    and the engine variants it ran."""
    blocks = {b for b in (_block(c) for c in run.cases.values()) if b is not None}
    files = len(run.info.case_files) or len({c.source for c in run.cases.values()})
    header = ["", "curated blocks", "cases in all", *EXPANSIONS]
    engines = [[e.get("name", ""), e.get("engine", ""), e.get("version", ""),
                e.get("settings", ""), e.get("available", "")] for e in run.info.engines]
    return "\n".join([
        f"The run's suite: **{count(len(blocks))} curated cases** (the `[[case]]` blocks of "
        f"{count(files)} case files) became **{count(len(run.cases))} cases in all** once sweeps "
        "and scenes were expanded into their points, 3-D cases given their 2-D twins and A/B "
        "swaps added.", "",
        "Per kind:", "", table(["kind", *header[1:]], _suite_rows(run, "kind")),
        "Per case group (case file):", "", table(["group", *header[1:]], _suite_rows(run, "group")),
        f"The run's **{count(len(engines))} engine variants**:", "",
        table(["variant", "engine", "version", "settings", "available"], engines)])


# --- how long it took ----------------------------------------------------------------------

def _instant(text: str | None) -> datetime | None:
    try:
        return datetime.fromisoformat(text) if text else None
    except ValueError:
        return None


def duration(seconds: float) -> str:
    """A wall-clock span: '139 s (2 min 19 s)'."""
    whole = round(seconds)
    if whole < 60:
        return f"{whole} s"
    minutes, rest = divmod(whole, 60)
    hours, minutes = divmod(minutes, 60)
    longer = f"{hours} h {minutes} min" if hours else f"{minutes} min {rest} s"
    return f"{whole:,} s ({longer})"


def machine_line(machine: dict[str, Any]) -> str:
    """The machine in one line: CPU, cores, Python, platform."""
    return (f"{machine.get('cpu', '?')}, {machine.get('cores', '?')} cores, "
            f"{machine.get('implementation', 'Python')} {machine.get('python', '?')}, "
            f"{machine.get('platform', '?')}")


def run_time(run: Run) -> str:
    """How long the run took, start to end, with its lanes, its timing phase and machine."""
    info, options = run.info, run.info.options
    start, end = _instant(info.started), _instant(info.finished)
    if start and end:
        span = duration((end - start).total_seconds())
        took = f"**{span}** from start to end ({info.started} to {info.finished})"
    else:
        took = f"not finished (started {info.started}): no end time in run.json"
    cores = info.machine.get("cores")
    lanes = options.jobs or cores or "?"
    lines = [f"The run `{info.run_id}` took {took}.", "",
             table(["", ""], [
                 ["command", f"{info.command}"],
                 ["cases x engines", f"{count(len(run.cases))} x {len(info.engines)}"],
                 ["lanes", f"{lanes}" + (" (one per core)" if not options.jobs else "")
                  + ("" if options.isolate else ", engines in-process")],
                 ["Dask scheduler", options.scheduler or "none (local run)"],
                 ["timing phase", _timing_line(run)],
                 ["machine", machine_line(info.machine)]])]
    if info.resumed:
        lines += [f"It was resumed at {', '.join(info.resumed)}: the span includes the pause.", ""]
    return "\n".join(lines)


def _timing_line(run: Run) -> str:
    timing, options = run.info.timing, run.info.options
    if timing is None:
        return "none (--quick)" if options.quick else "none recorded"
    return (f"{count(int(timing.get('sampled') or 0))} case x engine pairs timed "
            f"(up to {options.timing_cases} cases per engine x kind, {options.samples} samples "
            f"each); {timing.get('pinned', '')}" + _counting_text(timing))


def _counting_text(timing: dict[str, Any]) -> str:
    """The instruction timer's part of the timing line ('': the run did not count)."""
    cost = speed.cost_record(timing)
    if cost is None:
        return ""
    if cost.get("none"):
        return f"; instructions not counted: {cost['none']}"
    failed = int(cost.get("failed") or 0)
    return (f"; instructions counted under callgrind (--timer instructions) on "
            f"{count(int(cost.get('counted') or 0))} of {count(int(cost.get('sampled') or 0))}"
            f" pairs" + (f", {count(failed)} failed" if failed else ""))


# --- verdicts --------------------------------------------------------------------------------

STATUSES = [str(s) for s in Status]


def status_counts(run: Run) -> str:
    """Status counts (case x quantity rows) per engine x kind: the report's summary table."""
    frame = run.results
    if frame.empty:
        return "The run has no results rows.\n"
    summary = summary_tables.summary(frame)
    rows = [[r["engine"], r["kind"], *(count(int(r[s])) for s in STATUSES)]
            for r in summary.to_dict("records")]
    totals = [count(int(summary[s].sum())) for s in STATUSES]
    return "\n".join([
        f"Rows are case x quantity, **{count(len(frame))} in all**; per engine x kind:", "",
        table(["engine", "kind", *STATUSES], [*rows, ["all", "", *totals]])])


def categories(run: Run) -> str:
    """Disagreement categories per engine (rows with status disagree)."""
    frame = run.results
    names = [str(c) for c in Category]
    bad = frame[frame["status"] == str(Status.DISAGREE)]
    found = bad.groupby(["engine", "category"]).size()
    got = {(str(e), str(c)): int(n) for e, c, n in zip(
        found.index.get_level_values(0), found.index.get_level_values(1), found, strict=True)}
    rows = []
    for engine in dict.fromkeys(frame["engine"].astype(str)):
        numbers = [got.get((engine, c), 0) for c in names]
        rows.append([engine, *(count(n) for n in numbers), count(sum(numbers))])
    totals = [count(int((bad["category"] == c).sum())) for c in names]
    return "\n".join([
        f"Every `disagree` row has a category: **{count(len(bad))} disagree rows** in all.", "",
        table(["engine", *names, "disagree"], [*rows, ["all", *totals, count(len(bad))]])])


def _matrix_cell(c: dict[str, Any]) -> str:
    if c["skipped"]:
        return "skip"
    judged = c["scored"] + sum(c["failed"].values())
    return f"{count(c['agree'])} / {count(judged)}" if judged else DASH


def group_matrix(run: Run) -> str:
    """The engines x case groups matrix of the report: agree / judged rows per cell."""
    if run.results.empty:
        return "The run has no results rows.\n"
    matrix = summary_tables.group_matrix(run.results)
    header = ["engine", *(f"{g['name']} ({count(g['cases'])} cases)" for g in matrix["groups"])]
    rows = [[row["engine"], *(_matrix_cell(c) for c in row["cells"])] for row in matrix["rows"]]
    return "\n".join([
        "Each cell: agreeing rows / judged rows (agree, disagree, error, crash, timeout; skip "
        f"and undefined rows count neither way); `skip`: the engine cannot do any; {DASH}: "
        "nothing judged.", "", table(header, rows)])


def _spread(rows: pd.DataFrame) -> tuple[str, int]:
    spread = cost_of(rows).wall
    return (DASH if spread.n == 0 else with_iqr(spread)), spread.n


def _instructions(rows: pd.DataFrame) -> tuple[str, int]:
    """The median instructions per query over the counted cases of ``rows``, with their IQR,
    and how many cases were counted."""
    counted = cost_of(rows).counted
    text = DASH if counted.n == 0 else instructions_iqr(counted.median, counted.iqr)
    return text, counted.n


def _is_counted(frame: pd.DataFrame) -> bool:
    """Whether the run counted instructions of any pair (``--timer instructions``)."""
    return bool(column(frame, "query_instructions").notna().any())


def query_times(run: Run) -> str:
    """Median query time per engine x kind with its IQR over the timed cases; where the run
    counted instructions, the median instructions per query with their IQR over the counted
    cases beside them."""
    frame = run.results
    if frame.empty or frame["query_s"].isna().all():
        return "The run has no timing phase: no query was timed.\n"
    kinds = verdict.kinds_of(frame)
    rows, timed, counts, counted = [], [], [], []
    for engine, rows_of in frame.groupby("engine", sort=False):
        made = [_spread(rows_of[rows_of["kind"] == kind]) for kind in kinds]
        rows.append([engine, *(text for text, _n in made)])
        timed.append([engine, *(count(n) for _text, n in made)])
        tallied = [_instructions(rows_of[rows_of["kind"] == kind]) for kind in kinds]
        counts.append([engine, *(text for text, _n in tallied)])
        counted.append([engine, *(count(n) for _text, n in tallied)])
    parts = [
        "The median of the per-case median query times of the timed cases, with the "
        "interquartile range over those cases (a scene's time is one run of its stepping "
        "loop):", "", table(["engine", *kinds], rows)]
    counted_run = _is_counted(frame)
    if counted_run:
        parts += [
            "Beside them, the instructions per query counted under callgrind "
            "(`--timer instructions`): the median over the counted cases, with the "
            f"interquartile range over those cases ({DASH}: not counted; a scene's count is "
            "one run of its stepping loop):", "", table(["engine", *kinds], counts)]
    parts += ["Timed cases per engine x kind:", "", table(["engine", *kinds], timed)]
    if counted_run:
        parts += ["Counted cases per engine x kind:", "", table(["engine", *kinds], counted)]
    return "\n".join(parts)


HEADLINE_TOP = 3
"""Ranked engines shown per profile in the headline (the report shows them all)."""


def headline(run: Run) -> str:
    """The report's verdict on common ground, short: per standard profile, its top ranked
    engines and the float64 textbook baseline, with score, coverage and median query time;
    where a profile's ranked engines were all counted (``ProfileVerdict.by_counts``), their
    median instructions per query before it (``EngineScore.counted_text``)."""
    frame = run.results
    if frame.empty:
        return "The run has no results rows.\n"
    answers = profiles.profiles(frame, run.repros)
    counted = any(answer.by_counts for answer in answers)
    rows = []
    for answer in answers:
        ground = (f"{answer.profile.name} ({count(answer.common)} of {count(answer.total)} "
                  "rows)")
        shown = [(str(k + 1), s) for k, s in enumerate(answer.ranked[:HEADLINE_TOP])]
        shown += [("baseline", s) for s in answer.baselines[:1]]
        for k, (rank, s) in enumerate(shown):
            cost = ([s.counted_text if answer.by_counts else DASH] if counted else [])
            rows.append([ground if k == 0 else "", rank, s.engine,
                         f"{s.score.text} ({count(s.score.agree)} / {count(s.score.judged)})",
                         s.coverage_text, *cost, s.cost_text])
    if not counted:
        return "\n".join([
            "The verdict on common ground, per standard profile: each engine is scored over the "
            "rows every ranked engine answers (bad input left out), with its coverage of the "
            "profile beside the score and its median query time with the IQR over its timed "
            f"cases; the top {HEADLINE_TOP} ranked engines and the float64 textbook baseline:",
            "", table(["profile (common ground)", "rank", "engine", "score", "coverage",
                       "median query ± IQR"], rows)])
    return "\n".join([
        "The verdict on common ground, per standard profile: each engine is scored over the "
        "rows every ranked engine answers (bad input left out), with its coverage of the "
        "profile beside the score, then its cost: its median instructions per query with the "
        "IQR over its counted cases (counted under callgrind, `--timer instructions`) where "
        "every ranked engine of the profile was counted, the count then breaking ties after "
        f"score and coverage ({DASH}: a profile ranked by the wall clock, not every ranked "
        "engine counted), and its median query time with the IQR over its timed cases; the "
        f"top {HEADLINE_TOP} ranked engines and the float64 textbook baseline:", "",
        table(["profile (common ground)", "rank", "engine", "score", "coverage",
               "instructions per query ± IQR", "median query ± IQR"], rows)])


# --- conventions and the report --------------------------------------------------------------

def _value(value: object) -> str:
    if value in ("", None, {}, []):
        return DASH
    if isinstance(value, dict | list):
        return json.dumps(value, sort_keys=True)
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return str(value)


def _source(text: str) -> str:
    return f"<{text}>" if text.startswith(("http://", "https://")) else f"`{text}`"


def conventions(run: Run) -> str:
    """Each engine variant's declared conventions, with their sources, from run.json."""
    parts = ["The conventions each adapter declares (they decide the category of every "
             "disagreement), as the run recorded them.", ""]
    for engine in run.info.engines:
        declared = dict(engine.get("conventions") or {})
        sources = declared.pop("sources", []) or []
        rows = [[key, _value(value)] for key, value in declared.items()]
        if engine.get("touching_rule"):
            rows.append(["touching rule", engine["touching_rule"]])
        parts += [f"### {engine.get('name', '?')}", "",
                  f"{engine.get('engine', '')} {engine.get('version', '')}: "
                  f"{engine.get('settings', '')}", "",
                  table(["convention", "declared"], rows) if rows else "No conventions declared.\n"]
        parts += (["Sources: " + ", ".join(_source(str(s)) for s in sources) + ".", ""]
                  if sources else [])
    return "\n".join(parts).rstrip() + "\n"


ADVICE_PROFILES = (
    "--dim 3 --kind sphere --scale 0.01:10 --offset 10 --tolerance 1e-9 --angle-tolerance 1e-9",
    "--dim 3 --kind aabb --scale 0.1:10 --offset 1e4 --tolerance 1e-4 --angle-tolerance 1e-4",
    "--dim 2 --kind sphere --scale 0.1:10 --offset 1e3 --tolerance 1e-6 --angle-tolerance 1e-6",
    "--kind sphere_response --mass-ratio 1e3 --speed 10 --offset 1e3 --velocity-tolerance 1e-9",
    "--kind sphere_response --mass-ratio 1e3 --speed 10 --offset 1e3 --velocity-tolerance 1e-9 "
    "--scale 0:10",
)
"""The four scene profiles of docs/comparing-and-advice.md, as ``advise`` options, and the
fourth again with ``--scale 0:10``, which admits zero-size bodies (without ``--scale`` every
body has a positive size)."""


def advice(run: Run) -> str:
    """``crosscheck advise`` on each of :data:`ADVICE_PROFILES`: the command and its answer."""
    from crosscheck.cli import build_parser
    from crosscheck.cli.advise import envelope_of
    from crosscheck.report.advise import table as advise_table
    from crosscheck.report.advise.recommend import EnvelopeError, advise

    parts = []
    for options in ADVICE_PROFILES:
        args = build_parser().parse_args(["advise", str(run.directory), *options.split()])
        parts += ["```sh", f"crosscheck advise {run.directory} {options}", "```", ""]
        try:
            answer = advise(run, envelope_of(args))
        except EnvelopeError as exc:
            parts += [f"No answer from this run: {exc}.", ""]
            continue
        if not answer.cases:
            parts += ["No case of this run lies inside this envelope.", ""]
            continue
        head, shown = advise_table.table(answer)
        rows = [[*cells, advise_table.worst_text(e)] for cells, e in shown]
        parts += [f"{answer.cases:,} cases inside the envelope "
                  f"({', '.join(answer.kinds)}; {', '.join(f'{d}-D' for d in answer.dims)}).",
                  "", table([*head, "worst answer"], rows)]
        if answer.unsupported:
            parts += [f"Answer no case (not ranked): "
                      f"{', '.join(e.engine for e in answer.unsupported)}.", ""]
        parts += [f"Passing ({answer.passing_order}): "
                  f"{', '.join(e.engine for e in answer.passing)}."
                  if answer.passing else
                  f"Nothing passes the whole envelope; closest: {answer.closest}, decided by "
                  f"{', '.join(answer.deciding)}" + _mode_text(answer), ""]
    return "\n".join(parts).rstrip() + "\n"


def _mode_text(answer: Any) -> str:
    """The closest engine's failure modes, with their numbers and an example's reason."""
    closest = next((e for e in answer.ranking if e.engine == answer.closest), None)
    if closest is None or not closest.failure_modes:
        return "."
    modes = [f"{m.quantity} {m.status} on {m.cases} cases"
             + ("" if m.largest is None else f" (up to {m.largest:.3g}, needed {m.allowed:g})")
             + (f": {m.reason}" if m.reason else "") for m in closest.failure_modes[:2]]
    return ". Its failure modes: " + "; ".join(modes) + "."
