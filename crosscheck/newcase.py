"""Templates for ``crosscheck new-case``: a valid block per kind and dimension, ready to edit."""

from __future__ import annotations

from crosscheck.model import Kind


def _vec(*xs: float) -> str:
    return "[" + ", ".join(repr(float(x)) for x in xs) + "]"


def case_block(kind: Kind, dim: int, case_id: str) -> str:
    """A ``[[case]]`` block for ``kind`` in ``dim`` dimensions: two unit bodies, just touching.

    >>> print(case_block(Kind.SPHERE, 2, "my-case").splitlines()[1])
    id = "my-case"
    """
    zeros = [0.0] * (dim - 1)
    ca, cb = _vec(0.0, *zeros), _vec(1.0, *zeros)
    lines = [
        "[[case]]",
        f'id = "{case_id}"',
        'description = "TODO: say what this case probes"',
        f'kind = "{kind}"',
        f"dim = {dim}",
        "tags = []",
    ]
    if kind is Kind.AABB:
        half = _vec(*([0.5] * dim))
        lines += [f"a = {{ center = {ca}, half = {half} }}  # half-widths",
                  f"b = {{ center = {cb}, half = {half} }}"]
    elif kind is Kind.SPHERE:
        lines += [f"a = {{ center = {ca}, radius = 0.5 }}",
                  f"b = {{ center = {cb}, radius = 0.5 }}"]
    else:
        va, vb = _vec(1.0, *zeros), _vec(-1.0, *zeros)
        lines += [f"a = {{ center = {ca}, radius = 0.5, mass = 1.0, velocity = {va} }}",
                  f"b = {{ center = {cb}, radius = 0.5, mass = 1.0, velocity = {vb} }}",
                  "restitution = 1.0"]
    return "\n".join(lines) + "\n"
