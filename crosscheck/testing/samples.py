"""The cases the conformance kit puts to an adapter: plain, unit-sized, far from every edge.

Each :class:`Sample` is a validated case and a label that says what it is and what the
textbook answers, so that a failure report names the case in words.  Bodies have radius
or half-width 0.5; B sits on the +x axis (or the -y axis) of A.

>>> overlap(Kind.SPHERE, 2).label
'sphere 2-D, B 0.75 from A along +x (overlap 0.25)'
>>> gap(Kind.AABB, 3, axis=1, sign=-1.0).case.b.center
(0.0, -1.5, 0.0)

Two builders make a pair anywhere, for examples and tests of the library (its doctests use
them): :func:`sphere_pair` puts two spheres on the x axis, :func:`box_pair` two boxes.

>>> sphere_pair(0.0, 2.0, dim=2).b.center
(2.0, 0.0)
>>> box_pair([0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.5, 0.5]).b.half
(0.5, 0.5)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from crosscheck.core.model import Kind
from crosscheck.core.schema import CASE_ADAPTER, AabbCase, AnyCase, SphereCase

AXES = "xyz"


@dataclass(frozen=True, slots=True)
class Sample:
    """A case and what it is, in words (for failure reports)."""

    label: str
    case: AnyCase
    axis: int = 0
    sign: float = 1.0
    """The direction from A's centre to B's: ``sign`` along axis ``axis``."""


def _at(dim: int, axis: int, value: float) -> list[float]:
    point = [0.0] * dim
    point[axis] = value
    return point


def _pair(kind: Kind, dim: int, case_id: str, b_center: list[float]) -> AnyCase:
    size = {"half": [0.5] * dim} if kind is Kind.AABB else {"radius": 0.5}
    return CASE_ADAPTER.validate_python({
        "id": case_id, "description": "conformance kit sample", "kind": str(kind), "dim": dim,
        "a": {"center": [0.0] * dim, **size}, "b": {"center": b_center, **size}})


def overlap(kind: Kind, dim: int) -> Sample:
    """A detection pair overlapping by 0.25 along +x: hit, distance -0.25, normal +x."""
    case = _pair(kind, dim, f"kit-{kind}-{dim}d-overlap", _at(dim, 0, 0.75))
    return Sample(f"{kind} {dim}-D, B 0.75 from A along +x (overlap 0.25)", case)


def gap(kind: Kind, dim: int, axis: int = 0, sign: float = 1.0) -> Sample:
    """A detection pair 0.5 apart along ``sign`` x axis ``axis``: no hit, distance 0.5."""
    direction = f"{'+' if sign > 0 else '-'}{AXES[axis]}"
    case = _pair(kind, dim, f"kit-{kind}-{dim}d-gap-{AXES[axis]}", _at(dim, axis, 1.5 * sign))
    return Sample(f"{kind} {dim}-D, B 1.5 from A along {direction} (gap 0.5)", case, axis, sign)


def head_on(dim: int) -> Sample:
    """Equal unit masses touching on the x axis and approaching at 1 each, e = 1."""
    body: dict[str, Any] = {"radius": 0.5, "mass": 1.0}
    case = CASE_ADAPTER.validate_python({
        "id": f"kit-response-{dim}d", "description": "conformance kit sample",
        "kind": "sphere_response", "dim": dim,
        "a": {**body, "center": [0.0] * dim, "velocity": _at(dim, 0, 1.0)},
        "b": {**body, "center": _at(dim, 0, 1.0), "velocity": _at(dim, 0, -1.0)}})
    return Sample(f"sphere_response {dim}-D, equal masses touching head-on along x at "
                  f"+1 and -1, e = 1", case)


def scene(dim: int) -> Sample:
    """Two equal spheres 2 apart approaching at 1 each, stepped for 2 s (dt 0.01, e = 1)."""
    body: dict[str, Any] = {"radius": 0.5, "mass": 1.0}
    case = CASE_ADAPTER.validate_python({
        "id": f"kit-scene-{dim}d", "description": "conformance kit sample",
        "kind": "sphere_scene", "dim": dim, "duration": 2.0, "dt": 0.01, "bodies": [
            {**body, "center": _at(dim, 0, -1.0), "velocity": _at(dim, 0, 1.0)},
            {**body, "center": _at(dim, 0, 1.0), "velocity": _at(dim, 0, -1.0)}]})
    return Sample(f"sphere_scene {dim}-D, two equal spheres head-on along x, 2 s at "
                  f"dt 0.01, e = 1", case)


def crossing(dim: int) -> Sample:
    """Two spheres (r 0.5) 2.5 apart closing at 1 each along x over [0, 1]: first contact at
    t = 0.75, normal +x (still overlapping at t = 1, so a sampling engine sees it there)."""
    case = CASE_ADAPTER.validate_python({
        "id": f"kit-toi-{dim}d", "description": "conformance kit sample", "kind": "sphere_toi",
        "dim": dim, "duration": 1.0,
        "a": {"center": _at(dim, 0, -1.0), "radius": 0.5, "velocity": _at(dim, 0, 1.0)},
        "b": {"center": _at(dim, 0, 1.5), "radius": 0.5, "velocity": _at(dim, 0, -1.0)}})
    return Sample(f"sphere_toi {dim}-D, two spheres closing head-on along x, first contact "
                  f"at t = 0.75 of [0, 1]", case)


def first(kind: Kind, dim: int) -> Sample:
    """The kit's main sample of a kind: the overlap, the head-on response, the time-of-impact
    crossing or the scene."""
    if kind is Kind.SPHERE_RESPONSE:
        return head_on(dim)
    if kind is Kind.SPHERE_TOI:
        return crossing(dim)
    if kind is Kind.SPHERE_SCENE:
        return scene(dim)
    return overlap(kind, dim)


def sphere_pair(a: float, b: float, ra: float = 0.5, rb: float = 0.5,
                dim: int = 3) -> SphereCase:
    """A sphere detection pair with A's centre at ``a`` and B's at ``b`` on the x axis, radii
    ``ra`` and ``rb``, in ``dim`` dimensions."""
    pad = [0.0] * (dim - 1)
    case = CASE_ADAPTER.validate_python({
        "id": "sphere-pair", "description": "two spheres on the x axis", "kind": "sphere",
        "dim": dim, "a": {"center": [a, *pad], "radius": ra},
        "b": {"center": [b, *pad], "radius": rb}})
    assert isinstance(case, SphereCase)
    return case


def box_pair(ca: list[float], ha: list[float], cb: list[float], hb: list[float]) -> AabbCase:
    """An AABB detection pair: A centred at ``ca`` with half-widths ``ha``, B at ``cb`` with
    ``hb`` (the dimension is ``len(ca)``)."""
    case = CASE_ADAPTER.validate_python({
        "id": "box-pair", "description": "two boxes", "kind": "aabb", "dim": len(ca),
        "a": {"center": ca, "half": ha}, "b": {"center": cb, "half": hb}})
    assert isinstance(case, AabbCase)
    return case
