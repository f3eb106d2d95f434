"""What changed from one engine version to another (crosscheck.results.changes, and
``crosscheck compare`` with one run and --from/--to, or two runs).

Runs are written by hand: one engine at two versions, ``e@1.0`` and ``e``, with rows chosen
so that each failure mode has a known number of rows.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.cli import main
from crosscheck.core.model import Record, Status
from crosscheck.core.options import RunOptions
from crosscheck.results.changes import side, what_changed
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.store import ResultsStore

Row = tuple[str, str, str, str, float]
"""(case, quantity, status, category, error)"""


def record(engine: str, row: Row) -> Record:
    case, quantity, status, category, error = row
    return Record(case_id=case, source="cases/t.toml", kind="sphere", dim=3, tags="",
                  engine=engine, quantity=quantity, value=repr(error), truth="0", error=error,
                  tolerance=1e-15, status=Status(status), category=category, reason="",
                  setup_s=math.nan, query_s=math.nan, query_iqr_s=math.nan, loops=0,
                  unstable=False)


def make_run(directory: Path, rows: dict[str, list[Row]]) -> Path:
    store = ResultsStore(directory)
    store.append(record(engine, row) for engine, engine_rows in rows.items()
                 for row in engine_rows)
    store.write_run_info(RunInfo(
        run_id=directory.name, command="test", options=RunOptions(), machine={"cpu": "t"},
        started="", finished="", cases_run=1,
        engines=tuple({"name": e, "engine": "fake", "version": e.partition("@")[2] or "2.0"}
                      for e in rows)))
    store.close()
    return directory


BEFORE: list[Row] = [
    ("a", "hit", "agree", "", 0.0),
    ("b", "hit", "agree", "", 0.0),
    ("c", "distance", "disagree", "convention", 1e-3),
    ("d", "distance", "disagree", "convention", 1e-3),
    ("e", "distance", "crash", "", math.nan),
    ("f", "hit", "agree", "", 0.0),
]
AFTER: list[Row] = [
    ("a", "hit", "disagree", "tolerance", 1.0),   # agree -> disagree (tolerance)
    ("b", "hit", "disagree", "tolerance", 1.0),   # the same mode
    ("c", "distance", "disagree", "convention", 1e-2),  # error grew beyond the margin
    ("d", "distance", "disagree", "convention", 1e-5),  # error shrank beyond the factor
    ("e", "distance", "agree", "", 0.0),          # crash -> agree: stale
    ("f", "hit", "agree", "", 0.0),               # unchanged
    ("g", "hit", "agree", "", 0.0),               # new
]


@pytest.fixture
def run(tmp_path: Path) -> Path:
    return make_run(tmp_path / "run", {"e@1.0": BEFORE, "e": AFTER})


def test_changed_rows_fall_in_failure_modes_largest_first(run: Path) -> None:
    changes = what_changed(side(run, "e@1.0"), side(run, "e"))
    assert changes.compared == 7 and changes.changed == 6
    assert changes.answered_differently == 5  # a value per error: a to e moved, f did not
    assert {mode: len(rows) for mode, rows in changes.modes.items()} == {
        "hit: agree -> disagree (tolerance)": 2,
        "distance: crash -> agree": 1,
        "distance: disagree (convention), error grew": 1,
        "distance: disagree (convention), error shrank": 1,
        "hit: absent -> agree": 1,
    }
    assert next(iter(changes.modes)) == "hit: agree -> disagree (tolerance)"
    assert changes.counts() == {"regression": 3, "stale": 2, "new": 1}
    assert (changes.before.label, changes.after.label) == ("e@1.0 (1.0)", "e (2.0)")


def test_compare_of_one_run_writes_every_changed_row_with_both_repro_commands(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["compare", str(run), "--from", "e@1.0", "--to", "e", "--out", str(out)]) == 0
    said = capsys.readouterr().out.replace("\n", " ")
    assert "6 of 7 rows" in said and "hit: agree -> disagree (tolerance)" in said
    table = pd.read_csv(out / "changes.csv")
    assert len(table) == 6 and set(table["case_id"]) == {"a", "b", "c", "d", "e", "g"}
    grew = table.set_index("case_id").loc["c"]
    assert (grew["error_before"], grew["error_after"]) == (1e-3, 1e-2)
    assert grew["repro_before"] == f"crosscheck repro {run} c --engine e@1.0"
    assert grew["repro_after"] == f"crosscheck repro {run} c --engine e"
    markdown = (out / "changes.md").read_text()
    assert "## e@1.0 (1.0) -> e (2.0)" in markdown
    assert "### hit: agree -> disagree (tolerance): 2 rows" in markdown


def test_compare_of_two_runs_judges_each_shared_engine(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    a = make_run(tmp_path / "a", {"e": BEFORE, "same": BEFORE})
    b = make_run(tmp_path / "b", {"e": AFTER, "same": BEFORE})
    out = tmp_path / "out"
    assert main(["compare", str(a), str(b), "--out", str(out)]) == 0
    said = capsys.readouterr().out.replace("\n", " ")
    assert "no row changed from same (2.0) to same (2.0) (6 rows; 0 answer differently" in said
    table = pd.read_csv(out / "changes.csv")
    assert set(table["after_engine"]) == {"e (2.0)"} and len(table) == 6
    assert (out / "compare.html").exists()


@pytest.mark.parametrize(("args", "message"), [
    ([], "compare of one run needs --from ENGINE --to ENGINE"),
    (["--from", "e@1.0"], "--from and --to go together"),
    (["--from", "e@1.0", "--to", "nosuch"], "has no engine 'nosuch'"),
])
def test_compare_refuses_what_it_cannot_compare(
        run: Path, tmp_path: Path, args: list[str], message: str,
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["compare", str(run), *args, "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err.replace("\n", " ")
