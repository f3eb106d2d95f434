"""The pytest plugin: ``pytest --crosscheck-engine NAME`` in a project of its own.

The test plug-in distribution (tests/data/plugin_engine, ``numpy-spheres``) is pip-installed
into a folder of its own (the fixture of tests/adapters/test_plugins.py) and pytest runs in
a subprocess that sees it; fakes of :mod:`crosscheck.testing.fakes` that break in known ways
are declared as plug-ins by bare ``.dist-info`` folders.  Every outcome is asserted on cases
designed here: two spheres at a gap of 0.5 and two discs overlapping by 0.25, whose exact
answers numpy's agree with, and two boxes, a kind the plug-in does not do (skipped).
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import pytest

from crosscheck.core.model import Kind, quantities_of
from crosscheck.results.baseline import Baseline, Entry, write_baseline
from crosscheck.results.run import read_results
from crosscheck.testing.conformance import CHECKS
from tests.conftest import ROOT

ENGINE = "numpy-spheres"
CASES = """
[[case]]
id = "spheres-apart"
description = "two spheres with a gap of 0.5"
kind = "sphere"
dim = 3
swap = false
a = { center = [0.0, 0.0, 0.0], radius = 0.5 }
b = { center = [1.5, 0.0, 0.0], radius = 0.5 }

[[case]]
id = "discs-overlap"
description = "two discs overlapping by 0.25"
kind = "sphere"
dim = 2
swap = false
a = { center = [0.0, 0.0], radius = 0.5 }
b = { center = [0.0, 0.75], radius = 0.5 }

