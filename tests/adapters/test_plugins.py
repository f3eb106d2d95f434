"""Plug-in engines: the ``crosscheck.adapters`` entry-point group, beside the built-in table.

A real plug-in distribution (``tests/data/plugin_engine``) is pip-installed into a folder
of its own, never the shared venv, and driven through the CLI in subprocesses: it is
listed with its distribution, passes the kit, runs and is reported.  Broken plug-ins are
written as bare ``.dist-info`` folders: each is listed with its reason and refused by
name, and none replaces a built-in.  The plug-in docs/adding-an-engine.md shows is the tested one.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pandas as pd
import pytest

import adapters
from crosscheck.cli import engines as engine_choice
from crosscheck.cli import main
from tests.conftest import ROOT

PLUGIN = ROOT / "tests" / "data" / "plugin_engine"
PACKAGE = PLUGIN / "crosscheck_numpy_spheres"
MODULES = (PACKAGE / "__init__.py", PACKAGE / "calls.py")

CASES = """
[[case]]
id = "spheres-apart"
description = "two spheres with a gap of 0.5"
kind = "sphere"
dim = 3
a = { center = [0.0, 0.0, 0.0], radius = 0.5 }
b = { center = [1.5, 0.0, 0.0], radius = 0.5 }

[[case]]
id = "discs-overlap"
description = "two discs overlapping by 0.25"
kind = "sphere"
dim = 2
a = { center = [0.0, 0.0], radius = 0.5 }
b = { center = [0.0, 0.75], radius = 0.5 }

[[case]]
id = "discs-head-on"
description = "two discs closing head-on in open space, e = 1, for 0.5 s"
kind = "sphere_scene"
dim = 2
duration = 0.5
dt = 0.01
bodies = [{ center = [-1.0, 0.0], radius = 0.5, mass = 1.0, velocity = [1.0, 0.0] },
          { center = [1.0, 0.0], radius = 0.5, mass = 1.0, velocity = [-1.0, 0.0] }]

[[case]]
id = "ball-on-floor"
description = "a ball dropped on a floor: a scene with a wall, which the plug-in skips"
kind = "sphere_scene"
dim = 2
duration = 0.2
dt = 0.01
gravity = [0.0, -9.81]
walls = [{ normal = [0.0, 1.0], offset = 0.0 }]
bodies = [{ center = [0.0, 1.0], radius = 0.5, mass = 1.0, velocity = [0.0, 0.0] }]

[[case]]
id = "boxes-apart"
description = "two boxes, a kind the plug-in does not do"
kind = "aabb"
dim = 2
a = { center = [0.0, 0.0], half = [0.5, 0.5] }
b = { center = [2.0, 0.0], half = [0.5, 0.5] }
"""


# --- a real plug-in, installed and run -----------------------------------------------------

@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The test plug-in pip-installed into a folder of its own (on PYTHONPATH when used)."""
    base = tmp_path_factory.mktemp("plugin")
    source = base / "source"  # a copy: building never writes into the repository
    shutil.copytree(PLUGIN, source, ignore=shutil.ignore_patterns("__pycache__"))
    target = base / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation",
                    "--no-index", "--quiet", "--disable-pip-version-check",
                    "--target", str(target), str(source)],
                   check=True, capture_output=True, text=True, timeout=300)
    return target


