"""The declared rules of a stepped response that differ from the textbook's single impulse.

:func:`convention` gives the rule (category ``convention``) that fires on a response
case, in this order, with its numbers:

- a body of mass 0 made static (``zero_mass "static"``);
- bodies already separating left alone (``resolves_separating`` False);
- an approach slower than the restitution threshold: the bounce is inelastic;
- a speed cap (``max_speed``): the answer is the textbook's with the cap applied where
  the engine declares it acts, ``"step"`` (each body's velocity at the end of the
  step: Box2D's ``b2_maxTranslation`` per step), ``"per coordinate"`` (each velocity
  coordinate at the end of the step: PyBullet's multibody clamp) or
  ``"before restitution"`` (after the contact solve, before the bounce is added:
  Rapier's cap after each solver substep, its restitution an end-of-step pass) or
  ``"before the contact solve"`` (on the velocities the solve starts from, the bounce
  taken from the uncapped approach: Box2D v3's clamp in each sub-step's velocity
  integration).  It fires only when the answer is that one, within the engine's allowance.

:func:`missed` is a time-step rule (category ``timestep``): an engine that looks for
contacts only at the start of each step and pushes only bodies that overlap there
(``sampled_contacts``) never sees a contact whose overlap falls between two step starts;
it applies no force, and the answer is the bodies' own velocities.

>>> from crosscheck.core.contract import Conventions
>>> from crosscheck.core.schema import ResponseCase
>>> case = ResponseCase.model_validate({"id": "c", "kind": "sphere_response", "dim": 2,
...     "description": "touching, A fast", "a": {"center": [0, 0], "radius": 0.5, "mass": 1,
...     "velocity": [3000, 0]}, "b": {"center": [1, 0], "radius": 0.5, "mass": 1,
...     "velocity": [0, 0]}})
>>> box2d = Conventions(max_speed=2000.0, max_speed_at="step")
>>> met = Observation(resolved_at=((0.0, 0.0), (1.0, 0.0)))  # resolved in the first step
>>> convention(case, box2d, "v2", (2000.0, 0.0), met, 1e-3)[:53]
"A's speed 3e+03 is above the engine's speed cap 2000 "
>>> convention(case, box2d, "v2", (3000.0, 0.0), met, 1e-3)  # not the capped answer
''
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, difference, dot, norm
from crosscheck.core.model import Observation, Value
from crosscheck.core.schema import ResponseCase
from crosscheck.truth import oracle
from crosscheck.truth.allowance import approach_speed
from crosscheck.truth.bounds import error_of

__all__ = ["CASE_RULES", "case_rule", "convention", "missed"]


def convention(case: ResponseCase, conv: Conventions, quantity: str, value: Value,
               observation: Observation, tolerance: float) -> str:
    """The declared rule that explains the engine's answer ('' if none does)."""
    for rule in CASE_RULES.values():
        reason = rule(case, conv)
        if reason:
            return reason
    return _speed_cap(case, conv, quantity, value, observation, tolerance)


def _zero_mass(case: ResponseCase, conv: Conventions) -> str:
    zero = [side for side, body in (("A", case.a), ("B", case.b)) if body.mass == 0]
    if not (zero and conv.zero_mass == "static"):
        return ""
    return (f"body {zero[0]} has mass 0: the engine makes it static (immovable), the "
            "textbook gives it no inertia")


def _separating(case: ResponseCase, conv: Conventions) -> str:
    speed = approach_speed(case)
    if not (speed <= 0 and not conv.resolves_separating):
        return ""
    return (f"bodies already separating (approach speed {speed:.3g} <= 0): the engine "
            "leaves them alone, the textbook exchanges momentum regardless")


def _below_threshold(case: ResponseCase, conv: Conventions) -> str:
    speed = approach_speed(case)
    if not 0 < speed < conv.restitution_threshold:
        return ""
    return (f"approach speed {speed:.9g} below the engine's restitution threshold "
            f"{conv.restitution_threshold:.9g}: the bounce is inelastic")


