"""Repro scripts: standalone, and bit for bit what the run recorded.

One real run (every engine, a chosen handful of suite cases, ``--quick``) is made once;
every case x engine with a non-agree row gets its script, which runs in a fresh Python
process in an empty folder.  Its ``<quantity> = <text>`` lines must equal the run's
``value`` column, string for string.  A pair the run recorded as an error must raise the
recorded exception, a crash must die by the recorded signal, a declared hang must hang
after printing the quantities that answered.  Nothing here knows an engine's answer: the
run is the oracle.
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
from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.report.render import render
from crosscheck.results.store import REPRO_DIR, ResultsStore, read_run, repro_name
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.repro.script import (
    ReproError,
    RunRows,
    breaking_pairs,
    build,
    literal,
    scripts,
    write_run_scripts,
)
from tests.conftest import ROOT

pytestmark = pytest.mark.engine

ENGINES = ("fcl", "pybullet", "pybullet-default", "pymunk", "pymunk-default", "reference",
           "reference-f32")
FILES = ("aabb", "touching", "float_traps", "scale", "sphere", "degenerate", "response",
         "impacts", "bad_input", "mass_ratio")
CASES = (
    # boxes: corner touches (margins, touching rules, undefined normals), crossed boxes
    "aabb-2d-corner-touch-unequal", "aabb-3d-corner-touch-mixed-signs",
    "aabb-2d-coincident-cross",
    # spheres: a float trap, a small diagonal touch, coincident centres (FCL's known hang)
    "sphere-2d-trap-12-35-37", "sphere-3d-scale-1e-3-touch-122", "sphere-3d-coincident",
    # responses: separating bodies, oblique impacts, default settings, coincident centres
    "resp-2d-separating-head-on", "resp-2d-oblique-345-mass-2-1", "resp-3d-oblique-345",
    "resp-2d-coincident-centres", "resp-2d-slow-0.19",
    # bad input: NaN literals, a segfault, an abort, engines that raise
    "bad-sphere-2d-nan-centre", "bad-sphere-2d-nan-radius", "bad-resp-2d-negative-mass",
    "bad-resp-2d-zero-mass-a",
)
SCRIPT_TIMEOUT_S = 60.0
"""Generous: a script that answers takes well under a second."""
HANG_TIMEOUT_S = 2.0
"""A script the run recorded as hanging is stopped after this long (the run probed 0.25 s)."""


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    loaded = load_paths([ROOT / "cases" / f"{name}.toml" for name in FILES])
    chosen = [case for case in loaded.cases if case.id in CASES]
    assert sorted(case.id for case in chosen) == sorted(CASES)
    engines = [adapters.get(name) for name in ENGINES]
    directory = tmp_path_factory.mktemp("repro") / "run"
    options = RunOptions(quick=True, jobs=2)
    launch(ResultsStore(directory), chosen, engines, options,
           new_info(directory, "test_repro", options, engines, chosen))
    return directory


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


def check_pair(rows: list[dict[str, object]], ran: Ran) -> int:
    """Assert the script behaved as the run recorded; the non-agree rows compared bit for bit."""
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
    want = {str(r["quantity"]): str(r["value"]) for r in rows}  # a hung quantity's is ''
    assert answers(ran.out, {str(r["quantity"]) for r in rows}) == want
    return sum(Status(str(r["status"])) not in (Status.AGREE, Status.TIMEOUT) for r in rows)


def non_agree_pairs(runs: RunRows) -> Iterator[tuple[str, str]]:
    for pair, rows in runs.pairs.items():
        if any(Status(str(r["status"])) not in (Status.AGREE, Status.SKIP) for r in rows):
            yield pair


def one_per_engine_and_kind(runs: RunRows, pairs: list[tuple[str, str]]
                            ) -> list[tuple[str, str]]:
    """Of ``pairs``, the first answered one of each engine x kind, and every one that crashed,
    raised or hung: each way a script can end, on every engine and kind."""
    seen: set[tuple[str, str]] = set()
    chosen = []
    for case_id, engine in pairs:
        rows = runs.rows(case_id, engine)
        ended = {str(r["status"]) for r in rows} & {"crash", "error", "timeout"}
        group = (engine, str(rows[0]["kind"]))
        if ended:
            chosen.append((case_id, engine))
        elif group not in seen:
            chosen.append((case_id, engine))
            seen.add(group)
    return chosen


@pytest.mark.parametrize(("which", "at_least"), [
    pytest.param("one per engine and kind", 0, id="one-per-engine-and-kind"),
    pytest.param("every", 30, id="every-pair", marks=pytest.mark.slow),
])
def test_scripts_reproduce_the_run_bit_for_bit(run_dir: Path, tmp_path: Path, which: str,
                                               at_least: int) -> None:
    runs = RunRows(read_run(run_dir))
    pairs = list(non_agree_pairs(runs))
    if which != "every":
        pairs = one_per_engine_and_kind(runs, pairs)
    paths = []
    for case_id, engine in pairs:
        made = build(runs, case_id, engine)
        path = tmp_path / f"{made.name}.py"
        path.write_text(made.text, encoding="utf-8")
        paths.append(path)
    work = tmp_path / "cwd"
    work.mkdir()

    def execute(index: int) -> Ran:
        rows = runs.rows(*pairs[index])
        hangs = any(r["status"] == Status.TIMEOUT for r in rows)
        return run_script(paths[index], work, HANG_TIMEOUT_S if hangs else SCRIPT_TIMEOUT_S)

    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(execute, range(len(pairs))))
    compared: Counter[tuple[str, str]] = Counter()
    failures: Counter[str] = Counter()
    for (case_id, engine), ran in zip(pairs, results, strict=True):
        rows = runs.rows(case_id, engine)
        failures.update(str(r["status"]) for r in rows if Status(str(r["status"])).failed)
        compared[engine, str(rows[0]["kind"])] += check_pair(rows, ran)
    for name in ENGINES:
        for kind in {str(k) for k, _ in adapters.get(name).capabilities} - {"sphere_scene"}:
            assert compared[name, kind] >= 1, f"no non-agree {kind} row of {name} compared"
    assert sum(compared.values()) >= at_least, compared
    assert {"crash", "error", "timeout"} <= set(failures), failures


def test_a_bad_input_script_is_valid_python_with_exact_literals(run_dir: Path) -> None:
    made = scripts(read_run(run_dir), "bad-sphere-2d-nan-centre", "reference")[0]
    tree = ast.parse(made.text)
    assert 'float("nan")' in made.text and "float.fromhex(" in made.text
    imported = {alias.name.split(".")[0] for node in ast.walk(tree)
                if isinstance(node, ast.Import) for alias in node.names}
    imported |= {str(node.module).split(".")[0] for node in ast.walk(tree)
                 if isinstance(node, ast.ImportFrom)}
    assert "crosscheck" not in imported and "adapters" not in imported
    assert float.fromhex(literal(0.1)[len('float.fromhex("'):-2]) == 0.1
    assert literal(float("-inf")) == '-float("inf")'


def test_the_script_prints_truth_textbook_and_convention(run_dir: Path, tmp_path: Path) -> None:
    stored = read_run(run_dir)
    made = scripts(stored, "sphere-2d-trap-12-35-37", "fcl")[0]
    path = tmp_path / "s.py"
    path.write_text(made.text, encoding="utf-8")
    ran = run_script(path, tmp_path, SCRIPT_TIMEOUT_S)
    rows = stored.results[(stored.results["case_id"] == "sphere-2d-trap-12-35-37")]
    for quantity in ("hit", "distance", "normal"):
        truth = rows[(rows["engine"] == "fcl") & (rows["quantity"] == quantity)]["truth"]
        textbook = rows[(rows["engine"] == "reference") & (rows["quantity"] == quantity)]
        assert f"expected {quantity} = {truth.iloc[0]}" in ran.out.splitlines()
        assert f"textbook {quantity} = {textbook['value'].iloc[0]}" in ran.out.splitlines()
    assert any(line.startswith("# convention (fcl): normal ") for line in ran.out.splitlines())


def test_engines_without_a_script_are_refused(run_dir: Path) -> None:
    stored = read_run(run_dir)
    with pytest.raises(ReproError, match="did not run"):
        scripts(stored, "aabb-3d-corner-touch-mixed-signs", "pymunk")  # 2-D engine, 3-D case
    with pytest.raises(ReproError, match="no case"):
        scripts(stored, "no-such-case")
    defaults = [s.engine for s in scripts(stored, "resp-2d-separating-head-on")]
    assert "fcl" not in defaults and "pymunk" in defaults


def test_repro_names_are_safe_and_distinct() -> None:
    ids = ["a=1", "a,1", "a+1", "a_1", "a~3d1", "sweep.gap=1e-05,offset=1e+15.swapped",
           "x" * 300, "x" * 299 + "y"]
    names = {repro_name(case_id, engine) for case_id in ids for engine in ENGINES}
    assert len(names) == len(ids) * len(ENGINES)
    for name in names:
        assert len(name) <= 200 and set(name) <= set("abcdefghijklmnopqrstuvwxyz0123456789.-_~")


def test_cli_writes_the_script_and_it_runs(run_dir: Path, tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    case_id = "aabb-2d-corner-touch-unequal"
    shadow = tmp_path / "fcl.py"  # python would import the script itself for `import fcl`
    assert main(["repro", str(run_dir), case_id, "--engine", "fcl", "--out", str(shadow)]) == 2
    target = tmp_path / "repro-fcl.py"
    assert main(["repro", str(run_dir), case_id, "--engine", "fcl", "--out", str(target)]) == 0
    ran = run_script(target, tmp_path, SCRIPT_TIMEOUT_S)
    rows = RunRows(read_run(run_dir)).rows(case_id, "fcl")
    assert answers(ran.out, {"hit", "distance", "normal"}) == {
        str(r["quantity"]): str(r["value"]) for r in rows}
    capsys.readouterr()
    assert main(["repro", str(run_dir), case_id, "--engine", "reference"]) == 0
    assert capsys.readouterr().out == scripts(read_run(run_dir), case_id, "reference")[0].text
    several = tmp_path / "many.py"
    assert main(["repro", str(run_dir), case_id, "--out", str(several)]) == 0
    written = sorted(p.name for p in tmp_path.glob("many-*.py"))
    assert "many-fcl.py" in written and len(written) >= 2
    assert main(["repro", str(run_dir), "no-such-case"]) == 2


def test_the_report_links_each_written_script(run_dir: Path) -> None:
    written = write_run_scripts(run_dir)
    runs = RunRows(read_run(run_dir))
    pairs = [p for p in breaking_pairs(runs) if runs.stored.cases[p[0]].kind != "sphere_scene"]
    assert sorted(p.name for p in written) == sorted(f"{repro_name(*p)}.py" for p in pairs)
    html = render(run_dir)["report"].read_text(encoding="utf-8")
    link = f'href="{REPRO_DIR}/{repro_name("resp-2d-separating-head-on", "pymunk")}.py"'
    assert link in html
    (run_dir / REPRO_DIR / f"{repro_name('resp-2d-separating-head-on', 'pymunk')}.py").unlink()
    assert link not in render(run_dir)["report"].read_text(encoding="utf-8")


def test_crosscheck_run_writes_the_scripts_beside_its_report(tmp_path: Path) -> None:
    out = tmp_path / "run"
    cases = ROOT / "cases" / "float_traps.toml"
    assert main(["run", str(cases), "--quick", "--engine", "reference-f32", "--out",
                 str(out)]) == 0
    runs = RunRows(read_run(out))
    pairs = breaking_pairs(runs)
    assert pairs
    assert {p.name for p in (out / REPRO_DIR).glob("*.py")} == {
        f"{repro_name(*pair)}.py" for pair in pairs}
    assert f'href="{REPRO_DIR}/{repro_name(*pairs[0])}.py"' in (
        out / "report.html").read_text(encoding="utf-8")
