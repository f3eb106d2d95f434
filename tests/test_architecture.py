"""The house rules that import-linter does not check: function-level imports, private names,
module length, import circles.  (The layers themselves are checked by ``lint-imports`` in
``make lint``; a layer contract allows a circle inside one layer, so circles are checked here,
on grimp's graph of every module of ``crosscheck``, ``adapters`` and ``reference_impl``, a
package's ``__init__`` counting as a module.)

Function-level imports are allowed in three places only:

- anywhere, the optional engines and Dask (:data:`OPTIONAL`);
- in the command modules ``crosscheck/cli/*.py``, the library they drive
  (``crosscheck.*`` below the CLI) and pandas (:data:`CLI_LAZY`): each command imports what
  it runs inside its ``cmd_*`` function, so that building the parser (``crosscheck --help``,
  ``crosscheck <cmd> --help``) imports no pandas, numpy, pydantic, plotly, jinja2 or Dask
  (``tests/cli/test_startup.py`` checks the module set);
- single modules named in :data:`LAZY_AT`: the adapter contract inside the registry (listing
  engine names, which every ``--help`` of a command that takes ``--engine`` does, must not
  load pydantic and numpy), and the pytest plugin's suite inside the plugin (every pytest
  run with crosscheck installed loads the plugin; the library, pandas and the engines load
  only when ``--crosscheck-engine`` is given).
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

import grimp
import pytest

from tests.conftest import ROOT

PACKAGES = ("crosscheck", "adapters", "reference_impl")
OPTIONAL = {"pybullet", "pymunk", "fcl", "coal", "Box2D", "rapier3d", "mujoco", "dask",
            "distributed", "pydrake", "pyb2d3"}
"""What may be imported inside a function: the optional engines, and Dask (see run/distributed)."""
CLI_LAZY = ("crosscheck", "pandas")
"""What a CLI command module may import inside a function (not ``crosscheck.cli`` itself)."""
LAZY_AT = {"adapters/__init__.py": {"crosscheck.core.contract"},
           "crosscheck/pytest_plugin/__init__.py": {"crosscheck.pytest_plugin.suite"}}
"""Single modules a file may import inside a function, with the reason in the docstring above."""
MODULES = sorted(p for package in PACKAGES for p in (ROOT / package).rglob("*.py"))


def _name(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _allowed(path: str, module: str) -> bool:
    """Whether ``path`` may import ``module`` inside a function (see the module docstring)."""
    root = module.split(".")[0]
    if root in OPTIONAL or module in LAZY_AT.get(path, ()):
        return True
    in_cli = path.startswith("crosscheck/cli/")
    return in_cli and root in CLI_LAZY and not module.startswith("crosscheck.cli")


def _function_imports(tree: ast.Module, path: str = "") -> list[tuple[int, str]]:
    found = []
    for func in ast.walk(tree):
        if isinstance(func, ast.FunctionDef | ast.AsyncFunctionDef):
            for node in ast.walk(func):
                if isinstance(node, ast.Import):
                    found += [(node.lineno, a.name) for a in node.names]
                elif isinstance(node, ast.ImportFrom) and node.module:
                    found.append((node.lineno, node.module))
    return [(line, m) for line, m in found if not _allowed(path, m)]


def _private_imports(tree: ast.Module) -> list[tuple[int, str]]:
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in PACKAGES:
            found += [(node.lineno, f"{node.module}.{a.name}") for a in node.names
                      if a.name.startswith("_") and not a.name.startswith("__")]
            if any(part.startswith("_") and not part.startswith("__")
                   for part in (node.module or "").split(".")):
                found.append((node.lineno, str(node.module)))
    return found


@pytest.mark.parametrize("path", MODULES, ids=_name)
def test_no_function_level_import_but_optional_engines(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    assert _function_imports(tree, _name(path)) == []


@pytest.mark.parametrize("path", [*MODULES, *sorted((ROOT / "tests").rglob("*.py"))], ids=_name)
def test_no_import_of_another_modules_private_name(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    assert _private_imports(tree) == []


@pytest.mark.parametrize("path", MODULES, ids=_name)
def test_a_module_over_400_lines_says_why(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    if text.count("\n") > 400:
        docstring = ast.get_docstring(ast.parse(text)) or ""
        assert "400 lines" in docstring, f"{_name(path)}: {text.count(chr(10))} lines, no reason"


def test_the_rules_can_fail() -> None:
    tree = ast.parse("def f():\n    import json\n    from crosscheck.cases import load\n"
                     "from crosscheck.report.render import _private\n")
    assert _function_imports(tree) == [(2, "json"), (3, "crosscheck.cases")]
    assert _private_imports(tree) == [(4, "crosscheck.report.render._private")]


def test_only_cli_commands_import_the_library_lazily() -> None:
    tree = ast.parse("def f():\n    import pandas\n    from crosscheck.cases import load\n"
                     "    from crosscheck.cli import run\n    import json\n")
    assert _function_imports(tree, "crosscheck/cli/run.py") == [(4, "crosscheck.cli"),
                                                                (5, "json")]
    assert _function_imports(tree, "crosscheck/report/render.py") == [
        (2, "pandas"), (3, "crosscheck.cases"), (4, "crosscheck.cli"), (5, "json")]


def _reachable(graph: grimp.ImportGraph, start: str) -> set[str]:
    """The modules ``start`` imports, directly or through others."""
    found: set[str] = set()
    todo = [start]
    while todo:
        for imported in graph.find_modules_directly_imported_by(todo.pop()):
            if imported not in found:
                found.add(imported)
                todo.append(imported)
    return found


def circles(graph: grimp.ImportGraph, modules: Iterable[str]) -> list[list[str]]:
    """The import circles among ``modules``: each set of modules that import each other, in
    turn (a strongly connected component of more than one module, or one that imports
    itself), sorted."""
    reach = {m: _reachable(graph, m) for m in modules}
    found: list[list[str]] = []
    for module in sorted(reach):
        if module in reach[module] and not any(module in c for c in found):
            found.append(sorted({module} | {m for m in reach[module] if module in reach[m]}))
    return found


def test_no_import_circle() -> None:
    graph = grimp.build_graph(*PACKAGES)
    assert circles(graph, graph.modules) == []


def test_the_circle_check_can_fail() -> None:
    graph = grimp.ImportGraph()
    for importer, imported in (("p.a", "p.b"), ("p.b", "p.c"), ("p.c", "p.a"), ("p.c", "p.d"),
                               ("p", "p.d"), ("p.d", "p")):
        graph.add_import(importer=importer, imported=imported)
    assert circles(graph, graph.modules) == [["p", "p.d"], ["p.a", "p.b", "p.c"]]
