"""The label changes between two runs, per engine variant, as Markdown.

    python -m tools.label_changes reports/full-915f9e7 reports/<new-run>

Reads the ``results.csv`` of both run folders, keys their rows on ``(case_id, engine,
quantity)`` and prints, for each variant with a change, a table of ``status/category``
labels ``from -> to`` with the number of rows that moved; a row only one run has reads
``(absent)`` on the other side.  Rows whose label did not change are counted but not
listed.  The labels are read as the files give them (any results format whose csv has
``status`` and ``category`` columns).
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import Counter
from collections.abc import Iterable, Sequence
from pathlib import Path

Key = tuple[str, str, str]
ABSENT = "(absent)"


def labels(run: Path) -> dict[Key, str]:
    """``status/category`` (``status`` alone without a category) of every row of a run."""
    with (run / "results.csv").open(newline="", encoding="utf-8") as handle:
        return {(row["case_id"], row["engine"], row["quantity"]):
                "/".join(x for x in (row["status"], row.get("category") or "") if x)
                for row in csv.DictReader(handle)}


def changes(old: dict[Key, str], new: dict[Key, str]) -> dict[str, Counter[tuple[str, str]]]:
    """Per engine variant: how many rows moved from one label to another.

    >>> changes({("c", "e", "q"): "agree"}, {("c", "e", "q"): "disagree/error"})
    {'e': Counter({('agree', 'disagree/error'): 1})}
    """
    moved: dict[str, Counter[tuple[str, str]]] = {}
    for key in sorted(old.keys() | new.keys()):
        before, after = old.get(key, ABSENT), new.get(key, ABSENT)
        if before != after:
            moved.setdefault(key[1], Counter())[(before, after)] += 1
    return moved


def markdown(moved: dict[str, Counter[tuple[str, str]]], engines: Iterable[str],
             old_name: str, new_name: str) -> str:
    """The changes as Markdown: one table per variant that changed, in ``engines`` order."""
    lines = [f"Label changes from `{old_name}` to `{new_name}` (rows keyed on case, engine "
             "and quantity).", ""]
    unchanged = [e for e in engines if e not in moved]
    for engine in [e for e in engines if e in moved]:
        lines += [f"### {engine}", "", "| from | to | rows |", "| --- | --- | ---: |"]
        for (before, after), count in sorted(moved[engine].items(),
                                             key=lambda item: (-item[1], item[0])):
            lines.append(f"| {before} | {after} | {count:,} |")
        lines.append("")
    if unchanged:
        lines.append("No label changed: " + ", ".join(unchanged) + ".")
    return "\n".join(lines).rstrip() + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Compare two run folders (see the module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path, help="the earlier run folder")
    parser.add_argument("new", type=Path, help="the later run folder")
    args = parser.parse_args(argv)
    old, new = labels(args.old), labels(args.new)
    engines = list(dict.fromkeys(key[1] for key in [*old, *new]))
    sys.stdout.write(markdown(changes(old, new), engines, args.old.name, args.new.name))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
