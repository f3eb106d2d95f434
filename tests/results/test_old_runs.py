"""``crosscheck report`` and ``compare`` read a run of the previous format version, and refuse
a run of a later one with its version and how to upgrade.

``tests/data/format3-run`` was written by the harness of the commit before format 4
(``fc67e21^``, whose ``FORMAT_VERSION`` is 3), unchanged but for the files a report writes:

    git archive fc67e21^ | tar -x -C /tmp/fmt3 && cd /tmp/fmt3
    PYTHONPATH=. python -m crosscheck.cli run cases/bad_input.toml --engine reference \\
        --engine pymunk --quick --out out/format3-run
    cp out/format3-run/{run.json,cases.jsonl,results.jsonl} tests/data/format3-run/

Its ``value`` and ``truth`` columns hold every token of formats 1 to 3 that strict JSON
rejects or reads differently: ``""``, ``undefined``, and bare ``NaN`` and ``Infinity``.

``tests/data/format4-run`` was written by the harness of the commit before format 5 (the
repeat check; ``git archive`` of that commit, whose ``FORMAT_VERSION`` is 4), with
disagreeing rows, which a format-5 run with ``--repeat-check`` would have asked again:

    PYTHONPATH=. python -m crosscheck.cli run cases/sphere.toml --engine reference \
        --engine reference-f32 --quick --out out/format4-run
    cp out/format4-run/{run.json,cases.jsonl,results.jsonl} tests/data/format4-run/
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Any

import pytest

from crosscheck.cli import main
from crosscheck.core.values import decode
from crosscheck.results.store import read_results, read_run_info
from tests.conftest import ROOT

FORMAT3 = Path(__file__).resolve().parent.parent / "data" / "format3-run"
FORMAT4 = Path(__file__).resolve().parent.parent / "data" / "format4-run"


def copy_of(source: Path, target: Path) -> Path:
    """A copy of a stored run (a report writes into its run folder)."""
    shutil.copytree(source, target)
    return target


def strict(text: str) -> Any:
    """The JSON value of ``text``, refusing the bare tokens strict JSON has not."""
    def refuse(token: str) -> None:
        raise ValueError(f"not strict JSON: {token}")
    return json.loads(text, parse_constant=refuse)


def same(a: Any, b: Any) -> bool:
    """Equal values, NaN equal to NaN."""
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a):
        return math.isnan(b)
    return bool(a == b)


def test_the_fixture_is_of_format_3_with_the_old_tokens() -> None:
    assert json.loads((FORMAT3 / "run.json").read_text())["format_version"] == 3
    raw = (FORMAT3 / "results.jsonl").read_text()
    for token in ('"value": ""', '"value": "undefined"', '"value": "[NaN, NaN]"',
                  '"value": "Infinity"', '"truth": "undefined"'):
        assert token in raw


def test_a_format_3_run_reads_back_upgraded_row_by_row() -> None:
    raw = [json.loads(line) for line in (FORMAT3 / "results.jsonl").read_text().splitlines()]
    frame = read_results(FORMAT3)
    assert len(frame) == len(raw) > 0
    by_key = {(r["case_id"], r["engine"], r["quantity"]): r for r in raw}
    for row in frame.itertuples():
        old = by_key[(row.case_id, row.engine, row.quantity)]
        for column in ("value", "truth"):
            text = getattr(row, column)
            strict(text)  # strict JSON, or it raises
            assert same(decode(text), decode(old[column])), (text, old[column])
            if old[column] in ("", "undefined"):
                assert text == "null"
    assert read_run_info(FORMAT3).engine_names == ["reference", "pymunk"]


def test_report_renders_a_format_3_run(tmp_path: Path) -> None:
    run = copy_of(FORMAT3, tmp_path / "run")
    assert main(["report", str(run)]) == 0
    assert (run / "report.html").stat().st_size > 0
    assert len(read_results(run)) == len((FORMAT3 / "results.jsonl").read_text().splitlines())


@pytest.mark.engine
def test_compare_reads_a_format_3_run_against_a_new_one(tmp_path: Path) -> None:
    old = copy_of(FORMAT3, tmp_path / "old")
    new = tmp_path / "new"
    assert main(["run", str(ROOT / "cases" / "bad_input.toml"), "--engine", "reference",
                 "--engine", "pymunk", "--quick", "--out", str(new)]) == 0
    assert main(["compare", str(old), str(new), "--out", str(tmp_path / "cmp")]) == 0
    assert (tmp_path / "cmp" / "compare.html").exists()


@pytest.mark.parametrize("command", ["report", "compare"])
def test_a_run_of_a_later_format_is_refused_naming_its_version(
        command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    future = copy_of(FORMAT3, tmp_path / "future")
    info = json.loads((future / "run.json").read_text())
    (future / "run.json").write_text(json.dumps({**info, "format_version": 99}))
    argv = ["report", str(future)] if command == "report" else [
        "compare", str(copy_of(FORMAT3, tmp_path / "old")), str(future),
        "--out", str(tmp_path / "cmp")]
    assert main(argv) == 2
    message = " ".join(capsys.readouterr().err.split())
    assert "format 99" in message and "newer crosscheck" in message and "upgrade" in message
    assert "reads formats 1, 2, 3, 4, 5" in message and "Traceback" not in message


@pytest.mark.parametrize("fixture", [FORMAT3, FORMAT4], ids=["format3", "format4"])
def test_a_run_before_the_repeat_check_reads_as_not_asked_again(fixture: Path) -> None:
    assert json.loads((fixture / "run.json").read_text())["format_version"] < 5
    frame = read_results(fixture)
    assert len(frame) == len((fixture / "results.jsonl").read_text().splitlines())
    assert (frame["status"] == "disagree").any()  # rows a repeat check would have asked again
    assert not frame["nondeterministic"].any() and frame["nondeterministic"].dtype == bool
    assert (frame["repeat_status"] == "").all() and frame["repeat_value"].isna().all()
    info = read_run_info(fixture)
    assert info.repeat_check is None and info.options.repeat_check is False


def test_report_and_advise_read_a_format_4_run(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    run = copy_of(FORMAT4, tmp_path / "run")
    assert main(["report", str(run)]) == 0
    page = (run / "report.html").read_text()
    assert "Repeat check</b>: not run" in page
    assert "nondeterministic" in (run / "results.csv").read_text().splitlines()[0]
    capsys.readouterr()
    assert main(["advise", str(run), "--json"]) == 0
    advice = json.loads(capsys.readouterr().out)
    assert advice["repeat_checked"] is False
    assert all(e["repeated"] == 0 == e["nondeterministic"]
               for e in advice["baselines"] + advice["passing"] + advice["partial"]
               + advice["failing"])
