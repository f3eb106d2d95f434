"""``crosscheck bench --compare OLD``: this bench's figures beside a previous ``bench.json``.

A figure is matched by name.  The machines are compared first (CPU, cores,
Python, platform and package versions), because a figure measured on another
machine or with other packages is not comparable as such; the differences are
listed before the figures.

``bench.json`` format history (every version can be read):

- **1**: figures with name, value, unit, target, ok, detail and note; one suite
  run each of ``--quick`` and the full run, all engines;
- **2**: the suite runs name their engines (the seven variants of the targets,
  and every available engine), and ``--help`` and the report render are figures;
- **3**: a figure may be recorded only (``gating`` false, ``ok`` true, target
  ``recorded, never gating``); the harness overhead is counted in instructions under
  callgrind (``harness overhead <engine> <kind>, counted instructions``, gating, NaN with
  the reason when not counted) and the wall-clock figures of the same name without
  ``, counted instructions`` are recorded only.  A figure of an older file has no
  ``gating`` field and is read as gating (its ``ok`` judged its target).

>>> old = {"format_version": 1, "machine": {"cores": 2}, "figures": [
...     {"name": "f", "value": 2.0, "unit": "s", "target": "<= 3 s", "ok": True}]}
>>> new = {"format_version": 2, "machine": {"cores": 4}, "figures": [
...     {"name": "f", "value": 1.0, "unit": "s", "target": "<= 3 s", "ok": True}]}
>>> result = compare(new, old)
>>> result.machine, [(r.name, r.ratio) for r in result.rows]
(['cores: 2 -> 4'], [('f', 0.5)])
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

READABLE = (1, 2, 3)
"""The bench.json versions this harness reads."""


class BenchFileError(ValueError):
    """A bench.json that cannot be compared with."""


@dataclass(frozen=True)
class Row:
    """One figure in both benches (``old`` NaN: not in the previous one)."""

    name: str
    unit: str
    old: float
    new: float
    ok_old: bool | None
    ok_new: bool
    gating: bool = True
    """Whether the new figure judges its target (False: recorded only)."""

    @property
    def ratio(self) -> float:
        """new / old (NaN when either is missing or zero)."""
        if not (math.isfinite(self.old) and math.isfinite(self.new)) or self.old == 0:
            return math.nan
        return self.new / self.old


@dataclass(frozen=True)
class Comparison:
    """The machine differences, then every figure of the new bench."""

    machine: list[str]
    rows: list[Row]


def load(path: Path) -> dict[str, Any]:
    """A previous bench.json, checked for a readable format version."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise BenchFileError(f"--compare {path}: cannot read it: {exc}") from exc
    version = data.get("format_version") if isinstance(data, dict) else None
    if version not in READABLE:
        raise BenchFileError(f"--compare {path}: bench.json format {version!r}; this harness "
                             f"reads formats {', '.join(map(str, READABLE))}")
    return dict(data)


def machine_differences(new: dict[str, Any], old: dict[str, Any]) -> list[str]:
    """``key: old -> new`` for every machine field and package version that differs."""
    out = []
    for key in ("cpu", "cores", "python", "platform"):
        if old.get(key) != new.get(key):
            out.append(f"{key}: {old.get(key)} -> {new.get(key)}")
    packages_old, packages_new = old.get("packages", {}), new.get("packages", {})
    for name in sorted(set(packages_old) | set(packages_new)):
        if packages_old.get(name) != packages_new.get(name):
            out.append(f"{name}: {packages_old.get(name, 'absent')} -> "
                       f"{packages_new.get(name, 'absent')}")
    return out


def compare(new: dict[str, Any], old: dict[str, Any]) -> Comparison:
    """Every figure of ``new`` beside the same-named figure of ``old``."""
    before = {f["name"]: f for f in old.get("figures", [])}
    rows = []
    for f in new.get("figures", []):
        prior = before.get(f["name"], {})
        rows.append(Row(f["name"], f.get("unit", ""), float(prior.get("value", math.nan)),
                        float(f["value"]), prior.get("ok"), bool(f["ok"]),
                        bool(f.get("gating", True))))
    return Comparison(machine_differences(new.get("machine", {}), old.get("machine", {})),
                      rows)
