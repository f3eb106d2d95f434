"""Published accuracy claims: what an engine's own documentation promises, and where.

An adapter variant declares its engine's claims (``Adapter.claims``), each a :class:`Claim`:
a quantity of the rows (``distance``, ``normal``, ``hit``, a scene's ``positions`` ...), the
case kinds it speaks of (the shape pair: ``sphere`` is sphere-sphere, ``aabb`` box-box), the
bound on the rows' ``error`` for that quantity, the regime the claim is made for (the bodies'
size, the true gap, the case blocks) and the source in the engine's own words.  The report and
``crosscheck engines --claims`` set each claim beside the suite's measurement: the worst error
on the cases inside its regime, the worst outside it, and whether the claim holds.

A claim is never an allowance: a row's label comes from the conventions alone; a claim is
checked against the labels' errors, not used to make them.  The evaluation is
:mod:`crosscheck.report.claims`; :meth:`Claim.regime_words` and :meth:`Claim.bound_words`
are the claim in the words every table shows.

>>> c = Claim("distance", ("sphere",), 6e-15, "signed distance sphere-sphere",
...           "https://example.org", size=(0.1, 0.4))
>>> c.in_size(0.2), c.in_size(1.0), c.in_gap(-1.0)
(True, False, True)
>>> Claim.from_json(c.to_json()) == c
True
>>> c.regime_words(), c.bound_words()
('size 0.1 to 0.4 m', '6e-15 m')
>>> Claim("hit", ("aabb",), 0.0, "s", "u", gap=APART, clear_of_touching=0.005,
...       dims=(2,)).regime_words()
'gap > 0, |gap| >= 0.005 m, 2-D'
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any, Literal

from crosscheck.core.kinds import quantity_named

ALL = (-math.inf, math.inf)
"""An unbounded range."""
TINY = math.ulp(0.0)
"""The least positive float: a gap range starting (or ending) here leaves touching out."""
APART = (TINY, math.inf)
"""The gap range of separated pairs (gap > 0)."""
OVERLAP = (-math.inf, -TINY)
"""The gap range of overlapping pairs (gap < 0)."""


@dataclass(frozen=True, slots=True)
class Claim:
    """One published accuracy claim of an engine (see the module docstring).

    ``quantity`` a row quantity; ``kinds`` the case kinds it covers; ``bound`` the largest
    ``error`` the engine promises (in the quantity's error unit: m for a distance, radians for
    a normal, 0 or 1 for a verdict), times the case's size (or its length: ``relative_to``)
    when ``relative``; ``statement``
    the claim as its source words it; ``source`` where (a URL, with the line or anchor).

    The regime (every condition must hold for a case to be inside it): ``size`` the range of
    the bodies' size (the largest radius or half-width of the case's bodies, m); ``gap`` the
    range of the true signed gap between the surfaces (m, negative: overlap; pair cases only);
    ``clear_of_touching`` the least |gap| (m) inside the regime (0: any); ``offset`` the
    largest distance of the bodies' centres from the origin inside it (their largest
    |coordinate|, m; a float engine's documented working range); ``blocks`` the case blocks
    (a case's ``origin``, else its id, starting with one of them; empty: any); ``dims`` the
    dimensions.
    """

    quantity: str
    kinds: tuple[str, ...]
    bound: float
    statement: str
    source: str
    size: tuple[float, float] = ALL
    gap: tuple[float, float] = ALL
    clear_of_touching: float = 0.0
    offset: float = math.inf
    blocks: tuple[str, ...] = ()
    dims: tuple[int, ...] = (2, 3)
    relative: bool = False
    relative_to: Literal["size", "length"] = "size"
    """What a ``relative`` bound is multiplied by: ``size`` (the largest radius or half-width)
    or ``length`` (the largest |coordinate|, radius or half-width: the numbers a float
    engine holds, :func:`crosscheck.truth.allowance.length_scale`)."""

    def __post_init__(self) -> None:
        if not self.bound >= 0:
            raise ValueError(f"claim {self.statement!r}: bound {self.bound} is not >= 0")
        for name in ("size", "gap"):
            lo, hi = getattr(self, name)
            if not lo <= hi:
                raise ValueError(f"claim {self.statement!r}: {name} range ({lo}, {hi}) is empty")
        if not self.offset >= 0:
            raise ValueError(f"claim {self.statement!r}: offset {self.offset} is not >= 0")
        if self.relative_to not in ("size", "length"):
            raise ValueError(f"claim {self.statement!r}: relative_to {self.relative_to!r} is "
                             "neither 'size' nor 'length'")

    def in_size(self, size: float) -> bool:
        """Whether bodies of ``size`` are inside the claim's size range."""
        return self.size[0] <= size <= self.size[1]

    def in_gap(self, gap: float) -> bool:
        """Whether the true gap ``gap`` is inside the claim's gap range and clear of touching."""
        return self.gap[0] <= gap <= self.gap[1] and abs(gap) >= self.clear_of_touching

    def in_block(self, block: str) -> bool:
        """Whether a case of block (or id) ``block`` is one the claim speaks of."""
        return not self.blocks or block.startswith(self.blocks)

    def limit(self, size: float) -> float:
        """The bound for a case of ``size``: ``bound``, times the size when ``relative``."""
        return self.bound * size if self.relative else self.bound

    @property
    def unit(self) -> str:
        """The unit of the quantity's error (:attr:`crosscheck.core.kinds.Quantity.unit`), the
        unit of :attr:`bound`; '' for a quantity no kind scores."""
        try:
            return quantity_named(self.quantity).unit
        except KeyError:
            return ""

    def bound_words(self) -> str:
        """The bound in words: ``1e-06 m``, ``0 (no wrong verdict)``, ``4.77e-07 x size``."""
        if self.quantity == "hit":
            return "0 (no wrong verdict)" if self.bound == 0 else f"{self.bound:.3g} wrong"
        if self.relative:
            return f"{self.bound:.3g} x {self.relative_to}"
        return f"{self.bound:.3g} {self.unit}".strip()

    def regime_words(self) -> str:
        """The regime in words ('any case' when it has no condition)."""
        parts = []
        if self.size != ALL:
            parts.append(f"size {_range(self.size)} m")
        if self.gap == APART:
            parts.append("gap > 0")
        elif self.gap == OVERLAP:
            parts.append("gap < 0")
        elif self.gap != ALL:
            parts.append(f"gap {_range(self.gap)} m")
        if self.clear_of_touching > 0:
            parts.append(f"|gap| >= {self.clear_of_touching:.3g} m")
        if math.isfinite(self.offset):
            parts.append(f"centres within {self.offset:.3g} m of the origin")
        if self.blocks:
            parts.append("blocks " + ", ".join(f"{b}*" for b in self.blocks))
        if tuple(sorted(self.dims)) != (2, 3):
            parts.append("/".join(f"{d}-D" for d in self.dims))
        return ", ".join(parts) or "any case"

    def to_json(self) -> dict[str, Any]:
        """The claim as JSON data (run.json); infinities as strings."""
        out = asdict(self)
        for name in ("size", "gap"):
            out[name] = [_number(x) for x in out[name]]
        out["offset"] = _number(self.offset)
        return out

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Claim:
        """The claim :meth:`to_json` wrote."""
        known = {f.name for f in fields(cls)}
        values = {k: v for k, v in data.items() if k in known}
        for name in ("size", "gap"):
            if name in values:
                values[name] = tuple(float(x) for x in values[name])
        if "offset" in values:
            values["offset"] = float(values["offset"])
        for name in ("kinds", "blocks"):
            if name in values:
                values[name] = tuple(values[name])
        if "dims" in values:
            values["dims"] = tuple(int(x) for x in values["dims"])
        return cls(**values)


def _range(bounds: tuple[float, float]) -> str:
    lo, hi = bounds
    if math.isinf(lo):
        return f"<= {hi:.3g}"
    if math.isinf(hi):
        return f">= {lo:.3g}"
    return f"{lo:.3g} to {hi:.3g}"


def _number(x: float) -> float | str:
    return x if math.isfinite(x) else ("inf" if x > 0 else "-inf")
