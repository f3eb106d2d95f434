"""Start-up cost of the CLI, checked as a module set (never a timing): ``crosscheck --help``
and ``crosscheck <cmd> --help`` build the parser of every command without importing the
heavy libraries a command only needs when it runs (pandas, numpy, pydantic, plotly, jinja2,
Dask, scipy, pyarrow, the engines).  Each check runs in a fresh interpreter, so what this
test process has already imported cannot hide an import.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from crosscheck.cli import build_parser
from tests.conftest import ROOT

HEAVY = ("pandas", "numpy", "pydantic", "plotly", "jinja2", "dask", "distributed", "scipy",
         "pyarrow", "pybullet", "pymunk", "fcl", "coal", "mujoco", "Box2D", "rapier3d")
"""Top-level packages that no ``--help`` may import."""

PROBE = """
import json, sys
import crosscheck.cli
try:
    crosscheck.cli.main(json.loads(sys.argv[1]))
except SystemExit:
    pass
heavy = json.loads(sys.argv[2])
print(json.dumps(sorted({m.split(".")[0] for m in sys.modules} & set(heavy))))
"""


def heavy_imports(argv: list[str], heavy: tuple[str, ...] = HEAVY) -> list[str]:
    """The packages of ``heavy`` that ``crosscheck argv`` imports, in a fresh interpreter."""
    done = subprocess.run([sys.executable, "-c", PROBE, json.dumps(argv), json.dumps(heavy)],
                          cwd=ROOT, capture_output=True, text=True, timeout=120, check=True)
    found: list[str] = json.loads(done.stdout.strip().splitlines()[-1])
    return found


def commands() -> list[str]:
    """Every subcommand of ``crosscheck``."""
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert sub.choices is not None
    return sorted(sub.choices)


def test_top_level_help_imports_no_heavy_library() -> None:
    assert heavy_imports(["--help"]) == []


@pytest.mark.parametrize("command", commands())
def test_command_help_imports_no_heavy_library(command: str) -> None:
    assert heavy_imports([command, "--help"]) == []


def test_the_probe_can_fail() -> None:
    """A command that does run (here ``schema --check``, which needs pydantic) is caught."""
    assert "pydantic" in heavy_imports(["schema", "--check"])