CASE_RULES: dict[str, Callable[[ResponseCase, Conventions], str]] = {
    "zero_mass": _zero_mass, "resolves_separating": _separating,
    "restitution_threshold": _below_threshold}
"""The rules that fire on the case and the conventions alone, in the order they are tried,
each under the convention (a field of :class:`Conventions`) it reads; the speed cap
(``max_speed``), which reads the engine's answer too, comes after them."""


def case_rule(case: ResponseCase, conv: Conventions) -> str:
    """The convention of the first of :data:`CASE_RULES` that fires on ``case`` ('' none)."""
    return next((name for name, rule in CASE_RULES.items() if rule(case, conv)), "")


# --- the speed cap -------------------------------------------------------------------------


AFTER_STEP = ("step", "per coordinate")
"""The cap stages that act on the velocities at the end of every step (after the bounce)."""


def _at_contact(case: ResponseCase, observation: Observation, conv: Conventions,
                cap: float) -> ResponseCase:
    """The case as the engine met its contact: at ``resolved_at``, and, unless the contact
    was resolved in the first step, with the velocities that free steps capped."""
    start = (case.a.center, case.b.center)
    at = observation.resolved_at
    first = at is not None and (tuple(at[0]), tuple(at[1])) == start
    pa, pb = (at[0], at[1]) if at is not None else start
    va, vb = ((case.a.velocity, case.b.velocity) if first else
              (conv.clip(case.a.velocity, cap), conv.clip(case.b.velocity, cap)))
    return case.model_copy(update={
        "a": case.a.model_copy(update={"center": tuple(pa), "velocity": tuple(va)}),
        "b": case.b.model_copy(update={"center": tuple(pb), "velocity": tuple(vb)})})


def _capped_response(met: ResponseCase, conv: Conventions, cap: float) -> tuple[Vec, Vec] | None:
    """The textbook's response with the cap applied where the engine declares it acts."""
    if conv.max_speed_at in AFTER_STEP:
        done = oracle.truth(met)
        if not (isinstance(done.v1, tuple) and isinstance(done.v2, tuple)):
            return None
        return conv.clip(done.v1, cap), conv.clip(done.v2, cap)
    first = met  # "before the contact solve": the solve starts from the capped velocities
    if conv.max_speed_at == "before the contact solve":
        first = met.model_copy(update={
            "a": met.a.model_copy(update={"velocity": conv.clip(met.a.velocity, cap)}),
            "b": met.b.model_copy(update={"velocity": conv.clip(met.b.velocity, cap)})})
    plastic = oracle.truth(first.model_copy(update={"restitution": 0.0}))
    ma, mb = met.a.mass, met.b.mass
    line = difference(met.a.center, met.b.center)
    length = norm(line)
    if not (isinstance(plastic.v1, tuple) and isinstance(plastic.v2, tuple) and length > 0
            and all(math.isfinite(m) and m > 0 for m in (ma, mb))):
        return None
    n = tuple(x / length for x in line)
    bounce = met.restitution * approach_speed(met)
    va = tuple(x - mb / (ma + mb) * bounce * k for x, k in zip(conv.clip(plastic.v1, cap), n,
                                                                strict=True))
    vb = tuple(x + ma / (ma + mb) * bounce * k for x, k in zip(conv.clip(plastic.v2, cap), n,
                                                                strict=True))
    return va, vb


