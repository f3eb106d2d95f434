"""The fuzz study: generate cases near engine failure boundaries, run them, group findings.

Cases come from :mod:`crosscheck.studies.fuzzgen` (same seed, same cases); they run
into a normal run folder (``DIR/run``, through :func:`crosscheck.run.launch.launch`);
findings (disagree, error, crash, timeout) are grouped and written as
ready-to-commit case files by :mod:`crosscheck.studies.findings`, with
``DIR/findings.csv`` listing every one.  ``crosscheck fuzz`` is its command.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import pandas as pd

from crosscheck.core.contract import Adapter
from crosscheck.core.model import Kind
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import json_schema_text
from crosscheck.results.runinfo import now
from crosscheck.results.store import ResultsStore, read_results
from crosscheck.run import environment
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.findings import Group, write_findings
from crosscheck.studies.fuzzgen import Generated, generate

Progress = Callable[[int], None]


def run_cases(gens: Sequence[Generated], engines: Sequence[Adapter], directory: Path,
              options: RunOptions, command: str, progress: Progress | None = None) -> pd.DataFrame:
    """Run the cases into a normal run folder at ``directory``; return its results."""
    cases = [gen.case for gen in gens]
    info = new_info(directory, command, options, engines, cases)
    launch(ResultsStore(directory), cases, engines, options, info, progress)
    return read_results(directory)


def fuzz(kind: Kind, n: int, seed: int, directory: Path, engines: Sequence[Adapter],
         options: RunOptions, per_group: int = 5, command: str = "",
         progress: Progress | None = None) -> list[Group]:
    """Generate, run into ``directory/run``, write grouped findings into ``directory``."""
    if directory.exists() and any(directory.iterdir()):
        raise FileExistsError(f"{directory} is not empty; choose another --out or empty it")
    command = command or f"crosscheck fuzz --kind {kind.value} --n {n} --seed {seed}"
    start = time.perf_counter()
    gens = generate(kind, n, seed)
    generated = time.perf_counter()
    frame = run_cases(gens, engines, directory / "run", options, command, progress)
    ran = time.perf_counter()
    groups = write_findings(directory, {g.case.id: g for g in gens}, frame, command, per_group)
    (directory / "schema.json").write_text(json_schema_text(), encoding="utf-8")
    info = {"command": command, "kind": kind.value, "n": n, "seed": seed,
            "engines": [a.name for a in engines], "per_group": per_group,
            "options": options.to_json(), "finished": now(), "generate_s": generated - start,
            "run_s": ran - generated, "write_s": time.perf_counter() - ran,
            "findings": sum(len(g.rows) for g in groups), "groups": len(groups),
            "files": sum(bool(g.chosen) for g in groups), "machine": environment.machine()}
    (directory / "fuzz.json").write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")
    return groups
