"""How the report points at a row's repro script: the command that prints it, and the file
when the run folder holds one.

A run writes no repro scripts: ``crosscheck repro RUN CASE --engine ENGINE`` prints one on
demand, and ``crosscheck repro RUN --all`` writes every breaking pair's into ``RUN/repro/``.
The report cannot ask which engines make their calls as a module (it imports neither the
studies nor the adapters), so it gives the command for every breaking row; the command
itself says so when an engine's calls are not a module.  A run folder that holds
``repro/<name>.py`` (a run made when every run wrote them, or one after ``repro --all``)
keeps the link to it.

The page builds the command itself from the run folder (one value for the page) and each
row's case and engine, quoting as :func:`command` does (``reproCommand`` in
``templates/_disagreements.html.j2``).

>>> command("reports/r 1", "sphere-gap.gap=0.001", "pybullet")
"crosscheck repro 'reports/r 1' sphere-gap.gap=0.001 --engine pybullet"
>>> link("s1", "fcl", {"s1_fcl.py"}), link("s2", "fcl", {"s1_fcl.py"})
('repro/s1_fcl.py', '')
"""

from __future__ import annotations

import shlex
from collections.abc import Collection
from pathlib import Path

from crosscheck.results.store import REPRO_DIR, repro_name

__all__ = ["command", "link"]


def command(run_dir: str | Path, case_id: str, engine: str) -> str:
    """The command that prints the script reproducing ``case_id`` on ``engine``, quoted for a
    POSIX shell."""
    return shlex.join(["crosscheck", "repro", str(run_dir), case_id, "--engine", engine])


def link(case_id: str, engine: str, written: Collection[str]) -> str:
    """``repro/<name>.py``, relative to the report, when that script is among ``written``
    (file names: :attr:`crosscheck.results.run.Run.repros`), else ``""`` (a run folder
    without scripts, the usual case, names none: no name is built)."""
    if not written:
        return ""
    name = f"{repro_name(case_id, engine)}.py"
    return f"{REPRO_DIR}/{name}" if name in written else ""
