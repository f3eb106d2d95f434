"""``crosscheck new-case``: write one complete, valid ``[[case]]`` block.

Without geometry options the block is a template (two unit bodies just
touching) to edit; with them (``--a-center 0,0,0 --a-radius 0.5 ...``) one
command writes the finished case.  Floats are written with ``repr``, so every
binary value round-trips exactly.

>>> print(case_block(Kind.SPHERE, 2, "my-case").splitlines()[1])
id = "my-case"
>>> body = {"center": (0.0, 1e-300), "radius": 0.1}
>>> inline(body)
'{ center = [0.0, 1e-300], radius = 0.1 }'
"""

from __future__ import annotations

import json
import math
from typing import Any

from crosscheck.model import Kind

Body = dict[str, Any]


def _number(x: float) -> str:
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(float(x))


def _value(value: Any) -> str:
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_number(x) for x in value) + "]"
    if isinstance(value, str):
        return json.dumps(value)
    return _number(value)


def inline(body: Body) -> str:
    """A body as a TOML inline table, keys in the given order."""
    return "{ " + ", ".join(f"{key} = {_value(v)}" for key, v in body.items()) + " }"


def default_bodies(kind: Kind, dim: int) -> tuple[Body, Body]:
    """Two unit bodies just touching along +x (approaching, for responses)."""
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
    return a, b


def case_block(kind: Kind, dim: int, case_id: str, *, description: str | None = None,
               tags: list[str] | None = None, a: Body | None = None, b: Body | None = None,
               restitution: float | None = None) -> str:
    """A ``[[case]]`` block; bodies default to :func:`default_bodies`, overridden key by key."""
    base_a, base_b = default_bodies(kind, dim)
    lines = [
        "[[case]]",
        f"id = {json.dumps(case_id)}",
        f"description = {json.dumps(description or 'TODO: say what this case probes')}",
        f'kind = "{kind}"',
        f"dim = {dim}",
        f"tags = {json.dumps(tags or [])}",
        f"a = {inline(base_a | (a or {}))}",
        f"b = {inline(base_b | (b or {}))}",
    ]
    if kind is Kind.SPHERE_RESPONSE:
        lines.append(f"restitution = {_number(1.0 if restitution is None else restitution)}")
    return "\n".join(lines) + "\n"
