"""The layout of the tests and the names in the tree: names say what they are, never which
issue made them; every test module sits in a room that mirrors a package folder; no library
doctest leans on the ``tests`` package.

- No file or folder name in the project, and no test function name, carries an issue number
  (the word issue and digits, run together or apart) and no test function is numbered
  (``test_1_...``).
- Every test module lives in ``tests/<room>/`` where the room is a package folder of the
  project (``crosscheck/<pkg>``, ``adapters``, ``reference_impl``) or one of
  :data:`EXTRA_ROOMS`; deeper folders mirror a sub-package; every room folder is a package
  (an ``__init__.py``, so that two rooms may hold modules of the same name).  Only the house
  rules (:data:`TOP_LEVEL`) stay at the top.
- A doctest of ``crosscheck``, ``adapters`` or ``reference_impl`` imports nothing from
  ``tests``: examples use the public kit, :mod:`crosscheck.testing`.
"""

from __future__ import annotations

import ast
import doctest
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

import pytest

from tests.conftest import ROOT

PACKAGES = ("crosscheck", "adapters", "reference_impl")
EXTRA_ROOMS = {
    "guarantees": "the end-to-end promises of the reliability page",
    "docs": "the checks of the docs site (CLI page, stated numbers)",
}
TOP_LEVEL = {"test_architecture.py", "test_layout.py", "test_no_measured_time.py"}
"""Test modules that check the whole tree, and so belong to no room."""
SKIPPED = {".git", ".venv", "__pycache__", "reports", "node_modules", "build"}
"""Folders that are not the project's own names: tools' caches, outputs, the built site."""
ISSUE = re.compile(r"issue[\s_-]*#?\d+", re.IGNORECASE)
NUMBERED = re.compile(r"^test_?\d+(_|$)")


def project_names(root: Path) -> Iterator[Path]:
    """Every file and folder under ``root`` but hidden ones, caches and outputs."""
    for path in sorted(root.iterdir()):
        if path.name in SKIPPED or path.name.startswith(".") or path.name.endswith(".egg-info"):
            continue
        yield path
        if path.is_dir():
            yield from project_names(path)


def issue_numbered(name: str) -> bool:
    """Whether a name carries an issue number: the word issue, then digits."""
    return ISSUE.search(name) is not None


def names_of_tests(tree: ast.Module) -> Iterator[str]:
    """The names of the test functions and methods of a module."""
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and (
                node.name.startswith("test")):
            yield node.name


def bad_test_names(names: Iterable[str]) -> list[str]:
    """Test names that carry an issue number or are numbered."""
    return [n for n in names if issue_numbered(n) or NUMBERED.match(n)]


def rooms(root: Path) -> set[str]:
    """The rooms a test module may live in: the package folders, and the extra rooms."""
    found = {p.parent.name for p in (root / "crosscheck").glob("*/__init__.py")}
    return found | {"adapters", "reference_impl"} | set(EXTRA_ROOMS)


def package_folders(root: Path) -> set[str]:
    """Every package folder of the project below its top packages, as ``room/sub/...``."""
    folders = set()
    for package in PACKAGES:
        for init in (root / package).rglob("__init__.py"):
            parts = init.parent.relative_to(root).parts
            folders.add("/".join(parts[1:] if package == "crosscheck" else parts))
    return folders


def misplaced(tests: Path, allowed: set[str], folders: set[str]) -> list[str]:
    """Test modules outside a room, in a folder that mirrors no sub-package, or in a folder
    that is not a package; relative to ``tests``."""
    out = []
    for path in sorted(tests.rglob("test_*.py")):
        relative = path.relative_to(tests)
        parts = relative.parts
        if parts[0] == "data":
            continue  # fixtures, not tests
        if len(parts) == 1:
            if parts[0] not in TOP_LEVEL:
                out.append(f"{relative}: at the top, in no room")
            continue
        room, folder = parts[0], "/".join(parts[:-1])
        if room not in allowed:
            out.append(f"{relative}: {room}/ is no package folder and no declared room")
        elif len(parts) > 2 and room not in EXTRA_ROOMS and folder not in folders:
            out.append(f"{relative}: {folder}/ mirrors no sub-package")
        for depth in range(1, len(parts)):
            if not (tests.joinpath(*parts[:depth]) / "__init__.py").exists():
                out.append(f"{relative}: {'/'.join(parts[:depth])}/ has no __init__.py")
    return out


