"""New cases from the command line: one complete, valid ``[[case]]`` block, appended to a file.

Without geometry the block is a template (two unit bodies just touching) to
edit; without a description it says TODO, which ``crosscheck validate`` rejects
until the author replaces it; with it (``a={"center": [0, 0, 0], "radius": 0.5}, ...``) the finished
case.  The text goes through the one TOML writer (:mod:`crosscheck.cases.writer`),
so every binary value round-trips exactly, and the block is loaded and checked
before anything is written.

>>> print(new_block("sphere", 2, "my-case").splitlines()[1])
id = "my-case"
>>> print(new_block("sphere", 2, "my-case", a={"center": [0.0, 1e-300]}).splitlines()[-2])
a = { center = [0.0, 1e-300], radius = 0.5 }
"""

from __future__ import annotations

import re
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from crosscheck.cases.load import load_paths
from crosscheck.cases.writer import SCHEMA_LINE, literal
from crosscheck.core.kinds import NEW_CASE_KINDS
from crosscheck.core.model import Kind
from crosscheck.core.schema import ID_PATTERN, case_class

Body = dict[str, Any]


class NewCaseError(ValueError):
    """The new case cannot be written; ``problems`` says why, one line each."""

    def __init__(self, problems: Sequence[str]) -> None:
        super().__init__("; ".join(problems))
        self.problems = list(problems)


def default_bodies(kind: Kind, dim: int) -> tuple[Body, Body]:
    """Two unit bodies just touching along +x (approaching, for responses; for a time of
    impact, one diameter apart and closing so that they touch at t = 0.5)."""
    pad = [0.0] * (dim - 1)
    a: Body = {"center": [0.0, *pad]}
    b: Body = {"center": [1.0, *pad]}
    if kind is Kind.AABB:
        a["half"], b["half"] = [0.5] * dim, [0.5] * dim
    else:
        a["radius"], b["radius"] = 0.5, 0.5
    if kind is Kind.SPHERE_RESPONSE:
        a |= {"mass": 1.0, "velocity": [1.0, *pad]}
        b |= {"mass": 1.0, "velocity": [-1.0, *pad]}
    if kind is Kind.SPHERE_TOI:  # apart by one diameter, meeting half-way through [0, 1]
        b["center"] = [2.0, *pad]
        a |= {"velocity": [1.0, *pad]}
        b |= {"velocity": [-1.0, *pad]}
    return a, b


def new_block(kind: str, dim: int, case_id: str, *, description: str | None = None,
              tags: Sequence[str] | None = None, a: Mapping[str, Any] | None = None,
              b: Mapping[str, Any] | None = None, restitution: float | None = None,
              duration: float | None = None) -> str:
    """A ``[[case]]`` block; bodies default to :func:`default_bodies`, overridden key by key.

    >>> print(new_block("sphere_toi", 2, "t").splitlines()[6])
    duration = 1.0
    """
    base_a, base_b = default_bodies(Kind(kind), dim)
    fields: dict[str, Any] = {
        "id": case_id, "description": description or "TODO: say what this case probes",
        "kind": kind, "dim": dim, "tags": list(tags or []),
        "a": base_a | dict(a or {}), "b": base_b | dict(b or {})}
    if Kind(kind) is Kind.SPHERE_RESPONSE:
        fields["restitution"] = 1.0 if restitution is None else restitution
    if Kind(kind) is Kind.SPHERE_TOI:
        fields = {**dict(list(fields.items())[:5]), "duration": 1.0 if duration is None
                  else duration, **dict(list(fields.items())[5:])}
    return "\n".join(["[[case]]", *(f"{k} = {literal(v)}" for k, v in fields.items())]) + "\n"


def _problems(text: str) -> list[str]:
    """What is wrong with the block, but its template TODO (for the author to fill in)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "new.toml"
        path.write_text(text, encoding="utf-8")
        return [f"the new case would be invalid: {e.message.replace(f'{path}: ', '')}"
                for e in load_paths([path]).errors if e.field != "description"]


def body_keys(kind: str) -> frozenset[str]:
    """The body fields a kind of new case takes (``--a-<field>``, ``--b-<field>``): those of
    its schema's body A.

    >>> sorted(body_keys("sphere_toi"))
    ['center', 'radius', 'velocity']
    """
    body = case_class(kind).model_fields["a"].annotation
    return frozenset(body.model_fields) if isinstance(body, type) and issubclass(
        body, BaseModel) else frozenset()


VECTORS = frozenset({"center", "half", "velocity"})
"""Body fields that are vectors of ``dim`` numbers (the others are one number)."""


def _option_problems(kind: str, dim: int, case_id: str, a: Mapping[str, Any],
                     b: Mapping[str, Any], restitution: float | None,
                     duration: float | None = None) -> list[str]:
    """Each option that is malformed or does not apply to the kind, named as on the command line.

    >>> for problem in _option_problems("aabb", 2, "x", {"radius": 1.0, "center": [1.0]},
    ...                                 {}, 0.5):
    ...     print(problem)
    --a-center needs 2 numbers (--dim 2), got 1
    --a-radius applies to sphere, sphere_response, sphere_toi cases only, not aabb
    --restitution applies to sphere_response cases only, not aabb
    """
    problems = [] if re.fullmatch(ID_PATTERN, case_id) else [
        f"id {case_id!r} must match {ID_PATTERN}"]
    for side, body in (("a", a), ("b", b)):
        for key, value in body.items():
            option = f"--{side}-{key}"
            if key not in body_keys(kind):
                kinds = [k for k in NEW_CASE_KINDS if key in body_keys(k)]
                problems.append(f"{option} applies to {', '.join(kinds)} cases only, not {kind}")
            elif key in VECTORS and len(value) != dim:
                problems.append(f"{option} needs {dim} numbers (--dim {dim}), got {len(value)}")
    if restitution is not None and Kind(kind) is not Kind.SPHERE_RESPONSE:
        problems.append(f"--restitution applies to sphere_response cases only, not {kind}")
    if duration is not None and Kind(kind) is not Kind.SPHERE_TOI:
        problems.append(f"--duration applies to sphere_toi cases only, not {kind}")
    return sorted(problems)


def append_case(path: Path, kind: str, dim: int, case_id: str, *,
                description: str | None = None, tags: Sequence[str] | None = None,
                a: Mapping[str, Any] | None = None, b: Mapping[str, Any] | None = None,
                restitution: float | None = None, duration: float | None = None) -> str:
    """Check the new case, then append it to ``path`` (created with the schema line); its text.

    Raises :class:`NewCaseError` (nothing written) for a bad id, an id already
    used under ``cases/`` or in ``path``, an option that does not apply to the
    kind, or a block that would not validate.
    """
    problems = _option_problems(kind, dim, case_id, a or {}, b or {}, restitution, duration)
    if problems:
        raise NewCaseError(problems)
    existing = load_paths([p for p in (Path("cases"), path) if p.exists()])
    if any(case.id == case_id for case in existing.cases):
        raise NewCaseError([f"id {case_id!r} is already used"])
    text = new_block(kind, dim, case_id, description=description, tags=tags, a=a, b=b,
                     restitution=restitution, duration=duration)
    problems = _problems(text)
    if problems:
        raise NewCaseError(problems)
    path.parent.mkdir(parents=True, exist_ok=True)
    prefix = "\n" if path.exists() else f"{SCHEMA_LINE}\n\n"
    with path.open("a", encoding="utf-8") as handle:
        handle.write(prefix + text)
    return text
