"""Bad input is refused before any work starts or any folder is made: every bad command line
of ``run``, ``run --resume`` and ``new-case`` is an exit 2 with a message naming the option
and what it allows, never a traceback.  (Malformed case files: tests/cases/test_malformed.py
and tests/cases/test_load.py.)"""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.cli import main
from crosscheck.results.run import read_results
from tests.conftest import ROOT

SPHERES = str(ROOT / "cases" / "sphere.toml")


def refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """The error text of a command line that must be refused (argparse or the command)."""
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    assert code == 2
    return capsys.readouterr().err


@pytest.mark.parametrize(("option", "value", "allowed"), [
    ("--timeout", "-1", "> 0"), ("--timeout", "0", "> 0"), ("--timeout", "nan", "> 0"),
    ("--jobs", "-3", ">= 1"), ("--jobs", "0", ">= 1"), ("--jobs", "two", ">= 1"),
    ("--samples", "0", ">= 1"), ("--min-sample", "0", "> 0"), ("--min-sample", "-0.1", "> 0"),
    ("--scene-repeats", "0", ">= 1"), ("--timing-cases", "-1", ">= 0"),
])
def test_non_positive_numbers_are_refused_before_any_folder(
        option: str, value: str, allowed: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    message = refused(["run", SPHERES, "--engine", "reference", "--quick", "--out", str(out),
                       option, value], capsys)
    assert option in message and allowed in message and repr(value) in message
    assert not out.exists()


def test_unknown_engine_lists_the_known_ones(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    message = refused(["run", SPHERES, "--engine", "nosuch", "--out", str(out)], capsys)
    assert "--engine" in message and "nosuch" in message and "'reference'" in message
    assert "Traceback" not in message and not out.exists()


def test_missing_case_path_is_refused_before_any_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    missing = tmp_path / "nowhere.toml"
    message = refused(["run", str(missing), "--engine", "reference", "--out", str(out)], capsys)
    assert str(missing) in message and not out.exists()


def test_no_case_files_outside_the_project_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # no cases/ here
    message = refused(["run", "--engine", "reference", "--quick"], capsys)
    assert "no case files found under cases/: run from the project root or pass a path" in message
    empty = tmp_path / "empty"
    empty.mkdir()
    message = refused(["run", str(empty), "--engine", "reference"], capsys)
    assert f"no case files found under {empty}/" in message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty"]  # no reports/ folder


def test_resume_with_options_that_change_the_run_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    assert main(["run", SPHERES, "--quick", "--engine", "reference", "--out", str(out)]) == 0
    rows = len(read_results(out))
    capsys.readouterr()
    message = refused(["run", "--resume", str(out), "--engine", "pymunk", "--timeout", "9",
                       "--worker-memory", "100",
                       SPHERES], capsys)
    assert "--engine" in message and "--timeout" in message and "case paths" in message
    assert "--worker-memory" in message
    assert "--resume" in message
    assert len(read_results(out)) == rows
    assert main(["run", "--resume", str(out)]) == 0  # alone, it is accepted


@pytest.mark.parametrize(("options", "expected"), [
    (["--kind", "sphere", "--a-radius", "1,2"], "--a-radius: must be one number, not '1,2'"),
    (["--kind", "sphere", "--a-center", "1,,2"], "--a-center: must be numbers separated"),
    (["--kind", "sphere", "--a-center", "1,2"], "--a-center needs 3 numbers (--dim 3), got 2"),
    (["--kind", "aabb", "--restitution", "0.5"],
     "--restitution applies to sphere_response cases only, not aabb"),
    (["--kind", "aabb", "--b-radius", "1"], "--b-radius applies to sphere, sphere_response"),
    (["--kind", "sphere", "--a-half", "1,1,1"], "--a-half applies to aabb cases only"),
    (["--kind", "sphere", "--a-mass", "2"], "--a-mass applies to sphere_response cases only"),
])
def test_new_case_refuses_malformed_and_inapplicable_options(
        options: list[str], expected: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "user.toml"
    message = refused(["new-case", *options, "--dim", "3", "--id", "fresh-case",
                       "--file", str(target)], capsys)
    assert expected in " ".join(message.split())
    assert not target.exists()


def test_deep_with_case_paths_is_refused_before_any_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    message = refused(["run", "--deep", SPHERES, "--engine", "reference", "--out", str(out)],
                      capsys)
    assert "--deep" in message and SPHERES in message and "cases-deep/" in message
    assert not out.exists()
