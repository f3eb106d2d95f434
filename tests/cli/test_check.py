"""``crosscheck baseline`` and ``crosscheck check`` end to end on runs of fake engines: exit
codes, what they say, the files they write, and ``crosscheck run --baseline``."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import xmlschema

from crosscheck.cli import engines as engine_choice
from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.cases.test_load import sphere_text
from tests.conftest import ROOT, sphere

CASES = [sphere(0.0, 2.0, id="apart"), sphere(0.0, 1.0, id="touch"),
         sphere(0.0, 0.75, id="overlap")]
Edit = Callable[[dict[str, Any]], dict[str, Any] | None]


@pytest.fixture(scope="module")
def original(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished quick run of CASES on an engine that is always right and one whose
    distance is always 1 too large (a disagreement of category error, error 1)."""
    folder = tmp_path_factory.mktemp("runs") / "original"
    engines = [fakes.AlwaysRight(), fakes.OffByOne()]
    options = RunOptions(quick=True, isolate=False, jobs=1)
    launch(ResultsStore(folder), CASES, engines, options,
           new_info(folder, "test", options, engines, CASES))
    return folder


@pytest.fixture
def run(original: Path, tmp_path: Path) -> Path:
    """A copy of the original run, free to edit."""
    return Path(shutil.copytree(original, tmp_path / "run"))


def edit(run: Path, change: Edit) -> None:
    """Rewrite each row of ``run``'s results.jsonl as ``change`` returns it (None: drop it)."""
    path = run / "results.jsonl"
    rows = [change(json.loads(line)) for line in path.read_text().splitlines()]
    path.write_text("".join(json.dumps(r) + "\n" for r in rows if r is not None))


def at(case: str, engine: str, quantity: str, **fields: Any) -> Edit:
    """An edit of one row's fields."""
    def change(row: dict[str, Any]) -> dict[str, Any]:
        hit = (row["case_id"], row["engine"], row["quantity"]) == (case, engine, quantity)
        return row | fields if hit else row
    return change


def flat(text: str) -> str:
    return " ".join(text.split())


def baseline_of(run: Path, tmp_path: Path, *options: str) -> Path:
    path = tmp_path / "baseline.jsonl"
    assert main(["baseline", str(run), "--out", str(path), *options]) == 0
    return path


