"""The terminal face shared by every command: consoles, error lines, progress, the summary.

What goes to stdout reads whole at the width (the terminal's, else ``COLUMNS``, else 80 in a
file or a pipe): :func:`say` wraps lines at spaces and never splits a word (a path stays
whole), and :func:`fit` makes a table wrap or fold its cells instead of cutting them with
an ellipsis.  Errors, notes and progress go to stderr as whole lines.
"""

from __future__ import annotations

import contextlib
import math
import textwrap
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING

from rich import box
from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table
from rich.text import Text

from crosscheck.core.model import Status

if TYPE_CHECKING:
    import pandas as pd

    from crosscheck.cases.load import LoadResult
    from crosscheck.results.run import Run

stdout = Console()
stderr = Console(stderr=True, soft_wrap=True)


def fail(message: str) -> None:
    """Print an error line; the message is shown literally (no rich markup)."""
    stderr.print(f"[red]error:[/red] {escape(message)}", highlight=False)


def wrapped(message: str, width: int) -> list[str]:
    """The lines of ``message`` wrapped at spaces to ``width``; a word wider than that (a
    long path) is never split but stands alone; a continuation keeps its line's indent.

    >>> wrapped("  one two three", 9)
    ['  one two', '  three']
    >>> wrapped("see /a/long/path now", 8)
    ['see', '/a/long/path', 'now']
    """
    lines: list[str] = []
    for line in message.splitlines() or [""]:
        indent = line[:len(line) - len(line.lstrip())]
        lines += textwrap.wrap(line, width, subsequent_indent=indent, break_long_words=False,
                               break_on_hyphens=False) or [""]
    return lines


def say(message: str, console: Console | None = None, style: str = "") -> None:
    """Print a message literally (no rich markup) on stdout (or ``console``), wrapped at
    spaces to the width; ``style`` colours the first word (a label such as ``ok:``)."""
    console = console or stdout
    for n, line in enumerate(wrapped(message, console.width)):
        text = Text(line)
        if style and n == 0:
            text.stylize(style, 0, len(line.split(" ", 1)[0]))
        console.print(text, soft_wrap=True)


def report_case_errors(loaded: LoadResult) -> None:
    """One line per rejected case block: file, case, field and reason."""
    for problem in loaded.errors:
        stderr.print(f"[red]invalid:[/red] {escape(problem.message)}", highlight=False)


def fit(table: Table) -> Table:
    """``table`` with every header and cell wrapped at spaces, and a word folded only when
    it is wider than its column: it reads whole at any width, never cut with an ellipsis."""
    for column in table.columns:
        column.overflow, column.no_wrap = "fold", False
    return table


@contextlib.contextmanager
def progress_bar(total: int, label: str = "case x engine") -> Iterator[Callable[[int], None]]:
    """Progress of one pass on stderr: a transient bar on a terminal, plain lines every
    tenth of the way in a log or a pipe; yields the function that advances it by n."""
    with phase_bars() as start:
        yield start(label, total)


PHASES = {"verdicts": "case x engine", "timing": "timing (rounds, steps)",
          "counting": "counting instructions (cases)", "report": "report (files, sections)"}


class PlainProgress:
    """Progress as plain lines on stderr, for a log or a pipe: one at the start, then one each
    tenth of the way and at least every :data:`QUIET_S` seconds, each with the time taken and
    an estimate of the time left (at the rate so far)."""

    def __init__(self, label: str, total: int, clock: Callable[[], float] = time.monotonic):
        self.label, self.total, self.done, self.clock = label, total, 0, clock
        self.started, self.next = clock(), 0.1
        self.said = self.started
        self.lock = threading.Lock()
        say(f"{label}: {total} to go", stderr)

    def __call__(self, n: int) -> None:
        with self.lock:
            self.done += n
            if self.total and self.done / self.total >= self.next:
                self.next = math.floor(10 * self.done / self.total) / 10 + 0.1
                self._say(self.clock())
        self.beat()

    def beat(self) -> None:
        """Say where the phase is when nothing was said for :data:`QUIET_S` seconds (a long
        case in flight advances nothing; :func:`phase_bars` calls this every second)."""
        with self.lock:
            now = self.clock()
            if self.done < self.total and now - self.said >= QUIET_S:
                self._say(now)

    def _say(self, now: float) -> None:
        self.said = now
        say(f"{self.label}: {self.done}/{self.total} "
            f"({100 * self.done / max(self.total, 1):.0f}%, {now - self.started:.0f} s"
            f"{self.left(now)})", stderr)

    def left(self, now: float) -> str:
        """``, about N s left`` at the rate so far (nothing once done or before any)."""
        if not 0 < self.done < self.total:
            return ""
        return f", about {(now - self.started) * (self.total - self.done) / self.done:.0f} s left"


