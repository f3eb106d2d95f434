"""What each of ``advise``'s options applies to: the kinds a limit bounds, and the unit of every
quantity with the tolerance option that states it.

A limit of the envelope (``--speed``, ``--dt`` ...) bounds the cases of the kinds that have
that dimension (:data:`KIND_OPTIONS`) and leaves the other kinds' cases alone; asked of no
kind that has it, it is refused.  A tolerance carries its unit: each quantity is judged with
the tolerance of its unit (:data:`UNITS`, :data:`TOLERANCE_OPTIONS`), and a tolerance no
asked quantity is measured in is refused.

>>> UNITS["distance"], UNITS["normal"], UNITS["v1"], UNITS["toi"], UNITS["energy_drift"]
('m', 'rad', 'm/s', 's', 'fraction')
>>> refused_limit("--mass-ratio", ("aabb",))[:68]
'bounds the mass ratio max(m)/min(m) of sphere_response and sphere_sc'
>>> refused_limit("--mass-ratio", ("aabb",))[68:]
'ene cases; the asked kinds (aabb) have none (--kind sphere_response asks for them)'
>>> refused_tolerance("m", ("v1", "v2"))
'is in m (hit, distance, settle); no asked quantity is (v1, v2: m/s, --velocity-tolerance)'
"""

from __future__ import annotations

from collections.abc import Iterable

from crosscheck.core.kinds import (
    ANGLE,
    FRACTION,
    LENGTH,
    SPECS,
    TIME,
    VELOCITY,
    every_quantity,
    quantities_of,
)

TOLERANCE_OPTIONS: dict[str, str] = {
    LENGTH: "--tolerance", ANGLE: "--angle-tolerance", VELOCITY: "--velocity-tolerance",
    TIME: "--time-tolerance", FRACTION: "--fraction-tolerance"}
"""The option that states the tolerance of each unit (``--rtol`` adds one relative to the
body size, on lengths)."""

UNITS: dict[str, str] = {q.name: q.unit for unit in TOLERANCE_OPTIONS for q in every_quantity()
                         if q.unit == unit}
"""Each quantity's unit: what its error is measured in (its spec's, :mod:`crosscheck.core.kinds`;
a ``hit`` verdict is judged by the pair's exact |gap|, a length), by unit in the order of
:data:`TOLERANCE_OPTIONS`."""

LIMITS: dict[str, str] = {
    "speed": "the speed |v| of every body",
    "mass_ratio": "the mass ratio max(m)/min(m)",
    "duration": "the simulated time",
    "dt": "the time step",
    "step_travel": "the per-step travel |vb - va| dt / 2(ra + rb) of the fastest pair",
    "interval": "the interval's length",
    "touching_contact": "whether exact touching counts as contact",
}
"""The dimensions of the envelope that some kinds only have (:attr:`KindSpec.limits
<crosscheck.core.kinds.KindSpec.limits>`), and what a limit bounds there."""
KIND_OPTIONS: dict[str, tuple[tuple[str, ...], str]] = {
    f"--{limit.replace('_', '-')}": (tuple(str(s.kind) for s in SPECS if limit in s.limits), what)
    for limit, what in LIMITS.items()}
"""The options that apply to some kinds only: the kinds (in report order), and what the option
bounds there."""


def kind_quantities(kinds: Iterable[str]) -> tuple[str, ...]:
    """Every quantity of ``kinds``, in report order."""
    return tuple(dict.fromkeys(q for kind in kinds for q in quantities_of(kind)))


def refused_limit(option: str, kinds: tuple[str, ...]) -> str | None:
    """Why ``option`` cannot apply to ``kinds`` (None: it applies to one of them)."""
    applies, what = KIND_OPTIONS[option]
    if set(applies) & set(kinds):
        return None
    return (f"bounds {what} of {' and '.join(applies)} cases; the asked kinds "
            f"({', '.join(kinds)}) have none (--kind {applies[0]} asks for them)")


def refused_tolerance(unit: str, quantities: tuple[str, ...]) -> str | None:
    """Why a tolerance in ``unit`` judges none of ``quantities`` (None: it does)."""
    if any(UNITS[q] == unit for q in quantities):
        return None
    measured = ", ".join(q for q, u in UNITS.items() if u == unit)
    asked = "; ".join(f"{', '.join(q for q in quantities if UNITS[q] == u)}: {u}, "
                      f"{TOLERANCE_OPTIONS[u]}"
                      for u in dict.fromkeys(UNITS[q] for q in quantities))
    return f"is in {unit} ({measured}); no asked quantity is ({asked})"