def check(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    """``crosscheck check`` with ``args``: its exit code, stdout and stderr (flattened)."""
    capsys.readouterr()
    code = main(["check", *args])
    printed = capsys.readouterr()
    return code, flat(printed.out), flat(printed.err)


def test_a_run_checked_against_its_own_baseline_passes(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    code, out, _ = check(capsys, str(run), "--baseline", str(base))
    assert code == 0, out
    assert "regression 0" in out and "passed" in out
    rows = len((run / "results.jsonl").read_text().splitlines())
    assert f"expected {rows} " in out
    assert len(base.read_text().splitlines()) == rows + 1  # the header, then a line per row


def test_an_injected_regression_fails_naming_it(run: Path, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    edit(run, at("touch", "fake-right", "distance", status="disagree", category="error",
                 error=0.25))
    code, out, _ = check(capsys, str(run), "--baseline", str(base))
    assert code == 1
    assert "regression 1" in out and "failed (1 regression)" in out
    assert "fake-right touch distance a new disagreement" in out and "0.25" in out


def test_an_error_grown_beyond_the_margin_fails_with_its_numbers(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    edit(run, at("apart", "fake-off", "distance", error=1.6))
    code, out, _ = check(capsys, str(run), "--baseline", str(base))
    assert code == 1
    assert "error 1.6 > bound 1 x (1 + margin 0.5) = 1.5" in out
    assert check(capsys, str(run), "--baseline", str(base), "--margin", "0.7")[0] == 0


def test_an_engine_better_beyond_the_factor_fails_saying_the_baseline_is_stale(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    edit(run, at("apart", "fake-off", "distance", error=0.4))
    code, out, _ = check(capsys, str(run), "--baseline", str(base))
    assert code == 1 and "failed (1 stale)" in out
    assert "error 0.4 < bound 1 / stale factor 2 = 0.5: better than the baseline, update it" in out


def test_missing_and_new_rows_fail(run: Path, tmp_path: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path, "--engine", "fake-right")
    assert check(capsys, str(run), "--baseline", str(base), "--engine", "fake-right")[0] == 0
    fewer = Path(shutil.copytree(run, tmp_path / "fewer"))
    edit(fewer, lambda row: None if row["case_id"] == "apart" else row)
    smaller = baseline_of(fewer, tmp_path / "smaller", "--engine", "fake-right")
    code, out, _ = check(capsys, str(run), "--baseline", str(smaller), "--engine", "fake-right")
    assert code == 1 and "new 3" in out and "not in the baseline" in out  # apart's 3 rows
    edit(run, lambda row: None if row["case_id"] == "overlap" else row)
    code, out, _ = check(capsys, str(run), "--baseline", str(base), "--engine", "fake-right")
    assert code == 1 and "missing 3" in out and "not in the run" in out
    assert "engines: fake-right only" in out


def test_a_baseline_of_fewer_engines_without_engine_says_to_add_it(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Every row of an engine the baseline has no row of would be new: the check says so
    before judging any row, naming the baseline's engines and --engine, and exits 2."""
    base = baseline_of(run, tmp_path, "--engine", "fake-right")
    offs = sum('"fake-off"' in line for line in (run / "results.jsonl").read_text().splitlines())
    code, out, err = check(capsys, str(run), "--baseline", str(base))
    assert code == 2 and out == "" and "new" not in out
    assert f"{base} holds rows of fake-right only" in err
    assert f"1 engine it has no row of (fake-off): each of their {offs} rows would be new" in err
    assert "Check only the baseline's engines with --engine fake-right" in err
    assert check(capsys, str(run), "--baseline", str(base), "--update")[0] == 0  # adds them


def test_without_a_baseline_every_disagreement_fails(
        run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = check(capsys, str(run))
    assert code == 1 and "with no baseline: every disagreement fails" in out
    assert check(capsys, str(run), "--engine", "fake-right")[0] == 0


def test_a_malformed_baseline_exits_2_naming_file_and_line(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    lines = base.read_text().splitlines()
    lines[2] = lines[2].replace('"status": "agree"', '"status": "fine"')
    base.write_text("\n".join(lines) + "\n")
    with pytest.raises(SystemExit) as refused:
        main(["check", str(run), "--baseline", str(base)])
    assert refused.value.code == 2
    said = flat(capsys.readouterr().err)
    assert f"{base}, line 3: unknown status 'fine'" in said


@pytest.mark.parametrize("problem", ["no-folder", "no-results", "unknown-engine"])
def test_input_errors_exit_2_before_any_work(problem: str, run: Path, tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    args = [str(run), "--baseline", str(base), "--junit", str(tmp_path / "j.xml")]
    if problem == "no-folder":
        args[0] = str(tmp_path / "nowhere")
    elif problem == "no-results":
        (run / "results.jsonl").write_text("")
    else:
        args += ["--engine", "nosuch"]
    code, _, err = check(capsys, *args)
    assert code == 2 and not (tmp_path / "j.xml").exists()
    assert {"no-folder": "no such run folder", "no-results": "has no results",
            "unknown-engine": "no rows of nosuch"}[problem] in err


def test_bad_options_exit_2(run: Path, tmp_path: Path) -> None:
    for bad in (["--margin", "-1"], ["--stale-factor", "0.5"], ["--junit", str(tmp_path)]):
        with pytest.raises(SystemExit) as refused:
            main(["check", str(run), *bad])
        assert refused.value.code == 2


def test_baseline_refuses_an_unfinished_run(run: Path, tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    info = json.loads((run / "run.json").read_text())
    (run / "run.json").write_text(json.dumps(info | {"finished": None}))
    assert main(["baseline", str(run), "--out", str(tmp_path / "b.jsonl")]) == 2
    assert "unfinished run" in flat(capsys.readouterr().err)
    assert not (tmp_path / "b.jsonl").exists()
    code, _, err = check(capsys, str(run))
    assert "unfinished" in err and code == 1  # checked all the same, with a warning


def test_update_rewrites_the_baseline_says_what_changed_and_exits_0(
        run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path, "--margin", "0.25")
    edit(run, at("apart", "fake-off", "distance", error=0.4))
    code, out, _ = check(capsys, str(run), "--baseline", str(base), "--update")
    assert code == 0
    assert "0 added, 0 removed, 1 changed" in out
    assert ("fake-off apart distance: disagree (error), error 1 -> disagree (error), "
            "error 0.4") in out
    assert json.loads(base.read_text().splitlines()[0])["margin"] == 0.25  # kept
    assert '"case": "apart", "quantity": "distance", "status": "disagree", "category": ' \
           '"error", "error": 0.4}' in base.read_text()
    assert check(capsys, str(run), "--baseline", str(base))[0] == 0


def test_update_needs_a_baseline(run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = check(capsys, str(run), "--update")
    assert code == 2 and "--update rewrites the file given by --baseline" in err


def test_junit_and_markdown_outputs(run: Path, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    base = baseline_of(run, tmp_path)
    edit(run, at("touch", "fake-right", "hit", status="crash", reason="worker died | signal"))
    junit, markdown = tmp_path / "out" / "junit.xml", tmp_path / "summary.md"
    code, _, _ = check(capsys, str(run), "--baseline", str(base), "--junit", str(junit),
                       "--markdown", str(markdown))
    assert code == 1
    xmlschema.XMLSchema(ROOT / "tests" / "data" / "junit.xsd").validate(junit.read_text())
    assert 'failures="1"' in junit.read_text() and "touch :: hit" in junit.read_text()
    text = markdown.read_text()
    assert text.startswith("## crosscheck check: failed (1 regression)")
    assert "worker died \\| signal" in text
    capsys.readouterr()
    assert main(["check", str(run), "--baseline", str(base), "--markdown", "-"]) == 1
    printed = capsys.readouterr()
    assert printed.out == text  # stdout is the Markdown alone, the summary on stderr
    assert "failed (1 regression)" in flat(printed.err)


@pytest.fixture
def fake_engines(monkeypatch: pytest.MonkeyPatch) -> None:
    """``crosscheck run --engine reference`` runs the always-right fake instead."""
    monkeypatch.setattr(engine_choice, "select", lambda names: [fakes.AlwaysRight()])


def test_run_with_a_baseline_exits_with_the_checks_code(
        fake_engines: None, original: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    cases = tmp_path / "cases.toml"
    cases.write_text(sphere_text("touch") + sphere_text("apart", bx="2.0"))
    base = tmp_path / "base.jsonl"
    command = ["run", str(cases), "--quick", "--no-isolation", "--engine", "reference"]
    assert main([*command, "--out", str(tmp_path / "first")]) == 0
    assert main(["baseline", str(tmp_path / "first"), "--out", str(base)]) == 0
    junit = tmp_path / "junit.xml"
    assert main([*command, "--out", str(tmp_path / "same"), "--baseline", str(base),
                 "--junit", str(junit)]) == 0
    assert 'failures="0"' in junit.read_text()
    cases.write_text(sphere_text("touch"))  # one case fewer: its rows are missing
    assert main([*command, "--out", str(tmp_path / "fewer"), "--baseline", str(base)]) == 1
    gone = base.read_text().count('"case": "apart')
    assert gone >= 3 and f"failed ({gone} missing)" in flat(capsys.readouterr().out)


def test_run_refuses_a_malformed_baseline_before_it_starts(
        fake_engines: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cases = tmp_path / "cases.toml"
    cases.write_text(sphere_text("touch"))
    base = tmp_path / "base.jsonl"
    base.write_text("{}\n")
    with pytest.raises(SystemExit) as refused:
        main(["run", str(cases), "--quick", "--out", str(tmp_path / "r"), "--baseline",
              str(base)])
    assert refused.value.code == 2 and not (tmp_path / "r").exists()
    assert f"{base}, line 1: not a baseline header" in flat(capsys.readouterr().err)


def test_resume_refuses_the_check_options(original: Path, capsys: pytest.CaptureFixture[str]
                                          ) -> None:
    assert main(["run", "--resume", str(original), "--junit", "j.xml"]) == 2
    assert "--junit" in flat(capsys.readouterr().err)
