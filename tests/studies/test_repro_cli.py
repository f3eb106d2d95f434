"""``crosscheck repro``: stdout unless --out, every disagreeing engine, and issue-ready reports.

Reads the small real run of ``tests/studies/conftest.py``.  What a report must hold comes
from the stored run itself (run.json's engine, version and machine, results.csv's rows, the
case's source file), never from an engine's known answer.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from crosscheck.cli import main
from crosscheck.core.schema import SceneCase
from crosscheck.results.store import REPRO_DIR, read_run, repro_name
from crosscheck.studies.repro.script import RunRows, breaking_pairs, scripts
from tests.conftest import ROOT

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


def test_crosscheck_run_writes_the_scripts_beside_its_report(tmp_path: Path) -> None:
    out = tmp_path / "run"
    cases = ROOT / "cases" / "float_traps.toml"
    assert main(["run", str(cases), "--quick", "--engine", "box2d", "--engine", "rapier",
                 "--out", str(out)]) == 0
    runs = RunRows(read_run(out))
    pairs = breaking_pairs(runs)
    assert {e for _, e in pairs} == {"box2d", "rapier"}
    assert {p.name for p in (out / REPRO_DIR).glob("*.py")} == {
        f"{repro_name(*pair)}.py" for pair in pairs}
    assert f'href="{REPRO_DIR}/{repro_name(*pairs[0])}.py"' in (
        out / "report.html").read_text(encoding="utf-8")


def test_help_says_where_scripts_go(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["repro", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "printed one after another" in text and "--issue" in text and "--out" in text
