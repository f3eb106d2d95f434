"""Repro scripts: standalone, and bit for bit what the run recorded, on every engine variant.

One real run (every variant, a chosen slice of suite cases and a scene, ``--quick``:
``tests/studies/conftest.py``) is made once; case x engine pairs with a non-agree row get
their script, which runs in a fresh Python process in an empty folder.  Its ``<quantity> =
<text>`` lines must equal the run's ``value`` column, string for string (a scene's measures
the script does not compute, ``divergence`` and open space's, must be named in a comment).
A pair the run recorded as an error must raise the recorded exception, a crash must die by
the recorded signal, a declared hang must hang after printing the quantities that answered.
Nothing here knows an engine's answer: the run is the oracle.
"""

from __future__ import annotations

import ast
import signal
import subprocess
import sys
from collections import Counter
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest

import adapters
from crosscheck.core.model import Status
from crosscheck.core.schema import SceneCase
from crosscheck.results.run import read_run
from crosscheck.results.store import REPRO_DIR, repro_name
from crosscheck.studies.repro.script import (
    ReproError,
    RunRows,
    breaking_pairs,
    build,
    engine_part,
    literal,
    printed,
    scripts,
    write_run_scripts,
)
from crosscheck.truth.scene_measures import surrounded

pytestmark = pytest.mark.engine

SCRIPT_TIMEOUT_S = 120.0
"""Generous: a script that answers takes about a second (a scene a few)."""
HANG_TIMEOUT_S = 2.0
"""A script the run recorded as hanging is stopped after this long (the run probed 0.25 s)."""


@dataclass(frozen=True)
class Ran:
    """A script's run: exit code (None: it hung and was stopped), stdout, stderr."""

    code: int | None
    out: str
    err: str


