"""The engine's declared allowance for one quantity of one case: one rule for every quantity.

An engine declares its precision ``rtol`` (its arithmetic, relative to the numbers it
works on) and margins (absolute, at the feature where the bodies meet).  The allowance
of a quantity is what those declared numbers can do to it, and nothing else:

- ``distance``, ``normal``: the length margin at the nearest feature (``margins``) plus
  ``rtol x L``, ``L`` the case's largest length (|coordinate|, radius or half-width):
  every number the engine holds is off by up to ``rtol`` of it.  A normal gets the tilt
  that this length gives across the gap (:mod:`crosscheck.truth.categories`);
- ``hit``: the verdict's margin (``verdict_margins``: a prediction distance, a collision
  threshold) plus ``rtol x L``; a verdict threshold never acts on a distance or a normal;
- ``v1``, ``v2``: ``rtol_v x V`` (``V`` the largest |velocity component|; ``rtol_v`` the
  declared ``response_rtol``, else ``rtol``) plus the positional term: centres off by
  ``rtol x L`` each turn the line of centres ``D`` apart by up to ``2 rtol L / D`` rad,
  and a turn of the line by ``t`` changes a body's velocity by at most ``2 |va - vb| t``,
  so the term is ``2 |va - vb| min(1, 2 rtol L / D)``.  Margins never act on velocities.

So the same float32 rounding that blurs a distance at a 1e8 offset blurs the line of
centres of a response there, and both read alike.

>>> from crosscheck.core.contract import Conventions
>>> from crosscheck.testing.samples import sphere_pair
>>> str(allowance(sphere_pair(0.0, 2.5), Conventions(margins={"sphere": 0.01}), "distance"))
'declared tolerance 0.01 (margin 0.01 at a sphere + precision 0 x size 2.5)'
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import approach_speed as approach
from crosscheck.core.geometry import difference, norm
from crosscheck.core.schema import AabbCase, PairCase, ResponseCase

__all__ = ["Allowance", "allowance", "approach_speed", "length_scale", "nearest_feature",
           "positional", "touch_feature", "velocity_scale"]

VELOCITIES = ("v1", "v2")


def _finite_abs(xs: list[float]) -> list[float]:
    return [abs(x) for x in xs if math.isfinite(x)]


def length_scale(case: PairCase) -> float:
    """The size of the case's numbers: largest |coordinate|, radius or half-width."""
    nums = [*case.a.center, *case.b.center]
    nums += [*case.a.half, *case.b.half] if isinstance(case, AabbCase) else [
        case.a.radius, case.b.radius]
    return max(_finite_abs(nums), default=0.0)


def velocity_scale(case: PairCase) -> float:
    """Largest |velocity component| of a response case (0 for detection cases)."""
    if not isinstance(case, ResponseCase):
        return 0.0
    return max(_finite_abs([*case.a.velocity, *case.b.velocity]), default=0.0)


def approach_speed(case: ResponseCase) -> float:
    """Speed at which A and B approach along their line of centres (negative: separating)."""
    return approach(case.a.center, case.b.center, case.a.velocity, case.b.velocity)


def _features_apart(case: AabbCase, exact_touch: bool) -> int:
    def apart(ca: float, cb: float, ha: float, hb: float) -> bool:
        d, s = abs(Fraction(cb) - Fraction(ca)), Fraction(ha) + Fraction(hb)
        return d == s if exact_touch else d >= s
    return sum(apart(*x) for x in zip(case.a.center, case.b.center, case.a.half, case.b.half,
                                       strict=True))


def _feature(case: PairCase, axes: int) -> str:
    if not isinstance(case, AabbCase):
        return "sphere"
    if axes <= 1:
        return "face"
    return "edge" if axes == 2 and case.dim == 3 else "corner"


def touch_feature(case: PairCase) -> str:
    """Where two exactly touching bodies meet: ``sphere``, or a box ``face``/``edge``/``corner``.

    >>> from crosscheck.testing.samples import box_pair
    >>> touch_feature(box_pair([0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.5, 0.5]))
    'corner'
    """
    return _feature(case, _features_apart(case, True) if isinstance(case, AabbCase) else 0)