def doctest_imports_of_tests(source: str) -> list[str]:
    """Every doctest example in the docstrings of ``source`` that imports ``tests``."""
    found = []
    parser = doctest.DocTestParser()
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef
                          | ast.AsyncFunctionDef):
            continue
        docstring = ast.get_docstring(node, clean=False)
        for example in parser.get_examples(docstring or ""):
            try:
                tree = ast.parse(example.source)
            except SyntaxError:
                continue
            for statement in ast.walk(tree):
                modules = ([a.name for a in statement.names]
                           if isinstance(statement, ast.Import)
                           else [statement.module or ""]
                           if isinstance(statement, ast.ImportFrom) else [])
                if any(m == "tests" or m.startswith("tests.") for m in modules):
                    found.append(example.source.strip())
    return found


LIBRARY = sorted(p for package in PACKAGES for p in (ROOT / package).rglob("*.py"))
TESTS = sorted((ROOT / "tests").rglob("*.py"))


def test_no_file_or_folder_name_carries_an_issue_number() -> None:
    named = [str(p.relative_to(ROOT)) for p in project_names(ROOT) if issue_numbered(p.name)]
    assert named == []


@pytest.mark.parametrize("path", TESTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_test_name_carries_an_issue_number_or_a_number(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    assert bad_test_names(names_of_tests(tree)) == []


def test_every_test_module_lives_in_a_room() -> None:
    assert misplaced(ROOT / "tests", rooms(ROOT), package_folders(ROOT)) == []


@pytest.mark.parametrize("path", LIBRARY, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_library_doctest_imports_tests(path: Path) -> None:
    assert doctest_imports_of_tests(path.read_text(encoding="utf-8")) == []


def test_the_layout_rules_can_fail(tmp_path: Path) -> None:
    word = "issue"  # spelled apart, so that a search of the tree for issue numbers stays empty
    assert issue_numbered(f"test_{word}13_scoring.py") and issue_numbered(f"{word.title()}-18")
    assert not issue_numbered("test_scoring_defects.py") and not issue_numbered("tissue")
    assert bad_test_names(["test_1_a_normal", f"test_{word}_22", "test_2d_discs", "test_x"]) == [
        "test_1_a_normal", f"test_{word}_22"]
    assert {"truth", "run", "adapters", "guarantees"} <= rooms(ROOT)
    for name in ("test_flat.py", "misc/test_x.py", "truth/test_y.py", "truth/deep/test_z.py",
                 "run/test_ok.py"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    (tmp_path / "run" / "__init__.py").write_text("")
    assert misplaced(tmp_path, {"truth", "run"}, {"truth"}) == [
        "misc/test_x.py: misc/ is no package folder and no declared room",
        "misc/test_x.py: misc/ has no __init__.py",
        "test_flat.py: at the top, in no room",
        "truth/deep/test_z.py: truth/deep/ mirrors no sub-package",
        "truth/deep/test_z.py: truth/ has no __init__.py",
        "truth/deep/test_z.py: truth/deep/ has no __init__.py",
        "truth/test_y.py: truth/ has no __init__.py"]
    source = ('"""Doc.\n\n>>> from tests.conftest import aabb\n>>> import json\n"""\n'
              'def f():\n    """\n    >>> import tests.fakes as fakes\n    """\n')
    assert doctest_imports_of_tests(source) == ["from tests.conftest import aabb",
                                                "import tests.fakes as fakes"]
