"""The terminal face shared by every command: consoles, error lines, progress, the summary."""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
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

from crosscheck.core.model import Status

if TYPE_CHECKING:
    import pandas as pd

    from crosscheck.cases.load import LoadResult

out = Console(soft_wrap=True)
err = Console(stderr=True, soft_wrap=True)


def fail(message: str) -> None:
    """Print an error line; the message is shown literally (no rich markup)."""
    err.print(f"[red]error:[/red] {escape(message)}", highlight=False)


def say(message: str) -> None:
    """Print a line literally (no rich markup)."""
    out.print(escape(message), highlight=False)


def report_case_errors(loaded: LoadResult) -> None:
    """One line per rejected case block: file, case, field and reason."""
    for problem in loaded.errors:
        err.print(f"[red]invalid:[/red] {escape(problem.message)}", highlight=False)


@contextlib.contextmanager
def progress_bar(total: int, label: str = "case x engine") -> Iterator[Callable[[int], None]]:
    """A transient progress bar on stderr; yields the function that advances it by n."""
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=err, transient=True) as bar:
        task = bar.add_task(label, total=total)
        yield lambda n: bar.update(task, advance=n)


PHASES = {"verdicts": "case x engine", "timing": "timing (one at a time)"}


class PlainProgress:
    """Progress as plain lines, for a log or a pipe: one at the start, then every tenth."""

    def __init__(self, label: str, total: int, clock: Callable[[], float] = time.monotonic):
        self.label, self.total, self.done, self.clock = label, total, 0, clock
        self.started, self.next = clock(), 0.1
        say(f"{label}: {total} to go")

    def __call__(self, n: int) -> None:
        self.done += n
        if self.total and self.done / self.total >= self.next:
            self.next = math.floor(10 * self.done / self.total) / 10 + 0.1
            say(f"{self.label}: {self.done}/{self.total} "
                f"({100 * self.done / self.total:.0f}%, {self.clock() - self.started:.0f} s)")


@contextlib.contextmanager
def phase_bars() -> Iterator[Callable[[str, int], Callable[[int], None]]]:
    """Progress per phase of a run (verdicts, timing): transient bars on a terminal, plain
    lines every tenth of the way when stderr is a log or a pipe."""
    if not err.is_terminal:
        yield lambda name, total: PlainProgress(PHASES.get(name, name), total)
        return
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=err, transient=True) as bar:
        def start(name: str, total: int) -> Callable[[int], None]:
            task = bar.add_task(PHASES.get(name, name), total=total)
            return lambda n: bar.update(task, advance=n)
        yield start


def print_summary(directory: Path) -> None:
    """Print the engine x kind counts from the run's summary.csv (written by the report)."""
    import pandas as pd

    table = pd.read_csv(directory / "summary.csv", keep_default_na=False)
    out.print(summary_table(table, f"summary of {directory}"))


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
            rich_table.add_row(str(row.kind), *(str(getattr(row, s)) for s in statuses))
    return rich_table
