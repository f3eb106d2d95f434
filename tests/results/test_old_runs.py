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

``tests/data/format5-timed-run`` was written by the harness of the commit before the timing
phase's rounds (``55f0e8d``, format 5), with a timing phase: its ``timings.jsonl`` lines
have no per-round ``yardstick``, and run.json's ``timing`` no ``rounds``:

    git archive 55f0e8d | tar -x -C /tmp/fmt5 && cd /tmp/fmt5
    PYTHONPATH=. python -m crosscheck.cli run cases/sphere.toml --engine reference \
        --engine reference-f32 --timing-cases 2 --samples 12 --out reports/format5-timed
    cp reports/format5-timed/{run.json,cases.jsonl,results.jsonl,timings.jsonl} \
        tests/data/format5-timed-run/
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Any

import pytest

from crosscheck.cli import main
from crosscheck.compare.runs import compare
from crosscheck.core.values import decode
from crosscheck.results.run import read_results, read_run_info
from crosscheck.results.timings import TimingRecord, read_timings
from tests.conftest import ROOT

FORMAT3 = Path(__file__).resolve().parent.parent / "data" / "format3-run"
FORMAT4 = Path(__file__).resolve().parent.parent / "data" / "format4-run"
FORMAT5_TIMED = Path(__file__).resolve().parent.parent / "data" / "format5-timed-run"


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


def test_timings_from_before_the_rounds_read_back_without_yardsticks() -> None:
    lines = (FORMAT5_TIMED / "timings.jsonl").read_text().splitlines()
    assert lines and not any("yardstick" in json.loads(line) for line in lines)
    assert "rounds" not in json.loads((FORMAT5_TIMED / "run.json").read_text())["timing"]
    timings = read_timings(FORMAT5_TIMED)
    assert len(timings) == len(lines) and (timings["n"] == 12).all()
    assert all(list(y) == [] for y in timings["yardstick"])
    assert timings["normalised_median"].isna().all()
    assert all(TimingRecord.from_json(line).normalised == () for line in lines)
    frame = read_results(FORMAT5_TIMED)  # the results' timing columns still come from them
    assert frame["query_s"].notna().any()


def test_report_renders_a_run_timed_before_the_rounds(tmp_path: Path) -> None:
    run = copy_of(FORMAT5_TIMED, tmp_path / "run")
    assert main(["report", str(run)]) == 0
    assert "Timing" in (run / "report.html").read_text()


def in_rounds(source: Path, target: Path) -> Path:
    """A copy of a stored run whose samples carry a round yardstick each (1 ms)."""
    run = copy_of(source, target)
    lines = [json.loads(line) for line in (run / "timings.jsonl").read_text().splitlines()]
    (run / "timings.jsonl").write_text("".join(
        json.dumps(line | {"yardstick": [1e-3] * len(line["values"])}) + "\n" for line in lines))
    return run


def test_compare_judges_a_run_before_the_rounds_the_old_way(tmp_path: Path) -> None:
    old = copy_of(FORMAT5_TIMED, tmp_path / "old")
    new = in_rounds(FORMAT5_TIMED, tmp_path / "new")
    mixed = compare(old, new, tmp_path / "mixed")
    assert mixed.timing_pairs == 4 and mixed.timing_counts["same"] == 4
    assert "round" not in mixed.normalisation  # the start and end yardsticks, or none
    both = compare(new, in_rounds(FORMAT5_TIMED, tmp_path / "new2"), tmp_path / "both")
    assert both.normalised and "its round's yardstick" in both.normalisation
    assert both.timing_counts["same"] == 4
