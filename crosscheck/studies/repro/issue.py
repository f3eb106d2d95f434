"""An issue-ready bug report: a case x engine of a stored run as Markdown, around its repro script.

The report has the parts engine maintainers ask for in their issue templates: what happens
and what was expected (each quantity's answer beside the exact one, the error against the
float64 bound, the verdict), the setup (the engine and its version, the platform: OS,
Python, machine, all from run.json), a minimal model (MuJoCo: the MJCF the script
compiles) and the code that reproduces it (the script itself: the engine's own calls), how
the harness judged it (the category and reason of each row, the conventions it consulted,
their sources) and the case file block (TOML, as in ``cases/*.toml``).

The block is the one of the case's source file that the case comes from (its id, or the
block a sweep, a swap or a 2-D twin expanded it from), when that file can be read; the
case itself follows as one block that loads back into exactly this case
(:func:`crosscheck.cases.writer.case_block`) whenever it is not that block as written.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Sequence
from importlib import metadata
from pathlib import Path
from typing import Any

from crosscheck.cases.writer import case_block
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.studies.repro.script import Row, Script
from crosscheck.studies.repro.verdicts import against_bound, conventions_line

EXACT_PAIR = "crosscheck's oracle, in exact rational arithmetic"
EXACT_SCENE = "crosscheck's exact event-driven run of the scene, to the same simulated time"
REPO = Path(__file__).resolve().parents[3]
"""Where the shipped case files are (``cases/...`` paths in a run are relative to it)."""


def _source_file(source: str) -> Path | None:
    path = Path(source)
    for candidate in (path, REPO / path):
        if candidate.is_file():
            return candidate
    return None


def source_block(case: AnyCase) -> tuple[str, str] | None:
    """(block id, TOML text) of the block of the case's source file that ``case`` comes from:
    the block whose id is the case's id or its longest prefix ending before a ``.`` (a sweep,
    swap or 2-D twin adds ``.<suffix>``).  None when the file cannot be read or has no such
    block."""
    path = _source_file(case.source) if case.source else None
    if path is None:
        return None
    text = path.read_text(encoding="utf-8")
    try:
        blocks = tomllib.loads(text).get("case", [])
    except tomllib.TOMLDecodeError:
        return None
    lines = text.splitlines()
    starts = [i for i, line in enumerate(lines) if line.strip().replace(" ", "") == "[[case]]"]
    ids = [str(b.get("id", "")) for b in blocks if isinstance(b, dict)]
    if len(ids) != len(starts):
        return None
    prefixes = [case.id[:i] for i, c in enumerate(case.id) if c == "."] + [case.id]
    found = [i for i, block_id in enumerate(ids) if block_id in prefixes]
    if not found:
        return None
    index = max(found, key=lambda i: len(ids[i]))
    end = starts[index + 1] if index + 1 < len(starts) else len(lines)
    span = lines[starts[index]:end]
    while span and (not span[-1].strip() or span[-1].lstrip().startswith("#")):
        span.pop()
    return ids[index], "\n".join(span)


def _table(rows: Sequence[Row]) -> list[str]:
    out = ["| quantity | got | expected (exact) | error against its bound | verdict |",
           "|---|---|---|---|---|"]
    for r in rows:
        verdict = str(r["status"]) + (f" / {r['category']}" if r.get("category") else "")
        out.append(f"| {r['quantity']} | `{r['value']}` | `{r['truth']}` | "
                   f"{against_bound(r) or '-'} | {verdict} |")
    return out


def _judged(rows: Sequence[Row], info: Mapping[str, Any], case: AnyCase) -> list[str]:
    out = []
    for r in rows:
        head = f"- **{r['quantity']}**: {r['status']}" + (
            f" / {r['category']}" if r.get("category") else "")
        out.append(head + (f": {r['reason']}" if r.get("reason") else ""))
    rules = conventions_line(info, case).removeprefix("# ")
    out += ["", f"- {rules}"]
    sources = (info.get("conventions") or {}).get("sources") or ()
    if sources:
        out += ["- Sources of those conventions:", *(f"  - {s}" for s in sources)]
    return out


def _package(script: Script) -> str:
    """The distributions the script imports (third-party only), as installed here."""
    names = []
    found = metadata.packages_distributions()
    for line in script.text.splitlines():
        words = line.split()
        if len(words) >= 2 and words[0] == "import" and words[1] in found:
            names += [f"`{d}` (`import {words[1]}`)" for d in found[words[1]]]
    return ", ".join(dict.fromkeys(names)) or "-"


def _setup(info: Mapping[str, Any], machine: Mapping[str, Any], script: Script,
           run_id: str, commit: str) -> list[str]:
    python = f"{machine.get('implementation', 'Python')} {machine.get('python', '?')}"
    cpu = machine.get("cpu", "?") + (f", {machine['cores']} cores" if machine.get("cores")
                                     else "")
    return [f"- Engine: **{info.get('engine', '?')} {info.get('version', '?')}** "
            f"(crosscheck variant `{info.get('name', '?')}`)",
            f"- Python package: {_package(script)}",
            f"- Settings: {info.get('settings', '') or '-'}",
            f"- Platform: {machine.get('platform', '?')}; {python}; {cpu}",
            f"- Found by crosscheck run `{run_id}`" + (f" at commit `{commit[:12]}`" if commit
                                                       else "")]


def _case_part(case: AnyCase) -> list[str]:
    found = source_block(case)
    alone = case_block(case).rstrip("\n")
    if found is None:
        return ["The case (a block that loads back into exactly this case):", "",
                "```toml", alone, "```"]
    block_id, text = found
    out = [f"The block of `{case.source}` it comes from (`{block_id}`):", "",
           "```toml", text, "```"]
    if block_id != case.id:
        out += ["", f"`{case.id}` is one of the cases that block expands to (a sweep's point, "
                "a scene's time step, a swapped or a 2-D twin); alone, it is:", "", "```toml",
                alone, "```"]
    return out


def issue_report(script: Script, case: AnyCase, rows: Sequence[Row], info: Mapping[str, Any],
                 machine: Mapping[str, Any], run_id: str, commit: str = "") -> str:
    """The Markdown bug report of ``script`` (see the module docstring)."""
    bad = [r for r in rows if str(r["status"]) not in ("agree", "skip")] or list(rows)
    worst = ", ".join(f"{r['quantity']} {r['status']}"
                      + (f"/{r['category']}" if r.get("category") else "") for r in bad)
    name = f"{info.get('engine', script.engine)} {info.get('version', '')}".strip()
    parts = [f"## {name}: {worst} on `{case.id}`", "",
             f"{case.description}.", "", f"Below: {name}'s answer beside the exact one "
             f"({EXACT_SCENE if isinstance(case, SceneCase) else EXACT_PAIR}), and a "
             "standalone script that reproduces the answer bit for bit with the engine's "
             "own API.", "", "### What happens, and what was expected", "", *_table(rows), "",
             "### Setup", "",
             *_setup(info, machine, script, run_id, commit), ""]
    if script.model:
        parts += ["### Minimal model", "", "The MJCF the script compiles; the script then "
                  "sets the case's sizes, masses and pose in the compiled model.", "",
                  "```xml", script.model, "```", ""]
    parts += ["### Code for reproduction", "", "Standalone (only the imports it names): "
              "`python repro.py`. It prints its inputs, the engine's answer (`<quantity> = "
              "...`), the exact answer (`expected ...`) and the verdicts.", "",
              "```python", script.text.rstrip("\n"), "```", "",
              "### How crosscheck judged it", "", *_judged(rows, info, case), "",
              "### The case", "", *_case_part(case), ""]
    return "\n".join(parts)
