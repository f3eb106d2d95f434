"""The one advise table: its columns and each engine's cells, for every renderer.

``crosscheck advise`` prints it as aligned columns (a line per engine, its worst answer on
the line below), the docs' generated advice as Markdown, and the report's "Which engine for
my scene" section as HTML: all three read :func:`rows`, :func:`header` and :func:`cells`,
so an engine's tier, cases, share within and cost (median ± IQR,
:mod:`crosscheck.report.text`) read the same everywhere.  When an engine of the answer was
counted (``--timer instructions``) its instructions per query come first, the wall clock
beside them.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from crosscheck.report.advise.grade import EngineAdvice
from crosscheck.report.advise.recommend import Advice
from crosscheck.report.text import instructions_iqr, median_iqr, or_dash, percent, short

TIERS = {"passes": "pass", "partial": "part", "fails": "fail", "unsupported": "none"}
"""Each tier's word in the table."""
HEADER = ("#", "engine", "tier", "cases", "within", "median \u00b1 IQR")
"""The ranking's columns (``cases``: the cases of the envelope the engine answers, which its
grade rests on; ``within``: the share of those within the accuracy)."""
COUNTED_HEADER = (*HEADER[:5], "instr/query \u00b1 IQR", "wall \u00b1 IQR")
"""The ranking's columns when an engine was counted: its instructions per query first, the
wall-clock time beside them."""
BASELINE = "b"
"""The rank cell of a baseline (graded alike, never ranked)."""


def rows(advice: Advice) -> list[tuple[str, EngineAdvice]]:
    """The table's rows: the ranked engines numbered from 1, then the baselines."""
    return [*((str(rank), e) for rank, e in enumerate(advice.ranking, 1)),
            *((BASELINE, e) for e in advice.baselines)]


def is_counted(engines: Iterable[EngineAdvice]) -> bool:
    """Whether an engine of the table was counted (its cost then has two columns)."""
    return any(e.median_query_instructions is not None for e in engines)


def header(counted: bool) -> tuple[str, ...]:
    return COUNTED_HEADER if counted else HEADER


def cells(rank: str, engine: EngineAdvice, counted: bool) -> tuple[str, ...]:
    """An engine's cells under :func:`header` (its worst answer apart: :func:`worst_text`)."""
    time = or_dash(median_iqr, engine.median_query_s, engine.query_iqr_s)
    count = or_dash(instructions_iqr, engine.median_query_instructions,
                    engine.query_instructions_iqr)
    return (rank, engine.engine, TIERS[engine.tier], str(engine.answered),
            percent(engine.share_within), *((count, time) if counted else (time,)))


def worst_text(engine: EngineAdvice) -> str:
    """The worst answer in a few words: quantity, status, number against the need, case; with
    none, the part of the envelope it skips (kind, dimension, cases skipped of all), or else
    its most frequent declared convention (quantity, cases, largest number)."""
    worst = engine.worst
    skipped = [f"{p.kind} {p.dim}-D {p.cases - p.answered}/{p.cases}"
               for p in engine.parts if p.answered < p.cases]
    if worst is None and engine.answered and skipped:
        return "skips " + ", ".join(skipped)
    if worst is None and engine.conventions:
        mode = engine.conventions[0]
        number = "" if mode.largest is None else f" \u2264{short(mode.largest)}"
        return f"conv {mode.quantity} n={mode.cases}{number}"
    if worst is None:
        return "-" if engine.answered else "answers no case here"
    number = "" if worst.measure is None else f" {short(worst.measure)}>{short(worst.allowed)}"
    what = worst.status if worst.status != "disagree" else ""
    return f"{worst.quantity} {what}{number} {worst.case_id}".replace("  ", " ")


def table(advice: Advice) -> tuple[tuple[str, ...], list[tuple[tuple[str, ...], EngineAdvice]]]:
    """The header and, per row, its cells and engine (for a renderer's links and colours)."""
    shown = rows(advice)
    counted = is_counted(e for _, e in shown)
    return header(counted), [(cells(rank, e, counted), e) for rank, e in shown]


def engines_text(engines: Sequence[EngineAdvice]) -> str:
    return ", ".join(e.engine for e in engines)
