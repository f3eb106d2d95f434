"""Published accuracy claims: what an engine's own documentation promises, and where.

An adapter variant declares its engine's claims (``Adapter.claims``), each a :class:`Claim`:
a quantity of the rows (``distance``, ``normal``, ``hit``, a scene's ``positions`` ...), the
case kinds it speaks of (the shape pair: ``sphere`` is sphere-sphere, ``aabb`` box-box), the
bound on the rows' ``error`` for that quantity, the regime the claim is made for (the bodies'
size, the true gap, the case blocks) and the source in the engine's own words.  The report and
``crosscheck engines --claims`` set each claim beside the suite's measurement: the worst error
on the cases inside its regime, the worst outside it, and whether the claim holds.

A claim is never an allowance: a row's label comes from the conventions alone; a claim is
checked against the labels' errors, not used to make them.

>>> c = Claim("distance", ("sphere",), 6e-15, "signed distance sphere-sphere",
...           "https://example.org", size=(0.1, 0.4))
>>> c.in_size(0.2), c.in_size(1.0), c.in_gap(-1.0)
(True, False, True)
>>> Claim.from_json(c.to_json()) == c
True
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

ALL = (-math.inf, math.inf)
"""An unbounded range."""


@dataclass(frozen=True, slots=True)
class Claim:
    """One published accuracy claim of an engine (see the module docstring).

    ``quantity`` a row quantity; ``kinds`` the case kinds it covers; ``bound`` the largest
    ``error`` the engine promises (in the quantity's error unit: m for a distance, radians for
    a normal, 0 or 1 for a verdict), times the case's size when ``relative``; ``statement``
    the claim as its source words it; ``source`` where (a URL, with the line or anchor).

    The regime (every condition must hold for a case to be inside it): ``size`` the range of
    the bodies' size (the largest radius or half-width of the case's bodies, m); ``gap`` the
    range of the true signed gap between the surfaces (m, negative: overlap; pair cases only);
    ``clear_of_touching`` the least |gap| (m) inside the regime (0: any); ``blocks`` the case
    blocks (a case's ``origin``, else its id, starting with one of them; empty: any); ``dims``
    the dimensions.
    """

    quantity: str
    kinds: tuple[str, ...]
    bound: float
    statement: str
    source: str
    size: tuple[float, float] = ALL
    gap: tuple[float, float] = ALL
    clear_of_touching: float = 0.0
    blocks: tuple[str, ...] = ()
    dims: tuple[int, ...] = (2, 3)
    relative: bool = False

    def __post_init__(self) -> None:
        if not self.bound >= 0:
            raise ValueError(f"claim {self.statement!r}: bound {self.bound} is not >= 0")
        for name in ("size", "gap"):
            lo, hi = getattr(self, name)
            if not lo <= hi:
                raise ValueError(f"claim {self.statement!r}: {name} range ({lo}, {hi}) is empty")

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

    def to_json(self) -> dict[str, Any]:
        """The claim as JSON data (run.json); infinities as strings."""
        out = asdict(self)
        for name in ("size", "gap"):
            out[name] = [_number(x) for x in out[name]]
        return out

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Claim:
        """The claim :meth:`to_json` wrote."""
        known = {f.name for f in fields(cls)}
        values = {k: v for k, v in data.items() if k in known}
        for name in ("size", "gap"):
            if name in values:
                values[name] = tuple(float(x) for x in values[name])
        for name in ("kinds", "blocks"):
            if name in values:
                values[name] = tuple(values[name])
        if "dims" in values:
            values["dims"] = tuple(int(x) for x in values["dims"])
        return cls(**values)


def _number(x: float) -> float | str:
    return x if math.isfinite(x) else ("inf" if x > 0 else "-inf")
