"""The crosscheck command line, end to end on small case files."""

from __future__ import annotations

import html
import json
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from rich.console import Console

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.cli.console import COUNTS_TITLE, TIMES_TITLE, print_summary, summary_table
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import ResponseCase
from crosscheck.results.run import read_run
from crosscheck.results.runinfo import FORMAT_VERSION
from tests.cases.test_load import sphere_text
from tests.conftest import ROOT, embedded
from tests.report import counted as run
from tests.report.counted import counted_run

EVIL = "<script>alert('pwned')</script>"


@pytest.fixture
def small_suite(tmp_path: Path) -> Path:
    text = sphere_text("touch") + sphere_text("evil").replace("two spheres", EVIL)
    path = tmp_path / "cases" / "small.toml"
    path.parent.mkdir()
    path.write_text(text)
    return path


def test_validate_shipped_cases(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(ROOT / "cases")]) == 0
    assert "0 errors" in capsys.readouterr().out


def test_validate_names_file_case_and_field(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(sphere_text("broken-one", ra="-2.0"))
    assert main(["validate", str(bad)]) == 1
    err = capsys.readouterr().err.replace("\n", "")
    assert str(bad) in err and "case 'broken-one'" in err and "field a.radius" in err


def test_new_case_appends_a_valid_block(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    target = tmp_path / "cases" / "mine.toml"
    for kind, dim in [("aabb", 2), ("sphere", 3), ("sphere_response", 2)]:
        case_id = f"new-{kind}-{dim}".replace("_", "-")
        assert main(["new-case", "--kind", kind, "--dim", str(dim), "--id", case_id,
                     "--file", str(target)]) == 0
    assert main(["validate", str(target)]) == 1  # the template's TODO descriptions
    text = target.read_text().replace("TODO: say what this case probes", "two unit bodies")
    target.write_text(text)
    assert main(["validate", str(target)]) == 0
    assert main(["new-case", "--kind", "aabb", "--dim", "2", "--id", "new-aabb-2",
                 "--file", str(target)]) == 2


def test_new_case_says_the_whole_path_of_the_file_it_appended_to(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)  # the default file is relative to the current folder
    assert main(["new-case", "--kind", "sphere", "--dim", "2", "--id", "mine"]) == 0
    said = " ".join(capsys.readouterr().out.split())
    assert f"to {tmp_path / 'cases' / 'user.toml'};" in said
    assert "mine" in (tmp_path / "cases" / "user.toml").read_text()


@pytest.mark.engine
def test_run_writes_results_run_info_and_report(small_suite: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["run", str(small_suite), "--quick", "--out", str(out)]) == 0
    assert {"results.csv", "run.json", "report.html", "summary.csv",
            "disagreements.csv"} <= {p.name for p in out.iterdir()}
    info = json.loads((out / "run.json").read_text())
    assert info["machine"]["packages"]["numpy"] and info["finished"]
    assert [e["name"] for e in info["engines"]] == adapters.names()
    header = (out / "results.csv").read_text().splitlines()[0].split(",")
    assert header[:1] == ["case_id"]
    for column in ("kind", "dim", "engine", "quantity", "value", "truth", "error", "status"):
        assert column in header


def test_report_escapes_case_text(small_suite: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    main(["run", str(small_suite), "--quick", "--out", str(out), "--engine", "reference"])
    html = (out / "report.html").read_text()
    assert EVIL not in html  # not as markup: the case text travels as data, packed
    cases = embedded(html, "results-data")
    assert EVIL in json.dumps(cases)  # and the page shows it as text (tests/report/test_browser)


@pytest.mark.engine
def test_report_rerenders_without_running_engines(small_suite: Path, tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "out"
    main(["run", str(small_suite), "--quick", "--out", str(out)])
    before = (out / "results.csv").read_text()
    (out / "results.csv").unlink()
    (out / "report.html").unlink()

    def forbidden(name: str) -> None:
        raise AssertionError("a report must not run engines")

    monkeypatch.setattr(adapters, "get", forbidden)
    assert main(["report", str(out)]) == 0
    assert (out / "results.csv").read_text() == before
    assert (out / "report.html").exists()


@pytest.mark.engine
def test_run_goes_on_past_a_bad_case_and_exits_nonzero(small_suite: Path, tmp_path: Path) -> None:
    with small_suite.open("a") as handle:
        handle.write(sphere_text("bad-radius", ra="nan"))
    out = tmp_path / "out"
    assert main(["run", str(small_suite), "--quick", "--out", str(out)]) == 1
    info = json.loads((out / "run.json").read_text())
    assert info["cases_run"] == 4  # two valid blocks and their swapped twins
    assert any("bad-radius" in e and "a.radius" in e for e in info["case_errors"])


@pytest.mark.engine
def test_unwritable_output_is_a_clear_error(small_suite: Path, tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["run", str(small_suite), "--quick", "--out", str(blocker / "sub")]) == 2
    assert "cannot write results" in capsys.readouterr().err


def test_schema_check(tmp_path: Path) -> None:
    assert main(["schema", "--check", "--output", str(ROOT / "cases" / "schema.json")]) == 0
    stale = tmp_path / "schema.json"
    stale.write_text("{}")
    assert main(["schema", "--check", "--output", str(stale)]) == 1


def test_engines_lists_every_adapter(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["engines"]) == 0
    listing = capsys.readouterr().out
    for name in adapters.names():
        assert name in listing


def test_console_script_is_installed() -> None:
    script = Path(sys.executable).parent / "crosscheck"
    done = subprocess.run([str(script), "--help"], capture_output=True, text=True, check=True)
    assert "validate" in done.stdout


def test_new_case_with_geometry_writes_the_finished_case(tmp_path: Path) -> None:
    target = tmp_path / "mine.toml"
    assert main(["new-case", "--kind", "sphere_response", "--dim", "2", "--id", "hit-heavy",
                 "--file", str(target), "--description", "light ball hits a heavy one",
                 "--tag", "mass-ratio", "--a-center", "0,0", "--a-mass", "1e-6",
                 "--a-velocity", "0.1,0.3", "--b-center", "0.6,0.8", "--b-mass", "1e6",
                 "--restitution", "0.5"]) == 0
    (case,) = [c for c in load_paths([target]).cases if c.id == "hit-heavy"]
    assert isinstance(case, ResponseCase)
    assert case.a.velocity == (0.1, 0.3) and case.b.center == (0.6, 0.8)
    assert case.a.mass == 1e-6 and case.restitution == 0.5 and case.tags == ("mass-ratio",)
    assert main(["new-case", "--kind", "aabb", "--dim", "3", "--id", "bad-box",
                 "--file", str(target), "--a-half", "1,-1,1"]) == 2
    assert "bad-box" not in target.read_text()


def test_a_run_says_what_it_runs_progresses_in_plain_lines_and_says_when_it_is_done(
        small_suite: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["run", str(small_suite), "--engine", "reference", "--out", str(out),
                 "--timing-cases", "2", "--samples", "3", "--min-sample", "0.0005"]) == 0
    captured = capsys.readouterr()
    printed = captured.out.replace("\n", " ")
    assert f"x 1 engines (reference) -> {out}" in printed and "finished in " in printed
    progress = captured.err  # not a terminal: plain lines, on stderr
    assert "case x engine: " in progress and "(100%," in progress
    assert "timing (rounds, steps): " in progress and "case x engine" not in printed


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    expected = rf"crosscheck \S+ \(results format {FORMAT_VERSION}\)\n"
    assert re.fullmatch(expected, capsys.readouterr().out)


@pytest.mark.engine
def test_the_summary_reads_whole_at_80_columns(small_suite: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["run", str(small_suite), "--quick", "--out", str(out)]) == 0
    console = Console(width=80, record=True)
    summary = pd.read_csv(out / "summary.csv", keep_default_na=False)
    console.print(summary_table(summary, "summary"))
    text = console.export_text()
    assert "…" not in text and max(len(line.rstrip()) for line in text.splitlines()) <= 80
    for engine in set(summary["engine"]):
        assert f"\n{engine} " in text or f"\n{engine}\n" in text


def test_help_names_engines_defaults_and_examples(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = re.sub(r"-\s+", "-", " ".join(capsys.readouterr().out.split()))  # undo wrapping
    assert "pybullet-default" in text and f"default {RunOptions().timing_cases})" in text
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "examples:" in capsys.readouterr().out
    with pytest.raises(SystemExit) as refused:
        main(["run", "--engine", "nosuch"])
    assert refused.value.code == 2 and "invalid choice: 'nosuch'" in capsys.readouterr().err


def test_resume_from_the_cli_reports_progress(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    case_file = ROOT / "cases" / "sphere.toml"
    assert main(["run", str(case_file), "--quick", "--engine", "reference", "--out", str(out)]) == 0
    assert main(["run", "--resume", str(out)]) == 0
    assert "already done" in capsys.readouterr().out


@pytest.mark.engine
def test_the_run_prints_each_engine_and_kind_time_as_the_page_does(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The run's closing times table and the report's engine x kind table show the same
    figure in the same format (median ± IQR over the timed cases) for every engine x kind."""
    out = tmp_path / "run"
    cases = [str(ROOT / "cases" / name) for name in ("sphere.toml", "response.toml")]
    assert main(["run", *cases, "--engine", "reference", "--engine", "pymunk", "--samples", "3",
                 "--min-sample", "0.0005", "--timing-cases", "3", "--out", str(out)]) == 0
    printed = capsys.readouterr().out.split(TIMES_TITLE + "\n")[1].split("\nfinished")[0]
    header, *rows = [line.split() for line in printed.splitlines()
                     if line.strip() and not line.startswith("─")]
    in_terminal = {(row[0], kind): " ".join(cell) for row in rows
                   for kind, cell in zip(header[1:], _cells(row[1:]), strict=True)}
    page = (out / "report.html").read_text()
    row = r"<tr><td>([^<]+)</td><td>([^<]+)</td>(?:(?!</tr>).)*?<td class=\"num time\">([^<]+)<"
    on_page = {(engine, kind): html.unescape(time)  # the page escapes "<0.01" as HTML
               for engine, kind, time in re.findall(row, page, re.S)}
    assert on_page and set(on_page) <= set(in_terminal)
    for key, time in on_page.items():
        assert in_terminal[key] == time, key
    assert all(in_terminal[key] == "-" for key in set(in_terminal) - set(on_page))


def _cells(words: list[str]) -> list[list[str]]:
    """A times row's words grouped into cells: '12.8 ± 1.2 µs' is four words, '-' one."""
    cells, at = [], 0
    while at < len(words):
        width = 1 if words[at] == "-" else (4 if words[at + 1] == "±" else 2)
        cells.append(words[at:at + width])
        at += width
    return cells


def test_the_closing_tables_give_instructions_where_counted_as_the_page_does(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A run with counts (written by the test) ends with the instructions per query per engine
    x kind before the query times, cell for cell as the page's engine x kind table; a run
    without counts prints the query times alone, as before."""
    counted = counted_run(tmp_path / "counted")
    print_summary(read_run(counted))
    printed = capsys.readouterr().out
    assert printed.index(COUNTS_TITLE) < printed.index(TIMES_TITLE)
    table = printed.split(COUNTS_TITLE + "\n")[1].split(TIMES_TITLE)[0]
    header, *rows = [line.split() for line in table.splitlines()
                     if line.strip() and not line.startswith("─")]
    in_terminal = {(row[0], header[1]): " ".join(row[1:]) for row in rows}
    page = (counted / "report.html").read_text()
    cell = (r"<tr><td>([^<]+)</td><td>([^<]+)</td>(?:(?!</tr>).)*?"
            r"<td class=\"num instr\"[^>]*>([^<]+)<")
    on_page = {(engine, kind): text for engine, kind, text in re.findall(cell, page, re.S)}
    assert set(on_page) == set(in_terminal) == {(e, "sphere") for e in run.INSTRUCTIONS}
    assert on_page == in_terminal
    print_summary(read_run(counted_run(tmp_path / "uncounted", {})))
    printed = capsys.readouterr().out
    assert COUNTS_TITLE not in printed and TIMES_TITLE in printed
