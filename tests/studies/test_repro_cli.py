"""``crosscheck repro``: stdout unless --out, every disagreeing engine, issue-ready reports, and
``--all``: a run writes no script, its report gives the command, ``--all`` writes them all.

Reads the small real run of ``tests/studies/conftest.py``.  What a report must hold comes
from the stored run itself (run.json's engine, version and machine, results.csv's rows, the
case's source file), never from an engine's known answer.
"""

from __future__ import annotations

import html
import json
import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import pytest

from crosscheck.cli import main
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import SceneCase
from crosscheck.results.run import read_run
from crosscheck.results.store import REPRO_DIR, ResultsStore, repro_name
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.repro.script import RunRows, breaking_pairs, scripts
from tests import fakes
from tests.conftest import ROOT, embedded, sphere

pytestmark = pytest.mark.engine


def answers(out: str, quantities: set[str]) -> dict[str, str]:
    return {k: t for k, sep, t in (line.partition(" = ") for line in out.splitlines())
            if sep and k in quantities}


def test_one_script_goes_to_stdout_or_to_out(repro_run: Path, tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    case_id = "aabb-2d-corner-touch-unequal"
    shadow = tmp_path / "coal.py"  # python would import the script itself for `import coal`
    assert main(["repro", str(repro_run), case_id, "--engine", "coal", "--out", str(shadow)]) == 2
    target = tmp_path / "repro-coal.py"
    assert main(["repro", str(repro_run), case_id, "--engine", "coal", "--out", str(target)]) == 0
    done = subprocess.run([sys.executable, str(target)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120, check=True)
    rows = RunRows(read_run(repro_run)).rows(case_id, "coal")
    assert answers(done.stdout, {"hit", "distance", "normal"}) == {
        str(r["quantity"]): str(r["value"]) for r in rows}
    capsys.readouterr()
    assert main(["repro", str(repro_run), case_id, "--engine", "box2d"]) == 0
    assert capsys.readouterr().out == scripts(read_run(repro_run), case_id, "box2d")[0].text
    assert main(["repro", str(repro_run), "no-such-case"]) == 2


def test_without_engine_every_disagreeing_engine_is_printed_and_no_file_written(
        repro_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    case_id = "sphere-3d-scale-1e-3-touch-122"
    runs = RunRows(read_run(repro_run))
    disagreeing = [e for e in runs.stored.info.engine_names
                   if any(r["status"] not in ("agree", "skip") for r in runs.rows(case_id, e))]
    assert len(disagreeing) >= 3
    capsys.readouterr()
    assert main(["repro", str(repro_run), case_id]) == 0
    captured = capsys.readouterr()
    assert list(tmp_path.iterdir()) == []
    heads = re.findall(r"^# ===== repro (\d+) of (\d+): case (\S+) on engine (\S+) =====$",
                       captured.out, flags=re.MULTILINE)
    assert [h[3] for h in heads] == disagreeing
    assert {h[1] for h in heads} == {str(len(disagreeing))} and {h[2] for h in heads} == {case_id}
    said = " ".join(captured.err.split())  # wrapped to the terminal's width
    assert ", ".join(disagreeing) in said and "disagree" in said
    several = tmp_path / "many.py"
    assert main(["repro", str(repro_run), case_id, "--out", str(several)]) == 0
    assert sorted(p.name for p in tmp_path.glob("many-*.py")) == sorted(
        f"many-{e}.py" for e in disagreeing)


def _issue(repro_run: Path, case_id: str, engine: str,
           capsys: pytest.CaptureFixture[str]) -> str:
    capsys.readouterr()
    assert main(["repro", str(repro_run), case_id, "--engine", engine, "--issue"]) == 0
    return capsys.readouterr().out


def _fenced(markdown: str, language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)\n```$", markdown, flags=re.MULTILINE | re.DOTALL)


def test_the_issue_report_names_the_engine_version_platform_and_the_numbers(
        repro_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    case_id = "sphere-3d-scale-1e-3-touch-122"
    report = _issue(repro_run, case_id, "rapier", capsys)
    info = json.loads((repro_run / "run.json").read_text(encoding="utf-8"))
    engine = next(e for e in info["engines"] if e["name"] == "rapier")
    assert engine["engine"] == "rapier3d"
    assert f"{engine['engine']} {engine['version']}" in report.splitlines()[0]
    machine = info["machine"]
    assert all(str(machine[key]) in report for key in ("platform", "python", "cpu"))
    for row in RunRows(read_run(repro_run)).rows(case_id, "rapier"):
        line = next(li for li in report.splitlines() if li.startswith(f"| {row['quantity']} |"))
        assert f"`{row['value']}`" in line and f"`{row['truth']}`" in line
        assert str(row["status"]) in line
        if row["status"] == "disagree":
            assert "float64 bound" in line and str(row["reason"]) in report
    assert "conventions consulted (rapier, declared in run.json)" in report
    script = _fenced(report, "python")
    assert script == [scripts(read_run(repro_run), case_id, "rapier")[0].text.rstrip("\n")]
    blocks = _fenced(report, "toml")
    assert [tomllib.loads(b)["case"][0]["id"] for b in blocks] == [case_id]
    source = (ROOT / "cases" / "scale.toml").read_text(encoding="utf-8")
    assert blocks[0] in source  # the block as written in its case file


def test_an_expanded_case_shows_its_block_and_itself_and_mujoco_its_mjcf(
        repro_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    stored = read_run(repro_run)
    case_id = "scene-2d-head-on.dt=0.1"
    report = _issue(repro_run, case_id, "pymunk", capsys)
    blocks = _fenced(report, "toml")
    assert [tomllib.loads(b)["case"][0]["id"] for b in blocks] == ["scene-2d-head-on", case_id]
    assert blocks[0] in (ROOT / "cases" / "scenes.toml").read_text(encoding="utf-8")
    case = stored.cases[case_id]
    assert isinstance(case, SceneCase)
    assert tomllib.loads(blocks[1])["case"][0]["dt"] == case.dt
    report = _issue(repro_run, "resp-2d-oblique-345-mass-2-1", "mujoco", capsys)
    (model,) = _fenced(report, "xml")
    assert model.startswith("<mujoco") and model in _fenced(report, "python")[0]


@pytest.fixture(scope="module")
def floats_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``crosscheck run --quick`` of the float traps on Box2D and Rapier (both disagree)."""
    out = tmp_path_factory.mktemp("floats") / "run"
    assert main(["run", str(ROOT / "cases" / "float_traps.toml"), "--quick", "--engine",
                 "box2d", "--engine", "rapier", "--out", str(out)]) == 0
    return out


def _table(run: Path) -> tuple[str, dict[tuple[str, str], dict[str, Any]]]:
    """The run folder the report's results table carries, and its rows by (case id, engine)."""
    data = embedded((run / "report.html").read_text(encoding="utf-8"), "results-data")
    return data["run"], {(data["cases"][r["case"]]["id"], r["engine"]): r for r in data["rows"]}


def test_a_run_writes_no_script_and_its_report_gives_the_command(floats_run: Path) -> None:
    """No ``repro/`` after a run: the report's table carries the run folder once, from which
    the page builds each breaking row's command, and no row links a script."""
    assert not (floats_run / REPRO_DIR).exists()
    folder, rows = _table(floats_run)
    assert folder == str(floats_run)
    pairs = breaking_pairs(RunRows(read_run(floats_run)))
    assert {e for _, e in pairs} == {"box2d", "rapier"}
    assert all(row["repro"] == "" for row in rows.values())
    assert all(str(rows[pair]["status"]) in ("disagree", "error", "crash", "timeout")
               for pair in pairs)
    page = (floats_run / "report.html").read_text(encoding="utf-8")
    assert f'href="{REPRO_DIR}/' not in page
    commands = {shlex.join(["crosscheck", "repro", str(floats_run), case, "--engine", engine])
                for case, engine in pairs}
    modes = [html.unescape(command) for command in verdict_modes(page)]
    assert modes and set(modes) <= commands  # each failure mode's example, as a command


def verdict_modes(html: str) -> list[str]:
    """The repro commands of the verdict block's failure modes (server-rendered; the block
    holds no script)."""
    start = html.index('<div id="verdict"')
    return re.findall(r'<details class="repro-command"><summary[^>]*>[^<]*</summary>'
                      r"<code>([^<]*)</code>", html[start:html.index("<script", start)])


def test_repro_all_writes_every_breaking_pairs_script_and_the_report_links_them(
        floats_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    run = tmp_path / "run"
    subprocess.run(["cp", "-r", str(floats_run), str(run)], check=True)
    pairs = breaking_pairs(RunRows(read_run(run)))
    expected = {f"{repro_name(*pair)}.py" for pair in pairs}
    elsewhere = tmp_path / "scripts"
    assert main(["repro", str(run), "--all", "--out", str(elsewhere)]) == 0
    assert {p.name for p in elsewhere.iterdir()} == expected
    assert not (run / REPRO_DIR).exists()
    capsys.readouterr()
    assert main(["repro", str(run), "--all"]) == 0
    said = " ".join(capsys.readouterr().out.split())
    assert f"{len(expected)} script(s) written into {run / REPRO_DIR}" in said
    assert f"crosscheck report {run}" in said
    assert {p.name for p in (run / REPRO_DIR).iterdir()} == expected
    case, engine = pairs[0]
    assert (run / REPRO_DIR / f"{repro_name(case, engine)}.py").read_text(
        encoding="utf-8") == scripts(read_run(run), case, engine)[0].text
    assert main(["report", str(run)]) == 0
    folder, rows = _table(run)
    assert folder == str(run)
    linked = {pair for pair, row in rows.items() if row["repro"]}
    assert linked == set(pairs)
    assert all(rows[pair]["repro"] == f"{REPRO_DIR}/{repro_name(*pair)}.py" for pair in pairs)
    html = (run / "report.html").read_text(encoding="utf-8")
    assert f'href="{REPRO_DIR}/{repro_name(case, engine)}.py"' in html


def test_the_command_the_report_gives_says_so_for_an_engine_without_a_calls_module(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The report gives every breaking row the command; on an engine whose calls are not a
    module (here a fake with its own prepare and query) it refuses with the reason, and
    ``--all`` leaves it out."""
    run = tmp_path / "run"
    cases, engines = [sphere(0.0, 2.0, id="s0")], [fakes.OffByOne()]
    options = RunOptions(quick=True, isolate=False)
    launch(ResultsStore(run), cases, engines, options,
           new_info(run, "test", options, engines, cases))
    assert breaking_pairs(RunRows(read_run(run))) == [("s0", "fake-off")]
    assert main(["repro", str(run), "s0", "--engine", "fake-off"]) == 2
    said = " ".join(capsys.readouterr().err.split())
    assert "engine 'fake-off' makes no calls of a module" in said and "calls.py" in said
    assert main(["repro", str(run), "--all"]) == 0
    assert "0 script(s) written" in " ".join(capsys.readouterr().out.split())
    assert not (run / REPRO_DIR).exists()


@pytest.mark.parametrize(("argv", "said"), [
    (["CASE", "--all"], "it takes no CASE_ID 'CASE'"),
    (["--all", "--engine", "box2d"], "it takes no --engine"),
    (["--all", "--issue"], "it takes no --issue"),
    ([], "give a CASE_ID of the run, or --all"),
])
def test_all_takes_no_case_and_a_case_is_needed_without_it(
        argv: list[str], said: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """Refused before the run folder is read (exit 2, a message naming what to drop)."""
    assert main(["repro", str(tmp_path / "no-such-run"), *argv]) == 2
    assert said in " ".join(capsys.readouterr().err.split())
    assert list(tmp_path.iterdir()) == []


def test_help_says_where_scripts_go(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["repro", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "printed one after another" in text and "--issue" in text and "--out" in text