def run_script(path: Path, cwd: Path, timeout: float) -> Ran:
    try:
        done = subprocess.run([sys.executable, str(path)], cwd=cwd, capture_output=True,
                              text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired as exc:
        return Ran(None, _text(exc.stdout), _text(exc.stderr))
    return Ran(done.returncode, done.stdout, done.stderr)


def _text(data: bytes | str | None) -> str:
    return data.decode() if isinstance(data, bytes) else data or ""


def answers(out: str, quantities: set[str]) -> dict[str, str]:
    """The script's ``<quantity> = <text>`` lines (other lines are comments or the engine's)."""
    found = {}
    for line in out.splitlines():
        key, sep, text = line.partition(" = ")
        if sep and key in quantities:
            assert key not in found, f"{key} printed twice"
            found[key] = text
    return found


def check_pair(rows: list[dict[str, object]], ran: Ran, shown: tuple[str, ...]) -> int:
    """Assert the script behaved as the run recorded; the non-agree rows it prints (``shown``:
    ``script.printed``) compared bit for bit, the others named in a comment line."""
    statuses = {Status(str(r["status"])) for r in rows}
    reason = next((str(r["reason"]) for r in rows if Status(str(r["status"])).failed), "")
    if Status.CRASH in statuses:
        assert ran.code is not None and ran.code < 0, ran
        assert signal.Signals(-ran.code).name in reason
        return 0
    if Status.ERROR in statuses:
        assert ran.code not in (None, 0), ran
        assert reason.rsplit(" (at ", 1)[0] in ran.err, (reason, ran.err[-300:])
        return 0
    if Status.TIMEOUT in statuses:
        assert ran.code is None, f"the run recorded a hang, the script ended: {ran}"
    else:
        assert ran.code == 0, ran.err[-2000:]
    compared = [r for r in rows if r["quantity"] in shown]
    want = {str(r["quantity"]): str(r["value"]) for r in compared}  # a hung quantity's is null
    assert answers(ran.out, {str(r["quantity"]) for r in rows}) == want
    comments = [line for line in ran.out.splitlines() if line.startswith("# ")]
    for r in rows:
        if r["quantity"] not in shown:  # a scene's measure the script does not compute
            assert any(str(r["quantity"]) in line for line in comments), r["quantity"]
    return sum(Status(str(r["status"])) not in (Status.AGREE, Status.TIMEOUT) for r in compared)


def non_agree_pairs(runs: RunRows) -> Iterator[tuple[str, str]]:
    for pair, rows in runs.pairs.items():
        if any(Status(str(r["status"])) not in (Status.AGREE, Status.SKIP) for r in rows):
            yield pair


def one_per_engine_and_kind(runs: RunRows, pairs: list[tuple[str, str]]
                            ) -> list[tuple[str, str]]:
    """Of ``pairs``, the first answered one of each engine x kind (scenes in open space and
    with gravity or walls apart), and the first of each engine that crashed, raised or hung:
    each way a script can end, on every variant."""
    seen: set[tuple[str, str]] = set()
    chosen = []
    for case_id, engine in pairs:
        rows = runs.rows(case_id, engine)
        ended = {str(r["status"]) for r in rows} & {"crash", "error", "timeout"}
        case = runs.stored.cases[case_id]
        kind = str(rows[0]["kind"]) + (
            " surrounded" if isinstance(case, SceneCase) and surrounded(case) else "")
        group = (engine, min(ended) if ended else kind)
        if group not in seen:
            chosen.append((case_id, engine))
            seen.add(group)
    return chosen


def run_all(runs: RunRows, pairs: list[tuple[str, str]], folder: Path) -> list[Ran]:
    """Write the pairs' scripts into ``folder`` and run each in a fresh process (4 at once)."""
    paths = []
    for case_id, engine in pairs:
        made = build(runs, case_id, engine)
        path = folder / f"{made.name}.py"
        path.write_text(made.text, encoding="utf-8")
        paths.append(path)
    work = folder / "cwd"
    work.mkdir()

    def execute(index: int) -> Ran:
        rows = runs.rows(*pairs[index])
        hangs = any(r["status"] == Status.TIMEOUT for r in rows)
        return run_script(paths[index], work, HANG_TIMEOUT_S if hangs else SCRIPT_TIMEOUT_S)

    with ThreadPoolExecutor(max_workers=4) as pool:
        return list(pool.map(execute, range(len(pairs))))


@pytest.mark.parametrize(("which", "at_least"), [
    pytest.param("one per engine and kind", 0, id="one-per-engine-and-kind"),
    pytest.param("every", 100, id="every-pair", marks=pytest.mark.slow),
])
def test_scripts_reproduce_the_run_bit_for_bit(repro_run: Path, tmp_path: Path, which: str,
                                               at_least: int) -> None:
    runs = RunRows(read_run(repro_run))
    pairs = list(non_agree_pairs(runs))
    if which != "every":
        pairs = one_per_engine_and_kind(runs, pairs)
    results = run_all(runs, pairs, tmp_path)
    compared: Counter[tuple[str, str]] = Counter()
    failures: Counter[str] = Counter()
    for (case_id, engine), ran in zip(pairs, results, strict=True):
        rows = runs.rows(case_id, engine)
        failures.update(str(r["status"]) for r in rows if Status(str(r["status"])).failed)
        shown = printed(runs.stored.cases[case_id])
        compared[engine, str(rows[0]["kind"])] += check_pair(rows, ran, shown)
    groups = {(e, str(rows[0]["kind"])) for (_, e), rows in runs.pairs.items()
              if any(r["status"] != "skip" for r in rows)}
    disagreeing = {(e, str(runs.rows(c, e)[0]["kind"])) for c, e in non_agree_pairs(runs)}
    assert disagreeing == groups  # the slice makes every variant disagree on every kind it runs
    for engine, kind in sorted(groups):
        assert compared[engine, kind] >= 1, f"no non-agree {kind} row of {engine} compared"
    assert sum(compared.values()) >= at_least, compared
    assert {"crash", "error", "timeout"} <= set(failures), failures


def test_every_variant_and_kind_has_a_script(repro_run: Path) -> None:
    runs = RunRows(read_run(repro_run))
    for case_id, engine in runs.pairs:
        if any(r["status"] != "skip" for r in runs.rows(case_id, engine)):
            assert engine_part(adapters.get(engine), runs.stored.cases[case_id]).code, engine
    kinds = {(e, str(rows[0]["kind"])) for (c, e), rows in runs.pairs.items()
             if any(r["status"] != "skip" for r in rows)}
    assert {k for _, k in kinds} == {"aabb", "sphere", "sphere_response", "sphere_scene"}
    for case_id, engine in runs.pairs:
        if any(r["status"] != "skip" for r in runs.rows(case_id, engine)):
            assert build(runs, case_id, engine).text.startswith("#!/usr/bin/env python3")


def test_a_bad_input_script_is_valid_python_with_exact_literals(repro_run: Path) -> None:
    stored = read_run(repro_run)
    for engine in adapters.names():
        rows = RunRows(stored).rows("bad-sphere-2d-nan-centre", engine)
        if not rows or all(r["status"] == "skip" for r in rows):
            continue
        made = scripts(stored, "bad-sphere-2d-nan-centre", engine)[0]
        tree = ast.parse(made.text)
        imported = {alias.name.split(".")[0] for node in ast.walk(tree)
                    if isinstance(node, ast.Import) for alias in node.names}
        imported |= {str(node.module).split(".")[0] for node in ast.walk(tree)
                     if isinstance(node, ast.ImportFrom)}
        assert "crosscheck" not in imported and "adapters" not in imported, engine
        assert 'float("nan")' in made.text and "float.fromhex(" in made.text
    assert float.fromhex(literal(0.1)[len('float.fromhex("'):-2]) == 0.1
    assert literal(float("-inf")) == '-float("inf")'


@pytest.mark.parametrize(("case_id", "engine", "recorded"), [
    pytest.param("bad-sphere-2d-nan-centre", "rapier", "error", id="raising-guard"),
    pytest.param("bad-sphere-2d-nan-centre", "coal", "undefined", id="undefined-guard"),
])
def test_a_guard_can_be_lifted_to_see_the_engines_own_answer(
        repro_run: Path, tmp_path: Path, case_id: str, engine: str, recorded: str) -> None:
    runs = RunRows(read_run(repro_run))
    rows = runs.rows(case_id, engine)
    assert {str(r["status"]) for r in rows} == {recorded}
    text = build(runs, case_id, engine).text
    assert text.count("ASK_ANYWAY = False") == 1
    path = tmp_path / "lifted.py"
    path.write_text(text.replace("ASK_ANYWAY = False", "ASK_ANYWAY = True"), encoding="utf-8")
    ran = run_script(path, tmp_path, SCRIPT_TIMEOUT_S)
    assert ran.code == 0, ran.err[-1000:]
    got = answers(ran.out, {"hit", "distance", "normal"})
    assert set(got) == {"hit", "distance", "normal"} and got["hit"] in ("true", "false")


def test_the_script_prints_truth_bound_verdict_textbook_and_conventions(
        repro_run: Path, tmp_path: Path) -> None:
    stored = read_run(repro_run)
    runs = RunRows(stored)
    for case_id, engine in (("sphere-2d-trap-12-35-37", "fcl"),
                            ("sphere-3d-scale-1e-3-touch-122", "rapier-default"),
                            ("resp-2d-oblique-345-mass-2-1", "mujoco")):
        path = tmp_path / f"{repro_name(case_id, engine)}.py"
        path.write_text(scripts(stored, case_id, engine)[0].text, encoding="utf-8")
        lines = run_script(path, tmp_path, SCRIPT_TIMEOUT_S).out.splitlines()
        for row in runs.rows(case_id, engine):
            quantity = row["quantity"]
            assert f"expected {quantity} = {row['truth']}" in lines
            verdict = next(line for line in lines if line.startswith(f"# {quantity}: "))
            assert verdict.startswith(f"# {quantity}: {row['status']}")
            if row["status"] == "disagree":
                assert f"/{row['category']}: " in verdict and str(row["reason"]) in verdict
                assert "x the float64 bound" in verdict or "the float64 bound" in verdict
        textbook = {str(r["quantity"]): str(r["value"]) for r in runs.rows(case_id, "reference")}
        for quantity, value in textbook.items():
            assert f"textbook {quantity} = {value}" in lines
        assert any(line.startswith(f"# conventions consulted ({engine}, declared in run.json): ")
                   for line in lines)


def test_engines_without_a_script_are_refused(repro_run: Path) -> None:
    stored = read_run(repro_run)
    with pytest.raises(ReproError, match="did not run"):
        scripts(stored, "aabb-3d-corner-touch-mixed-signs", "pymunk")  # 2-D engine, 3-D case
    with pytest.raises(ReproError, match="did not run"):
        scripts(stored, "scene-2d-head-on.dt=0.1", "coal")  # no scenes
    with pytest.raises(ReproError, match="no case"):
        scripts(stored, "no-such-case")
    defaults = [s.engine for s in scripts(stored, "resp-2d-separating-head-on")]
    assert "fcl" not in defaults and "pymunk" in defaults


def test_repro_names_are_safe_and_distinct() -> None:
    ids = ["a=1", "a,1", "a+1", "a_1", "a~3d1", "sweep.gap=1e-05,offset=1e+15.swapped",
           "x" * 300, "x" * 299 + "y"]
    engines = adapters.names()
    names = {repro_name(case_id, engine) for case_id in ids for engine in engines}
    assert len(names) == len(ids) * len(engines)
    for name in names:
        assert len(name) <= 200 and set(name) <= set("abcdefghijklmnopqrstuvwxyz0123456789.-_~")


def test_the_report_links_each_written_script(repro_run: Path, tmp_path: Path) -> None:
    from crosscheck.report.render import render

    run = tmp_path / "run"
    subprocess.run(["cp", "-r", str(repro_run), str(run)], check=True)
    written = write_run_scripts(run)
    runs = RunRows(read_run(run))
    pairs = breaking_pairs(runs)
    assert sorted(p.name for p in written) == sorted(f"{repro_name(*p)}.py" for p in pairs)
    assert {e for _, e in pairs} <= {p.name.rsplit("_", 1)[1][:-3] for p in written}
    assert any(runs.stored.cases[c].kind == "sphere_scene" for c, _ in pairs)
    html = render(run)["report"].read_text(encoding="utf-8")
    names = [repro_name("resp-2d-separating-head-on", "pymunk"),
             repro_name("scene-2d-head-on.dt=0.1", "pybullet")]
    assert all(f'href="{REPRO_DIR}/{name}.py"' in html for name in names)
    for name in names:
        (run / REPRO_DIR / f"{name}.py").unlink()
    html = render(run)["report"].read_text(encoding="utf-8")
    assert not any(f'href="{REPRO_DIR}/{name}.py"' in html for name in names)


def test_a_verdict_line_says_when_the_repeat_check_got_another_answer() -> None:
    from crosscheck.studies.repro.verdicts import verdict_line

    row = {"quantity": "distance", "status": "disagree", "category": "error", "error": 2.0,
           "tolerance": 0.5, "reason": "off", "kind": "sphere", "nondeterministic": False,
           "repeat_value": None, "repeat_status": ""}
    plain = "# distance: disagree/error: error 2 = 4 x the float64 bound 0.5: off"
    assert verdict_line(row) == plain
    again = verdict_line(row | {"nondeterministic": True, "repeat_value": "-1.5",
                                "repeat_status": "disagree"})
    assert again.endswith(": not reproducible: asked again in a fresh worker, the engine "
                          "answered -1.5 (disagree)")
