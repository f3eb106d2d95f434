"""What the exact run of each scene case showed (``scene_facts.jsonl``): what the report needs.

A report never runs an engine, and it should not run the exact reference either: the
runner has computed every scene case's truth (:func:`crosscheck.truth.scenes.truth`, the
event-driven reference) to score its rows, so it stores, beside them, the facts of that
exact run the report reads: for each scene case one :class:`SceneFacts` line, appended as
the case's rows are written (before them, so every case with rows has its line): the
number of impacts of the exact run and those on a step boundary ``k dt``
(:func:`crosscheck.truth.scenes.aligned`; the dynamics chart flags them).  They depend on
the case alone (its bodies, walls, gravity, duration and ``dt``), not on an engine.

A case whose truth the run did not compute (a scene ``--quick`` skips) has no line.  A
resumed run appends after the old lines; a case run again for another engine appends a
new line, and :func:`read_facts` keeps the last line of each case.

Loader rule: a scene case with no line (every case of a run before format 7, which had
no ``scene_facts.jsonl``; a case cut short by a kill; a run scored record by record,
``run(..., columnar=False)``) has its facts recomputed from its stored case by
:func:`recomputed`, the same function of the same truth, so the page is the same.

>>> f = SceneFacts("c", 3, (0.5,))
>>> SceneFacts.from_json(f.to_json()) == f
True
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from crosscheck.core.model import Observation
from crosscheck.core.schema import AnyCase, SceneCase
from crosscheck.results import jsonlines
from crosscheck.truth import scenes

FILE = "scene_facts.jsonl"


@dataclass(frozen=True, slots=True)
class SceneFacts:
    """One scene case's exact run, as the report reads it."""

    case_id: str
    impacts: int | None
    """How many impacts the exact run resolved (None: there is no exact run, the reference
    failed on the case)."""
    aligned: tuple[float, ...] = ()
    """The times (s) of those impacts that fall on a step boundary ``k dt``."""

    def to_json(self) -> str:
        """The case's line in ``scene_facts.jsonl`` (without the newline; times exact)."""
        return json.dumps({"case_id": self.case_id, "impacts": self.impacts,
                           "aligned": list(self.aligned)})

    @classmethod
    def from_json(cls, data: str | Mapping[str, Any]) -> SceneFacts:
        row = json.loads(data) if isinstance(data, str) else data
        impacts = row["impacts"]
        return cls(str(row["case_id"]), None if impacts is None else int(impacts),
                   tuple(float(t) for t in row["aligned"]))


def facts_of(case: AnyCase, truth: Observation) -> SceneFacts | None:
    """The facts of ``case`` from the truth the run computed for it (None for a pair case,
    or a scene whose truth was not computed: ``--quick`` skipped it)."""
    if not isinstance(case, SceneCase) or truth.positions is None:
        return None
    impacts = truth.impacts
    return SceneFacts(case.id, None if impacts is None else len(impacts),
                      tuple(scenes.aligned(case, impacts or ())))


def recomputed(case: SceneCase) -> SceneFacts:
    """The facts of a case the run stored none for: its exact run computed again (the
    reference is deterministic, so these are the facts the run would have stored)."""
    found = facts_of(case, scenes.truth(case))
    assert found is not None  # a scene's truth always has positions, or why not
    return found


def read_facts(directory: Path) -> dict[str, SceneFacts]:
    """The stored facts of a run by case id, the last line of each; none when the run has no
    ``scene_facts.jsonl`` (a half-written last line is left out)."""
    path = directory / FILE
    found: dict[str, SceneFacts] = {}
    for line in jsonlines.parse_lines(path):  # a half-written last line is left out
        try:
            facts = SceneFacts.from_json(line)
        except (KeyError, TypeError, ValueError, AttributeError):
            continue  # a line cut where it still reads as JSON
        found[facts.case_id] = facts
    return found