def _speed_cap(case: ResponseCase, conv: Conventions, quantity: str, value: Value,
               observation: Observation, tolerance: float) -> str:
    cap = conv.max_speed
    if cap is None or not isinstance(value, tuple):
        return ""
    textbook = oracle.truth(case)
    speeds = {"A": _speed(conv, case.a.velocity), "B": _speed(conv, case.b.velocity)}
    if conv.max_speed_at in AFTER_STEP and isinstance(textbook.v1, tuple) and isinstance(
            textbook.v2, tuple):
        speeds = {side: max(speeds[side], _speed(conv, v))
                  for side, v in (("A", textbook.v1), ("B", textbook.v2))}
    side, fastest = max(speeds.items(), key=lambda kv: kv[1])
    if not fastest > cap:
        return ""
    want = _capped_response(_at_contact(case, observation, conv, cap), conv, cap)
    if want is None:
        return ""
    err = error_of(quantity, value, want[0] if quantity == "v1" else want[1])
    if not err <= tolerance:
        return ""
    when = ("after the textbook's response " if conv.max_speed_at in AFTER_STEP and
            fastest > _speed(conv, (case.a if side == "A" else case.b).velocity) else "")
    return (f"{side}'s speed {fastest:.3g} {when}is above the engine's speed cap {cap:.6g} "
            f"(declared; it acts {_WHERE[conv.max_speed_at]}): the answer is the textbook's "
            f"with the cap applied there (error {err:.3g} against that)")


def _speed(conv: Conventions, v: Vec) -> float:
    """What the cap compares: the largest |coordinate| for a cap per coordinate, the norm
    otherwise."""
    if conv.max_speed_at == "per coordinate":
        return max((abs(x) for x in v), default=0.0)
    return norm(v)


_WHERE = {"step": "on each body's velocity at the end of every step",
          "per coordinate": "on each velocity coordinate at the end of every step",
          "before restitution": "after the contact solve, before the bounce is added",
          "before the contact solve": "on the velocities the contact solve starts from, the "
                                      "bounce taken from the uncapped approach"}


# --- a contact between two steps -------------------------------------------------------------


def _overlap(case: ResponseCase) -> tuple[float, float] | None:
    """When the freely moving spheres overlap: the open interval of times (None: never)."""
    p = difference(case.a.center, case.b.center)
    w = difference(case.a.velocity, case.b.velocity)
    reach = case.a.radius + case.b.radius
    a, b, c = dot(w, w), dot(p, w), dot(p, p) - reach * reach
    disc = b * b - a * c
    if not (a > 0 and disc > 0 and math.isfinite(disc)):
        return None
    root = math.sqrt(disc)
    return (-b - root) / a, (-b + root) / a


def _apart_at_start(case: ResponseCase) -> bool:
    """Whether the spheres do not overlap at the case's start (exactly)."""
    gap = [Fraction(y) - Fraction(x) for x, y in zip(case.a.center, case.b.center, strict=True)]
    reach = Fraction(case.a.radius) + Fraction(case.b.radius)
    return sum(g * g for g in gap) >= reach * reach


def missed(case: ResponseCase, conv: Conventions, quantity: str, value: Value,
           observation: Observation, tolerance: float, declared_err: float) -> str:
    """Why the engine rightly applied no force: the contact fell between two steps ('' if
    the rule does not fire, or the answer is not the bodies' own velocities)."""
    dt = conv.time_step
    if not (conv.sampled_contacts and dt and observation.resolved_at is None
            and isinstance(value, tuple)):
        return ""
    when = _overlap(case)
    if when is None or not _apart_at_start(case):
        return ""
    start, end = when
    first = max(1, math.floor(start / dt) + 1)  # the first step start after the overlap began
    if first * dt < end:
        return ""  # a step starts inside the overlap: the engine sees the contact
    own = case.a.velocity if quantity == "v1" else case.b.velocity
    err = error_of(quantity, value, own)
    if not err <= tolerance:
        return ""
    return (f"the spheres overlap only from t = {max(start, 0.0):.3g} s to {end:.3g} s and no "
            f"step of {dt:.3g} s starts in between (declared: the engine looks for contacts at "
            f"the start of each step and pushes only overlapping bodies), so no force acts: "
            f"the answer is the body's own velocity (error {err:.3g} against it); against the "
            f"case as declared the error is {declared_err:.3g}")