QUIET_S = 10.0
"""The longest a plain progress log stays silent while a phase advances."""


@contextlib.contextmanager
def phase_bars() -> Iterator[Callable[[str, int], Callable[[int], None]]]:
    """Progress per phase of a run (verdicts, timing) on stderr: transient bars on a
    terminal, plain lines every tenth of the way when stderr is a log or a pipe."""
    if not stderr.is_terminal:
        made: list[PlainProgress] = []
        stop = threading.Event()

        def beats() -> None:
            while not stop.wait(1.0):
                for progress in list(made):
                    progress.beat()

        def start_plain(name: str, total: int) -> Callable[[int], None]:
            for earlier in made:  # a new phase: the earlier ones are over
                earlier.done = earlier.total
            made.append(PlainProgress(PHASES.get(name, name), total))
            return made[-1]

        beating = threading.Thread(target=beats, name="progress", daemon=True)
        beating.start()
        try:
            yield start_plain
        finally:
            stop.set()
            beating.join()
        return
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=stderr, transient=True) as bar:
        def start(name: str, total: int) -> Callable[[int], None]:
            task = bar.add_task(PHASES.get(name, name), total=total)
            return lambda n: bar.update(task, advance=n)
        yield start


def print_summary(run: Run) -> None:
    """Print the engine x kind counts of the run (the report's summary table, from the run's
    rows: no file is read), then the instructions per query when the run counted any case
    (``--timer instructions``), then the query times when it timed any."""
    from crosscheck.report.summary_tables import summary

    table = summary(run.results)
    stdout.print(summary_table(table, f"summary of {run.directory}"))
    if "median_query_instructions" in table and table["median_query_instructions"].notna().any():
        say(COUNTS_TITLE)
        stdout.print(counts_table(table))
    if table["median_query_s"].notna().any():
        say(TIMES_TITLE)
        stdout.print(times_table(table))


TIMES_TITLE = "query time: median ± IQR over the timed cases (scenes: per run)"
COUNTS_TITLE = "instructions per query (callgrind): median ± IQR over the counted cases"


def times_table(table: pd.DataFrame) -> Table:
    """Per engine x kind, the median query time ± its IQR over the timed cases: the figure and
    the format of the report page's engine x kind table (``-``: not timed)."""
    from crosscheck.report.text import median_iqr

    return _engine_kind_table(table, "median_query_s", "iqr_query_s", median_iqr)


def counts_table(table: pd.DataFrame) -> Table:
    """Per engine x kind, the median instructions per query ± their IQR over the counted cases:
    the figure and the format of the report page's engine x kind table (``-``: not
    counted)."""
    from crosscheck.report.text import instructions_iqr

    return _engine_kind_table(table, "median_query_instructions", "iqr_query_instructions",
                              instructions_iqr)


def _engine_kind_table(table: pd.DataFrame, median_column: str, iqr_column: str,
                       written: Callable[[float, float], str]) -> Table:
    """One row per engine, one column per kind: each median ± IQR as ``written`` writes it."""
    kinds = [str(k) for k in dict.fromkeys(table["kind"])]
    cells = {(str(engine), str(kind)): written(float(median), float(iqr))
             for engine, kind, median, iqr in zip(table["engine"], table["kind"],
                                                 table[median_column], table[iqr_column],
                                                 strict=True) if not math.isnan(float(median))}
    rich_table = Table(box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False,
                       collapse_padding=True)
    rich_table.add_column("engine", no_wrap=True)
    for kind in kinds:
        rich_table.add_column(kind, justify="right")
    for engine in dict.fromkeys(table["engine"]):
        rich_table.add_row(str(engine), *(cells.get((str(engine), k), "-") for k in kinds))
    return fit(rich_table)


def summary_table(table: pd.DataFrame, title: str) -> Table:
    """Status counts per engine x kind, about 72 columns wide: an engine's name heads its
    rows (never truncated), so the table reads whole in an 80-column terminal."""
    statuses: Sequence[str] = tuple(str(s) for s in Status)
    rich_table = Table(title=title, box=box.SIMPLE_HEAD, title_justify="left", show_edge=False,
                       pad_edge=False, collapse_padding=True)
    rich_table.add_column("engine / kind", no_wrap=True)
    for status in statuses:
        rich_table.add_column(status, justify="right", no_wrap=True)
    for n, (engine, rows) in enumerate(table.groupby("engine", sort=False)):
        if n:
            rich_table.add_section()
        rich_table.add_row(f"[bold]{escape(str(engine))}[/]", *([""] * len(statuses)))
        for row in rows.itertuples(index=False):
            rich_table.add_row(str(row.kind), *(str(int(getattr(row, s))) for s in statuses))
    return rich_table