def nearest_feature(case: PairCase) -> str:
    """Where the bodies are nearest: ``sphere``, or the box ``face``, ``edge`` or ``corner``.

    A box pair separated (or touching) along one axis meets at a face, along two
    at an edge (a corner in 2-D), along three at a corner; overlapping boxes
    meet across a face.

    >>> from crosscheck.testing.samples import box_pair
    >>> nearest_feature(box_pair([0.0, 0.0], [0.5, 0.5], [2.0, 3.0], [0.5, 0.5]))
    'corner'
    >>> nearest_feature(box_pair([0.0, 0.0], [0.5, 0.5], [0.5, 0.2], [0.5, 0.5]))
    'face'
    """
    return _feature(case, _features_apart(case, False) if isinstance(case, AabbCase) else 0)


@dataclass(frozen=True, slots=True)
class Allowance:
    """An engine's declared tolerance for one quantity of one case, part by part.

    ``margin`` acts at ``feature`` (``verdict`` True: the verdict's threshold);
    ``rtol x size`` is the precision; ``positional`` (responses) what the length
    precision does to the line of centres, ``apart`` long.
    """

    margin: float
    feature: str
    rtol: float
    size: float
    verdict: bool = False
    positional: float = 0.0
    apart: float = math.nan

    @property
    def total(self) -> float:
        return self.margin + self.rtol * self.size + self.positional

    def __str__(self) -> str:
        kind = "verdict margin" if self.verdict else "margin"
        margin = f"{kind} {self.margin:.3g} at a {self.feature} + " if self.margin else ""
        where = (f" + {self.positional:.3g} from the centres' rounding across "
                 f"{self.apart:.3g}" if self.positional else "")
        return (f"declared tolerance {self.total:.3g} ({margin}precision "
                f"{self.rtol:.3g} x size {self.size:.3g}{where})")


def positional(case: ResponseCase, rtol: float) -> tuple[float, float]:
    """The positional term of a response's allowance and the centres' distance ``D``.

    >>> case = ResponseCase.model_validate({"id": "c", "kind": "sphere_response", "dim": 2,
    ...     "description": "3-4-5 at 1e8", "a": {"center": [1e8, 0], "radius": 2.5, "mass": 1,
    ...     "velocity": [1, 0]}, "b": {"center": [1e8 + 3, 4], "radius": 2.5, "mass": 1,
    ...     "velocity": [-1, 0]}})
    >>> positional(case, 2.0**-21)  # float32 at 1e8: the line of centres may turn freely
    (4.0, 5.0)
    >>> positional(case, 2.0**-52)[0] < 1e-7  # float64: it turns by 2e-8 rad at most
    True
    """
    apart = norm(difference(case.a.center, case.b.center))
    relative = norm(difference(case.a.velocity, case.b.velocity))
    if not (rtol > 0 and math.isfinite(relative)):
        return 0.0, apart
    turn = 2.0 * rtol * length_scale(case) / apart if apart > 0 else math.inf
    return 2.0 * relative * min(1.0, turn), apart


def allowance(case: PairCase, conv: Conventions, quantity: str) -> Allowance:
    """The declared tolerance of ``quantity`` (see the module docstring)."""
    if quantity in VELOCITIES:
        assert isinstance(case, ResponseCase)
        rtol = conv.rtol if conv.response_rtol is None else conv.response_rtol
        term, apart = positional(case, conv.rtol)
        return Allowance(0.0, "", rtol, velocity_scale(case), positional=term, apart=apart)
    feature = nearest_feature(case)
    if quantity == "hit":
        return Allowance(conv.verdict_margin_for(feature), feature, conv.rtol,
                         length_scale(case), verdict=True)
    return Allowance(conv.margin_for(feature), feature, conv.rtol, length_scale(case))
