"""The suite's two tiers: which case folders a run of each holds, and which tier a run was.

The **standard** tier (``cases/``, what ``make run`` and ``crosscheck run`` run) holds every
kind, family, engine and regime, each sweep trimmed to the levels where the engines break.
The **deep** tier (``crosscheck run --deep``, ``make run-deep``) adds ``cases-deep/``: the
scenes' time steps below 1e-3 (a convergence question: a million steps at 1e-5 s for a
ten-second scene), the minute-long gases at 1/240 s, the strength-3 covering designs and
the rest of the fast-disc-against-a-wall block.
The tier is the folder a case file lies in: a run is ``deep`` when one of its case files
lies in a folder named ``cases-deep``, and ``standard`` otherwise (run.json's ``tier``, and
the report's header).

>>> tier_of(["cases/sphere.toml", "cases-deep/scenes.toml"])
'deep'
>>> tier_of(["cases/sphere.toml"])
'standard'
>>> [str(p) for p in tier_paths(deep=True)]
['cases', 'cases-deep']
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path, PurePath

STANDARD = Path("cases")
"""The standard tier's case folder."""
DEEP = Path("cases-deep")
"""The folder the deep tier adds."""


def tier_paths(deep: bool) -> list[Path]:
    """The case folders a run of the tier holds (relative to the project root)."""
    return [STANDARD, DEEP] if deep else [STANDARD]


def tier_of(case_files: Iterable[str | PurePath]) -> str:
    """``deep`` when a case file lies in a ``cases-deep`` folder, else ``standard``."""
    return ("deep" if any(DEEP.name in PurePath(f).parts[:-1] for f in case_files)
            else "standard")
