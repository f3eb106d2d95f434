"""The set-up time of a fresh clone: ``make venv`` and ``make test``, wall clock, as JSON.

    python -m tools.measure_setup              # make venv in a fresh clone of HEAD
    python -m tools.measure_setup --test       # then make test in that clone too

Clones the repository's committed HEAD into a temporary folder (what a new user gets:
nothing of this checkout's ``.venv``, caches or uncommitted files), runs each step there
once and records its wall-clock seconds in ``docs/measurements/setup.json`` (``--output``),
with the clone's commit, the date and the machine.  pip's download cache is off unless
``--pip-cache`` is given, as on a fresh machine.  A step that fails is not recorded (the
command's output says why).  ``make docs-figures`` turns the file into
``docs/generated/setup.md``; a step never measured is "not measured yet" there.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from crosscheck.results.runinfo import now
from crosscheck.run import environment

ROOT = Path(__file__).resolve().parent.parent
OUTPUT = ROOT / "docs" / "measurements" / "setup.json"


def timed(command: Sequence[str], cwd: Path, env: dict[str, str],
          clock: Callable[[], float] = time.perf_counter) -> float | None:
    """Run ``command`` in ``cwd``; its wall-clock seconds (``clock`` read before and after
    it), or None when it failed."""
    start = clock()
    done = subprocess.run(list(command), cwd=cwd, env=env, check=False)
    seconds = clock() - start
    if done.returncode:
        print(f"error: {' '.join(command)} failed (exit {done.returncode}) after "
              f"{seconds:.0f} s: not recorded", file=sys.stderr)
        return None
    return seconds


def measure(steps: Sequence[str], pip_cache: bool) -> dict[str, dict[str, Any]]:
    """Each step's record, run one after the other in one fresh clone of HEAD."""
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    if not pip_cache:
        env["PIP_NO_CACHE_DIR"] = "1"
    records: dict[str, dict[str, Any]] = {}
    with tempfile.TemporaryDirectory(prefix="crosscheck-fresh-clone-") as folder:
        clone = Path(folder) / "clone"
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
        machine = environment.machine() | {"git_commit": environment.git_commit(clone)}
        for step in steps:
            print(f"timing {step} in a fresh clone at {machine['git_commit']} ...", flush=True)
            seconds = timed(step.split(), clone, env)
            if seconds is None:
                break
            records[step] = {"seconds": seconds, "measured": now(), "command": step,
                             "pip_cache": pip_cache, "machine": machine}
            print(f"{step}: {seconds:.0f} s", flush=True)
    return records


def main(argv: Sequence[str] | None = None) -> int:
    """Measure, then merge the records into ``--output`` (other steps' records are kept)."""
    cli = argparse.ArgumentParser(prog="python -m tools.measure_setup", description=__doc__,
                                  formatter_class=argparse.RawDescriptionHelpFormatter)
    cli.add_argument("--test", action="store_true", help="also time make test (minutes)")
    cli.add_argument("--pip-cache", action="store_true", help="let pip use its download cache")
    cli.add_argument("--output", type=Path, default=OUTPUT, help="the JSON file to update")
    args = cli.parse_args(argv)
    steps = ["make venv", *(["make test"] if args.test else [])]
    records = measure(steps, args.pip_cache)
    if records:
        old = json.loads(args.output.read_text(encoding="utf-8")) if args.output.exists() else {}
        args.output.parent.mkdir(parents=True, exist_ok=True)
        args.output.write_text(json.dumps(old | records, indent=2) + "\n", encoding="utf-8")
        print(f"wrote {args.output}")
    return 0 if len(records) == len(steps) else 1


if __name__ == "__main__":
    sys.exit(main())