def python(site: Path, *args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """``python *args`` in a subprocess that sees the plug-in installed in ``site``."""
    paths = [str(site), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths), "COLUMNS": "200"}
    return subprocess.run([sys.executable, *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=600)


def test_an_installed_plugin_is_discovered_run_and_reported(site: Path, tmp_path: Path) -> None:
    listed = python(site, "-m", "crosscheck.cli", "engines", cwd=tmp_path)
    assert listed.returncode == 0, listed.stderr
    row = next(line for line in listed.stdout.splitlines() if "│ numpy-spheres " in line)
    assert re.search(r"│ plug-in +│ [^│]+ │ yes +│ sphere 2-D/3-D,? +sphere_scene 2-D/3-D +│",
                     row), row
    assert ("plug-in engine 'numpy-spheres' from distribution crosscheck-numpy-spheres 0.1.0 "
            "(crosscheck_numpy_spheres:NumpySpheres)") in listed.stdout

    (tmp_path / "cases.toml").write_text(CASES, encoding="utf-8")
    out = tmp_path / "run"
    ran = python(site, "-m", "crosscheck.cli", "run", "cases.toml", "--quick", "--jobs", "1",
                 "--engine", "reference", "--engine", "numpy-spheres", "--out", str(out),
                 cwd=tmp_path)
    assert ran.returncode == 0, ran.stderr
    (out / "report.html").unlink()
    reported = python(site, "-m", "crosscheck.cli", "report", str(out), cwd=tmp_path)
    assert reported.returncode == 0, reported.stderr

    results = pd.read_csv(out / "results.csv")
    mine = results[results["engine"] == "numpy-spheres"]
    assert set(mine["case_id"]) == set(results["case_id"])  # every case, twins included
    spheres = mine[mine["kind"] == "sphere"]
    assert len(spheres) == 3 * 4 and spheres["status"].isin(["agree", "disagree"]).all()
    boxes = mine[mine["kind"] == "aabb"]
    assert set(boxes["status"]) == {"skip"}
    assert set(boxes["reason"]) == {"numpy-spheres does not support aabb in 2-D"}
    assert "numpy-spheres" in (out / "report.html").read_text(encoding="utf-8")


def test_an_installed_plugin_gets_repro_scripts_that_print_its_rows(site: Path,
                                                                     tmp_path: Path) -> None:
    (tmp_path / "cases.toml").write_text(CASES, encoding="utf-8")
    out = tmp_path / "run"
    ran = python(site, "-m", "crosscheck.cli", "run", "cases.toml", "--quick", "--jobs", "1",
                 "--engine", "numpy-spheres", "--out", str(out), cwd=tmp_path)
    assert ran.returncode == 0, ran.stderr
    results = pd.read_csv(out / "results.csv", keep_default_na=False)
    assert set(results.loc[results["case_id"] == "ball-on-floor", "status"]) == {"skip"}
    for case in ("spheres-apart", "discs-head-on"):
        made = python(site, "-m", "crosscheck.cli", "repro", str(out), case,
                      "--engine", "numpy-spheres", cwd=tmp_path)
        assert made.returncode == 0, made.stderr
        (tmp_path / "alone").mkdir(exist_ok=True)  # no plug-in, no harness: the script alone
        script = tmp_path / "alone" / f"{case}.py"
        script.write_text(made.stdout, encoding="utf-8")
        alone = subprocess.run([sys.executable, "-I", str(script)], cwd=script.parent,
                               capture_output=True, text=True, timeout=300)
        assert alone.returncode == 0, alone.stderr
        printed = dict(line.split(" = ", 1) for line in alone.stdout.splitlines()
                       if " = " in line and not line.startswith(("#", "expected", "textbook")))
        rows = dict(zip(*results.loc[results["case_id"] == case, ["quantity", "value"]].T.values,
                        strict=True))
        shown = {"distance", "normal", "hit"} if case == "spheres-apart" else {
            "positions", "velocities", "momentum", "energy", "energy_drift"}  # open space
        assert shown <= set(printed) and shown <= set(rows), (case, printed)
        assert {q: printed[q] for q in shown} == {q: rows[q] for q in shown}, case


def docs_page() -> str:
    """The docs page that shows the plug-in: docs/adding-an-engine.md."""
    return (ROOT / "docs" / "adding-an-engine.md").read_text(encoding="utf-8")


def docs_blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", docs_page(), flags=re.DOTALL)


def test_the_docs_ci_example_runs_the_kit_on_the_installed_plugin(site: Path,
                                                                  tmp_path: Path) -> None:
    example = next(block for block in docs_blocks("python") if "check_adapter(" in block)
    test = re.search(r"def (test_\w+)\(", example)
    assert test
    ran = python(site, "-c", f"{example}\n{test.group(1)}()\nprint('conforms')", cwd=tmp_path)
    assert ran.returncode == 0 and "conforms" in ran.stdout, ran.stderr


def test_the_docs_show_the_tested_plugin_in_under_90_lines() -> None:
    shown = docs_blocks("python")
    for module in MODULES:
        assert module.read_text(encoding="utf-8") in shown, module.name
    assert sum(m.read_text(encoding="utf-8").count("\n") for m in MODULES) < 90
    (shown,) = docs_blocks("toml")
    tested = tomllib.loads((PLUGIN / "pyproject.toml").read_text(encoding="utf-8"))
    assert tomllib.loads(shown) == {"project": tested["project"]}
    points = tested["project"]["entry-points"][adapters.ENTRY_POINT_GROUP]
    assert points == {"numpy-spheres": "crosscheck_numpy_spheres:NumpySpheres"}


# --- broken plug-ins, refused with their reasons -------------------------------------------

DISTRIBUTIONS = {
    ("crosscheck-clash", "1.0"): {"fcl": "crosscheck_numpy_spheres:NumpySpheres"},
    ("crosscheck-broken", "2.0"): {
        "boom": "crosscheck_boom_plugin:Boom",
        "missing": "crosscheck_no_such_module:Engine",
        "not-adapter": "json:dumps",
        "misnamed": "crosscheck.testing.fakes:Conforming",
        "twice": "crosscheck.testing.fakes:AlwaysRight",
        "fake-needs-argument": "tests.adapters.test_conformance:NeedsArgument"},
    ("crosscheck-twin", "3.0"): {"twice": "crosscheck.testing.fakes:OffByOne"},
    ("crosscheck-fakes", "0.0.1"): {"fake-conforming": "crosscheck.testing.fakes:Conforming"},
}


@pytest.fixture
def plugins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Plug-in distributions as bare .dist-info folders on sys.path, and a module that fails
    on import; the built-in table cut down to two engines and a missing module."""
    for (dist, version), points in DISTRIBUTIONS.items():
        info = tmp_path / f"{dist.replace('-', '_')}-{version}.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(
            f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n", encoding="utf-8")
        lines = [f"{name} = {target}" for name, target in points.items()]
        (info / "entry_points.txt").write_text(
            "\n".join([f"[{adapters.ENTRY_POINT_GROUP}]", *lines, ""]), encoding="utf-8")
    (tmp_path / "crosscheck_boom_plugin.py").write_text(
        'raise RuntimeError("libboom.so not found")\n', encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(adapters, "REGISTRY", {
        "reference": ("adapters.reference", "ReferenceF64"), "fcl": ("adapters.fcl", "Fcl"),
        "ghost": ("adapters.ghost_engine", "Ghost")})
    return tmp_path


REFUSALS = {
    "fcl": "plug-in engine 'fcl' from distribution crosscheck-clash 1.0 "
           "(crosscheck_numpy_spheres:NumpySpheres) is refused: its name clashes with the "
           "built-in engine 'fcl', which keeps it",
    "boom": "plug-in engine 'boom' from distribution crosscheck-broken 2.0 "
            "(crosscheck_boom_plugin:Boom) is refused: import failed: RuntimeError: "
            "libboom.so not found",
    "missing": "is refused: import failed: ModuleNotFoundError: No module named "
               "'crosscheck_no_such_module'",
    "not-adapter": "(json:dumps) is refused: it is not an Adapter subclass (it is function",
    "misnamed": "is refused: its class declares the name 'fake-conforming', not 'misnamed'",
    "twice": "from distribution crosscheck-broken 2.0 (crosscheck.testing.fakes:AlwaysRight) "
             "is refused: crosscheck-twin 3.0 also declare(s) 'twice': neither is used",
    "fake-needs-argument": "(tests.adapters.test_conformance:NeedsArgument) is refused: it fails: "
                           "TypeError: NeedsArgument.__init__() missing 1 required positional "
                           "argument: 'path'",
    "ghost": "built-in engine 'ghost' (adapters.ghost_engine:Ghost) is unavailable: import "
             "failed: ModuleNotFoundError: No module named 'adapters.ghost_engine'",
}


@pytest.mark.engine
def test_engines_lists_every_plugin_with_its_origin_and_every_refusal(
        plugins: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["engines"]) == 0
    captured = capsys.readouterr()
    assert "Traceback" not in captured.out + captured.err
    flat = " ".join(captured.out.split())  # the notes below the table wrap at the width
    for refusal in REFUSALS.values():
        assert " ".join(refusal.split()) in flat, refusal
    rows: dict[str, list[str]] = {}
    for line in captured.out.splitlines():
        if line.startswith("│ ") and line.split("│")[1].strip():
            rows.setdefault(line.split("│")[1].strip(), []).append(line)
    assert re.search(r"│ plug-in +│ 0 +│ yes +│", *rows["fake-conforming"])
    assert ("plug-in engine 'fake-conforming' from distribution crosscheck-fakes 0.0.1 "
            "(crosscheck.testing.fakes:Conforming)") in flat
    builtin_fcl, plugin_fcl = rows["fcl"]  # the built-in keeps the name; the clash is listed
    assert re.search(r"│ built-in +│ [\d.]+ +│ yes +│", builtin_fcl)
    assert re.search(r"│ plug-in +│ - +│ refused +│", plugin_fcl)
    for name in ("boom", "missing", "not-adapter", "misnamed", "fake-needs-argument"):
        assert re.search(r"│ plug-in +│ - +│ refused +│", *rows[name])
    assert all(re.search(r"│ plug-in +│ - +│ refused +│", row) for row in rows["twice"])
    assert re.search(r"│ built-in +│ - +│ unavailable +│", *rows["ghost"])


@pytest.mark.parametrize("name", ["boom", "missing", "not-adapter", "misnamed", "twice",
                                  "fake-needs-argument", "ghost"])
def test_run_refuses_a_broken_engine_by_name_with_the_reason(
        name: str, plugins: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (plugins / "cases.toml").write_text(CASES, encoding="utf-8")
    code = main(["run", str(plugins / "cases.toml"), "--quick", "--engine", name,
                 "--out", str(plugins / "run")])
    captured = capsys.readouterr()
    assert code == 2 and not (plugins / "run").exists()
    assert REFUSALS[name] in " ".join(captured.err.split()), captured.err
    assert "Traceback" not in captured.err


def test_a_plugin_never_shadows_a_built_in(plugins: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    (chosen,) = engine_choice.select(["fcl"])
    assert type(chosen).__module__ == "adapters.fcl"
    note = " ".join(capsys.readouterr().err.split())
    assert "crosscheck-clash 1.0" in note and "the built-in runs" in note


@pytest.mark.engine
def test_every_engine_means_every_usable_one_and_a_note_for_the_rest(
        plugins: Path, capsys: pytest.CaptureFixture[str]) -> None:
    chosen = [adapter.name for adapter in engine_choice.select(None)]
    assert chosen == ["reference", "fcl", "fake-conforming"]
    notes = " ".join(capsys.readouterr().err.split())
    for name in ("fcl", "boom", "missing", "not-adapter", "misnamed", "twice",
                 "fake-needs-argument"):
        assert f"note: skipping plug-in engine {name!r} from distribution crosscheck-" in notes
    assert "note: skipping built-in engine 'ghost'" in notes
    assert "engine 'fake-conforming'" not in notes


def test_plugin_names_are_choices_of_engine_and_refused_names_say_why(plugins: Path) -> None:
    assert engine_choice.names() == [
        "reference", "fcl", "ghost", "boom", "fake-conforming", "fake-needs-argument",
        "misnamed", "missing",
        "not-adapter", "twice"]
    with pytest.raises(adapters.RefusedEngine, match="neither is used"):
        adapters.get("twice")
    with pytest.raises(adapters.UnknownEngine, match="unknown engine 'nosuch'; known: "):
        adapters.get("nosuch")
    assert isinstance(adapters.get("fake-conforming"), adapters.adapter_class("fake-conforming"))