[[case]]
id = "boxes-apart"
description = "two boxes, a kind the plug-in does not do"
kind = "aabb"
dim = 2
swap = false
a = { center = [0.0, 0.0], half = [0.5, 0.5] }
b = { center = [2.0, 0.0], half = [0.5, 0.5] }
"""
ANSWERED = {case: quantities_of(Kind.SPHERE) for case in ("spheres-apart", "discs-overlap")}
SKIPPED = {"boxes-apart": quantities_of(Kind.AABB)}
FAKES = {"fake-off": "crosscheck.testing.fakes:OffByOne",
         "fake-aborts": "crosscheck.testing.fakes:Aborts",
         "fake-missing": "crosscheck.testing.fakes:Unavailable"}


def ids(engine: str, cases: Mapping[str, tuple[str, ...]]) -> set[str]:
    """The node ids of the findings of ``cases`` (by case, its quantities) on ``engine``."""
    return {f"crosscheck/{engine}/{case}::{q}" for case, qs in cases.items() for q in qs}


def kit_ids(engine: str) -> set[str]:
    return {f"crosscheck/{engine}/conformance::{check}" for check in CHECKS}


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """A project of its own (its own rootdir) with the cases, and the fakes as plug-ins."""
    (tmp_path / "pytest.ini").write_text("[pytest]\n", encoding="utf-8")
    (tmp_path / "cases.toml").write_text(CASES, encoding="utf-8")
    info = tmp_path / "fakes" / "crosscheck_fakes-0.0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: crosscheck-fakes\n"
                                   "Version: 0.0.1\n", encoding="utf-8")
    lines = [f"{name} = {target}" for name, target in FAKES.items()]
    (info / "entry_points.txt").write_text("\n".join(["[crosscheck.adapters]", *lines, ""]),
                                           encoding="utf-8")
    return tmp_path


def pytest_in(site: Path, project: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """``pytest *args`` in ``project``, in a subprocess that sees the plug-in and the fakes."""
    paths = [str(site), str(project / "fakes"), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths), "COLUMNS": "200"}
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *args],
                          cwd=project, env=env, capture_output=True, text=True, timeout=600)


def suite(site: Path, project: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """The plugin on the designed cases, verbose, with JUnit XML in ``junit.xml``."""
    return pytest_in(site, project, "--crosscheck-cases", "cases.toml", "-v",
                     "--junitxml", "junit.xml", *args)


def junit(project: Path) -> dict[str, tuple[str, str]]:
    """Each JUnit testcase's node id (its classname's dots back to slashes: no case id here
    has a dot) -> its outcome (passed, failure, skipped) and that element's text (a skip's
    message)."""
    found = {}
    for case in ET.parse(project / "junit.xml").getroot().iter("testcase"):
        nodeid = f"{case.get('classname', '').replace('.', '/')}::{case.get('name')}"
        outcome = [e for e in case if e.tag in ("failure", "skipped", "error")]
        assert nodeid not in found and len(outcome) <= 1
        text = (outcome[0].get("message") if outcome and outcome[0].tag == "skipped"
                else outcome[0].text if outcome else "")
        found[nodeid] = (outcome[0].tag if outcome else "passed", text or "")
    return found


def with_outcome(results: dict[str, tuple[str, str]], outcome: str) -> set[str]:
    return {nodeid for nodeid, (got, _) in results.items() if got == outcome}


def run_folder(stdout: str) -> Path:
    found = re.search(r"^run folder: (.+)$", stdout, flags=re.MULTILINE)
    assert found, stdout
    return Path(found.group(1))


def test_the_suite_and_the_kit_are_items_of_an_installed_plugin(site: Path,
                                                                 project: Path) -> None:
    ran = suite(site, project, "--crosscheck-engine", ENGINE)
    assert ran.returncode == 0, ran.stdout + ran.stderr
    results = junit(project)
    assert with_outcome(results, "passed") == kit_ids(ENGINE) | ids(ENGINE, ANSWERED)
    assert with_outcome(results, "skipped") == ids(ENGINE, SKIPPED)
    for nodeid in ids(ENGINE, SKIPPED):  # the row's reason
        assert "numpy-spheres does not support aabb in 2-D" in results[nodeid][1]
    shown = re.findall(r"^(crosscheck/\S+) (PASSED|SKIPPED)", ran.stdout, flags=re.MULTILINE)
    assert {nodeid for nodeid, _ in shown} == set(results)  # -v names the items by node id
    assert f"{len(results) - 3} passed, 3 skipped" in ran.stdout
    folder = run_folder(ran.stdout)  # kept, for crosscheck report
    assert f"crosscheck report {folder}" in ran.stdout
    rows = read_results(folder)
    assert len(rows) == len(ids(ENGINE, ANSWERED | SKIPPED))
    assert set(rows["engine"]) == {ENGINE}


def baseline(project: Path, engine: str, *changed: Entry) -> Path:
    """A baseline of the designed cases' expected outcome on ``engine`` (every sphere row
    agrees; every box row is skipped by the plug-in, agrees on the textbook formula), with
    ``changed`` entries in place of theirs."""
    boxes = "skip" if engine == ENGINE else "agree"
    entries = {(case, engine, q): Entry(case, engine, q, "agree", "", 0.0)
               for case, qs in ANSWERED.items() for q in qs}
    entries |= {(case, engine, q): Entry(case, engine, q, boxes, "", float("nan"))
                for case, qs in SKIPPED.items() for q in qs}
    for entry in changed:
        assert entry.key in entries
        entries[entry.key] = entry
    path = project / "baseline.jsonl"
    write_baseline(Baseline(entries, 0.5, 2.0, "designed"), path)
    return path


def test_a_regression_against_the_baseline_fails_its_item_alone_also_in_junit(
        site: Path, project: Path) -> None:
    answered = Entry("boxes-apart", ENGINE, "hit", "agree", "", 0.0)  # the plug-in skips it
    baseline(project, ENGINE, answered)
    ran = suite(site, project, "--crosscheck-engine", ENGINE,
                "--crosscheck-baseline", "baseline.jsonl")
    assert ran.returncode == 1, ran.stdout + ran.stderr
    results = junit(project)  # one testcase per item
    assert set(results) == kit_ids(ENGINE) | ids(ENGINE, ANSWERED | SKIPPED)
    failed = f"crosscheck/{ENGINE}/boxes-apart::hit"
    assert with_outcome(results, "failure") == {failed}
    assert with_outcome(results, "passed") == set(results) - {failed}
    text = results[failed][1]
    folder = run_folder(ran.stdout)
    assert text.startswith("REGRESSION: no longer answered: skip")
    assert "expected (baseline " in text and "baseline.jsonl): agree, error 0" in text
    assert "got (this run): skip" in text
    assert (f"reproduce: crosscheck run {project / 'cases.toml'} --engine {ENGINE} (case "
            "boxes-apart; no repro script: crosscheck repro writes one where the engine makes "
            "the case as calls of its module)") in text  # a skip: no call made
    assert folder.is_dir()
    assert text in ran.stdout and "Traceback" not in ran.stdout  # its text, no traceback


def test_a_stale_entry_of_a_built_in_fails_saying_so_with_a_repro_command_that_works(
        site: Path, project: Path) -> None:
    worse = Entry("spheres-apart", "reference", "distance", "disagree", "tolerance", 1e-3)
    baseline(project, "reference", worse)
    ran = suite(site, project, "--crosscheck-engine", "reference",
                "--crosscheck-baseline", "baseline.jsonl")
    assert ran.returncode == 1, ran.stdout + ran.stderr
    results = junit(project)
    failed = "crosscheck/reference/spheres-apart::distance"
    assert with_outcome(results, "failure") == {failed}
    assert with_outcome(results, "passed") == set(results) - {failed}
    text = results[failed][1]
    assert text.startswith("STALE: better than the baseline: agree") and "update it" in text
    assert "disagree (tolerance), error 0.001" in text
    command = f"crosscheck repro {run_folder(ran.stdout)} spheres-apart --engine reference"
    assert f"reproduce: {command}\n" in f"{text}\n"
    script = subprocess.run([sys.executable, "-m", "crosscheck.cli", *command.split()[1:]],
                            cwd=project, capture_output=True, text=True, timeout=120)
    assert script.returncode == 0, script.stderr
    assert "Reproduce crosscheck case spheres-apart on engine reference" in script.stdout


def test_a_crash_costs_rows_and_kit_items_never_the_session(site: Path, project: Path) -> None:
    ran = suite(site, project, "--crosscheck-engine", "fake-aborts",
                "--crosscheck-engine", "fake-off")
    assert ran.returncode == 1, ran.stdout + ran.stderr
    results = junit(project)
    every = ids("fake-off", ANSWERED | SKIPPED) | ids("fake-aborts", ANSWERED | SKIPPED)
    assert set(results) == kit_ids("fake-off") | kit_ids("fake-aborts") | every
    for nodeid in ids("fake-aborts", ANSWERED | SKIPPED):  # no baseline: a crash fails
        assert results[nodeid][0] == "failure"
        assert "got (this run): crash" in results[nodeid][1]
    for nodeid in kit_ids("fake-aborts"):  # the kit asked in a process of its own
        assert results[nodeid][0] == "failure"
        assert "the kit's process died: worker killed by SIGABRT" in results[nodeid][1]
    off = {case: ("distance",) for case in ANSWERED | SKIPPED}  # OffByOne: distance + 1
    assert {n for n in with_outcome(results, "failure") if "/fake-off/" in n} == ids(
        "fake-off", off) | {f"crosscheck/fake-off/conformance::{c}"
                            for c in ("conventions", "query", "overlap")}
    overlap = results["crosscheck/fake-off/conformance::overlap"][1]
    assert "overlap on sphere 3-D" in overlap and "expected a negative float distance" in overlap
    assert "REGRESSION: no baseline: every disagreement fails; disagree (error)" in results[
        "crosscheck/fake-off/spheres-apart::distance"][1]


def test_items_are_selected_by_keyword_and_marker(site: Path, project: Path) -> None:
    ran = pytest_in(site, project, "--crosscheck-engine", ENGINE, "--crosscheck-cases",
                    "cases.toml", "--collect-only", "-q", "-m", "crosscheck",
                    "-k", "distance and not boxes")
    assert ran.returncode == 0, ran.stdout + ran.stderr
    listed = set(re.findall(r"^crosscheck/\S+", ran.stdout, flags=re.MULTILINE))
    assert listed == ids(ENGINE, {case: ("distance",) for case in ANSWERED})


@pytest.mark.parametrize(("args", "said"), [
    (["--crosscheck-engine", "nosuch"],
     ["--crosscheck-engine nosuch: unknown engine 'nosuch'; known: reference"]),
    (["--crosscheck-engine", "fake-missing"],
     ["--crosscheck-engine fake-missing: plug-in engine 'fake-missing' from distribution "
      "crosscheck-fakes 0.0.1 (crosscheck.testing.fakes:Unavailable) is refused:"]),
    (["--crosscheck-engine", ENGINE, "--crosscheck-cases", "nothere.toml"],
     ["--crosscheck-cases: no such case file or folder:", "nothere.toml"]),
    (["--crosscheck-engine", ENGINE, "--crosscheck-cases", "bad.toml"],
     ["--crosscheck-cases: 2 error(s) in the case files; nothing was run:",
      "bad.toml:1: case 'half': field description: missing",
      "bad.toml:1: case 'half': field b: missing"]),
    (["--crosscheck-engine", ENGINE, "--crosscheck-cases", "cases.toml",
      "--crosscheck-baseline", "cases.toml"],
     ["--crosscheck-baseline: ", "cases.toml, line 2: not a JSON line"]),
])
def test_a_bad_option_is_a_usage_error_before_any_work(
        site: Path, project: Path, args: list[str], said: list[str]) -> None:
    (project / "bad.toml").write_text(
        '[[case]]\nid = "half"\nkind = "sphere"\ndim = 2\n'
        'a = { center = [0.0, 0.0], radius = 0.5 }\n', encoding="utf-8")
    ran = pytest_in(site, project, *args, "--crosscheck-out", "out")
    assert ran.returncode == 4, ran.stdout + ran.stderr
    for words in said:
        assert words in ran.stderr, ran.stderr
    assert "Traceback" not in ran.stderr and not (project / "out").exists()


def test_without_its_options_the_plugin_adds_nothing(site: Path, project: Path,
                                                     pytestconfig: pytest.Config) -> None:
    (project / "test_own.py").write_text("def test_own() -> None:\n    pass\n",
                                         encoding="utf-8")
    ran = pytest_in(site, project, "-v")
    assert ran.returncode == 0, ran.stdout + ran.stderr
    assert "collected 1 item" in ran.stdout and "crosscheck/" not in ran.stdout
    assert "= crosscheck =" not in ran.stdout
    imported = subprocess.run(
        [sys.executable, "-c", "import sys, crosscheck.pytest_plugin; print(sorted(m for m in "
         "('pandas', 'numpy', 'pydantic', 'adapters', 'crosscheck.pytest_plugin.suite') "
         "if m in sys.modules))"], capture_output=True, text=True, check=True, timeout=60)
    assert imported.stdout.strip() == "[]"
    manager = pytestconfig.pluginmanager  # this session: loaded by its entry point, inert
    assert manager.has_plugin("crosscheck") and not manager.has_plugin("crosscheck-suite")


def test_the_plugin_has_an_item_for_every_check_of_the_kit() -> None:
    named = set()
    for module in ("conformance", "answers"):
        source = (ROOT / "crosscheck" / "testing" / f"{module}.py").read_text(encoding="utf-8")
        for node in ast.walk(ast.parse(source)):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ("fail", "guarded") and node.args
                    and isinstance(node.args[0], ast.Constant)):
                named.add(node.args[0].value)
    assert named == set(CHECKS) and len(CHECKS) == len(named)


def test_the_docs_page_names_every_option_and_every_check() -> None:
    page = (ROOT / "docs" / "pytest-plugin.md").read_text(encoding="utf-8")
    source = (ROOT / "crosscheck" / "pytest_plugin" / "__init__.py").read_text(encoding="utf-8")
    options = set(re.findall(r'addoption\("(--crosscheck-[a-z-]+)"', source))
    assert len(options) == 5
    assert {o for o in options if f"| `{o}" in page} == options  # a row of the options table
    listed = re.search(r"conformance kit \(((?:`\w+`,?\s*)+)", page)
    assert listed and re.findall(r"`(\w+)`", listed.group(1)) == list(CHECKS)
