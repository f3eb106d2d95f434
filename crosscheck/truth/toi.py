"""Times of impact (kind ``sphere_toi``): the exact truth, the agree bounds and the categories.

Two spheres move with constant velocities over ``[0, T]`` (``T`` the case's
``duration``).  The truth is :func:`reference_impl.toi.time_of_impact`: whether they
touch in the closed interval (``hit``), the first contact time correctly rounded
(``toi``) and the unit normal from A's centre to B's then (``normal``).  Without a
hit, ``toi`` and ``normal`` have no value (``undefined`` rows).

**Agree bounds** (what float64 allows).  A float64 solver rounds ``dp = cb - ca``
and ``dv = vb - va`` and the coefficients of ``f(t) = |dp + dv t|**2 - R**2``; each
coefficient is off by a few ``u`` of the magnitudes it combines, so ``f`` near the
root by ``u S`` with ``S = (|dv| t + |dp|)**2 + R**2``.  The root moves by that over
the slope ``|f'(t)| = 2 sqrt(disc)``; at a graze (``disc`` near 0) by at most
``sqrt(u S / a)`` (``a = |dv|**2``).  So ``toi`` agrees within
``K_TOI u (t + min(S / (2 sqrt(disc)), sqrt(S / (K_TOI u a))))``, and the normal within
``K_ANGLE u`` plus the tilt that time error gives it, ``|dv| dt / R`` (and ``u`` of the
lengths it divides).  ``hit`` is right or wrong.

**Categories**, from declared conventions only:

- ``convention``: the engine declares a target separation for its time of impact
  (``toi_target``: Box2D stops at an overlap of ``3 linearSlop``), and at the time it
  reported the exact surfaces are within ``toi_tolerance`` of it; or it reports no
  contact for a pair that never reaches that overlap;
- ``tolerance``: the same with no target (``toi_target`` 0), within the declared
  ``toi_tolerance`` or the engine's precision ``rtol`` on the case's numbers;
- ``tolerance`` also: a time within the declared ``toi_time_tolerance`` (a fraction of
  the interval) of the exact one;
- ``timestep``: an engine that samples the interval (``toi_samples`` evenly spaced
  discrete tests, 2 for the two ends) reported the first sample that overlaps, or saw
  no contact because it fell between its samples (a sample within the engine's precision
  of touching may round either way: a pair touching at the start can read apart there);
- ``convention`` also: no contact for a first touch exactly at the interval's end, by an
  engine that declares the end excluded (``toi_end_excluded``);
- ``error``: none of these.  A normal gets the category of its time when it is right
  for the time the engine reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import (
    Category,
    Kind,
    Observation,
    Status,
    Undefined,
    Value,
    quantities_of,
)
from crosscheck.core.schema import ToiCase
from crosscheck.truth.bounds import K_ANGLE, TINY, U, error_of, failed, is_unit
from reference_impl.toi import time_of_impact

CONVENTIONS = ("toi_target", "touching", "toi_end_excluded")
"""The declared conventions whose rules make a disagreement a ``convention`` (see the module
docstring; fields of :class:`~crosscheck.core.conventions.Conventions`)."""
K_TOI = 16
"""Operation-count factor of the time bound (a dozen roundings of ``f``, with room)."""
NO_CONTACT = "no contact in the interval"
"""The reason of ``toi`` and ``normal`` without a contact (the truth's and the engines')."""


def no_contact() -> Observation:
    """The answer without a contact in the interval: ``toi`` and ``normal`` have no value."""
    return Observation(hit=False, toi=Undefined(NO_CONTACT), normal=Undefined(NO_CONTACT))


def truth(case: ToiCase) -> Observation:
    """The exact first contact of ``case`` in ``[0, duration]``."""
    a, b = case.a, case.b
    try:
        impact = time_of_impact(a.center, a.velocity, a.radius, b.center, b.velocity,
                                b.radius, case.duration)
    except ValueError as exc:
        return Observation.undefined(quantities_of(Kind.SPHERE_TOI), str(exc))
    if not impact.hit:
        return no_contact()
    normal = (Undefined("the centres coincide at contact") if impact.normal is None
              else impact.normal)
    return Observation(hit=True, toi=impact.toi, normal=normal)


@dataclass(frozen=True, slots=True)
class Motion:
    """The relative motion of B seen from A, in float64: ``d(t) = dp + dv t``, ``R``."""

    dp: Vec
    dv: Vec
    radius: float

    @classmethod
    def of(cls, case: ToiCase) -> Motion:
        dp = tuple(y - x for x, y in zip(case.a.center, case.b.center, strict=True))
        dv = tuple(y - x for x, y in zip(case.a.velocity, case.b.velocity, strict=True))
        return cls(dp, dv, case.a.radius + case.b.radius)

    def at(self, t: float) -> Vec:
        return tuple(p + v * t for p, v in zip(self.dp, self.dv, strict=True))

    def gap(self, t: float) -> float:
        """The distance between the surfaces at ``t`` (negative: overlapping)."""
        return norm(self.at(t)) - self.radius

    def closest(self, end: float) -> float:
        """The time in ``[0, end]`` at which the centres are closest."""
        a = math.fsum(v * v for v in self.dv)
        if a == 0:
            return 0.0
        return min(end, max(0.0, -math.fsum(p * v for p, v in zip(self.dp, self.dv,
                                                                    strict=True)) / a))

    def time_bound(self, t: float, unit: float) -> float:
        """How far rounding at relative ``unit`` moves the first root ``t`` (module docstring)."""
        a = math.fsum(v * v for v in self.dv)
        if a == 0:  # at t = 0 the root still moves: a pair touching at the start rounds apart
            return K_TOI * TINY
        b = math.fsum(p * v for p, v in zip(self.dp, self.dv, strict=True))
        c = math.fsum(p * p for p in self.dp) - self.radius**2
        disc = max(0.0, b * b - a * c)
        size = (math.sqrt(a) * t + norm(self.dp)) ** 2 + self.radius**2
        graze = math.sqrt(size / (K_TOI * unit * a))
        slope = size / (2.0 * math.sqrt(disc)) if disc > 0 else math.inf
        return K_TOI * unit * (t + min(slope, graze)) + K_TOI * TINY


def bound(case: ToiCase, quantity: str, want: Observation, unit: float = U) -> float:
    """The agree tolerance of ``quantity``: the case's own, or the bound at relative ``unit``."""
    own = case.tolerance
    if quantity == "hit":
        return 0.0
    motion = Motion.of(case)
    t = want.toi if isinstance(want.toi, float) else 0.0
    dt = motion.time_bound(t, unit)
    if quantity == "toi":
        return own.toi if own and own.toi is not None else dt
    if own and own.normal is not None:
        return own.normal
    if motion.radius <= 0:
        return math.pi
    lengths = norm(motion.dp) + norm(motion.dv) * t
    return K_ANGLE * unit + (norm(motion.dv) * dt + K_ANGLE * unit * lengths) / motion.radius


def judge(case: ToiCase, conv: Conventions, quantity: str, value: Value, truth: Observation,
          observed: Observation) -> tuple[Status, float, float, str, str]:
    """Status, error, tolerance, category and reason of one quantity (the truth is defined)."""
    want = truth.get(quantity)
    assert want is not None and not isinstance(want, Undefined)
    tol = bound(case, quantity, truth)
    if (quantity == "normal" and isinstance(value, tuple) and not failed(value)
            and not is_unit(vec := cast(Vec, value))):
        return (Status.DISAGREE, math.inf, tol, Category.ERROR,
                f"engine normal is not a unit vector (length {norm(vec):.7g})")
    err = math.inf if isinstance(value, Undefined) else error_of(quantity, value, want)
    if err <= tol and not failed(value):
        return Status.AGREE, err, tol, "", ""
    category, reason = explain(case, conv, quantity, value, truth, observed, err)
    return Status.DISAGREE, err, tol, category, reason


def explain(case: ToiCase, conv: Conventions, quantity: str, value: Value,
            truth: Observation, observed: Observation, err: float) -> tuple[str, str]:
    """The category and reason of a disagreement (see the module docstring)."""
    motion = Motion.of(case)
    reported = observed.hit if isinstance(observed.hit, bool) else None
    when = observed.toi if isinstance(observed.toi, float) and math.isfinite(observed.toi) \
        else None
    exact = truth.toi if isinstance(truth.toi, float) else None
    if isinstance(observed.hit, Undefined):
        return Category.ERROR, f"the engine gave no answer: {observed.hit.reason}"
    if quantity == "hit" or when is None or not reported:
        return _verdict(case, conv, motion, reported, exact)
    rule = _at_time(case, conv, motion, when, truth)
    if quantity == "toi":
        return rule or (Category.ERROR, _unexplained(motion, when, exact, err, "toi"))
    right_then = _normal_then(motion, value, when)
    if rule and right_then is not None and right_then <= bound(
            case, "normal", truth, max(U, conv.rtol)):
        category, why = rule
        return category, (f"normal right for the engine's time {when:.17g} (off by "
                          f"{right_then:.3g} rad from the direction then): {why}")
    if rule and norm(motion.at(when)) <= precision(conv, case) and failed(value):
        category, why = rule
        return category, (f"no normal: at the engine's time {when:.17g} the centres coincide "
                          f"(to its precision), so no direction is defined there: {why}")
    return Category.ERROR, _unexplained(motion, when, exact, err, "normal")


def _unexplained(motion: Motion, when: float, exact: float | None, err: float,
                 quantity: str) -> str:
    at = f"exact contact at t = {exact!r}" if exact is not None else "no exact contact"
    return (f"{quantity} off by {err:.3g}: at the engine's time {when:.17g} the surfaces are "
            f"{motion.gap(when):.3g} apart ({at}); no declared target separation, tolerance "
            "or sampling explains it")


def _normal_then(motion: Motion, value: Value, when: float) -> float | None:
    if not isinstance(value, tuple) or motion.radius <= 0:
        return None
    d = motion.at(when)
    length = norm(d)
    if length == 0:
        return None
    return error_of("normal", value, tuple(x / length for x in d))


def target_separation(conv: Conventions, case: ToiCase) -> float:
    """The separation of the surfaces the engine's query aims for: ``toi_target``, but never
    closer than ``toi_min_centre_distance`` between the centres (Box2D's ``linearSlop``)."""
    radius = case.a.radius + case.b.radius
    return max(conv.toi_target, conv.toi_min_centre_distance - radius)


def precision(conv: Conventions, case: ToiCase) -> float:
    """What the engine's arithmetic precision ``rtol`` allows a separation to be off by:
    ``K_TOI rtol`` of the magnitudes it holds (the coordinates, as an engine in float32
    rounds them, the travel over the interval and the radii)."""
    a, b = case.a, case.b
    magnitude = (max(norm(a.center), norm(b.center))
                 + (norm(a.velocity) + norm(b.velocity)) * case.duration + a.radius + b.radius)
    return K_TOI * max(U, conv.rtol) * magnitude


def _separation(conv: Conventions, case: ToiCase) -> tuple[float, float]:
    """The declared target separation and its allowance (tolerance plus precision)."""
    return target_separation(conv, case), conv.toi_tolerance + precision(conv, case)


def _at_time(case: ToiCase, conv: Conventions, motion: Motion, when: float,
             truth: Observation) -> tuple[str, str] | None:
    """A reported time explained by a declared target, tolerance or sampling, else None."""
    target, slack = _separation(conv, case)
    gap = motion.gap(when)
    aim = (f"the declared target separation {target:.3g}" if target
           else "touching (separation 0)")
    category = Category.CONVENTION if target != 0 else Category.TOLERANCE
    within = (f"within {slack:.3g} (declared toi_tolerance {conv.toi_tolerance:.3g} plus rtol "
              f"{max(U, conv.rtol):.3g} of the case's magnitudes)")
    if abs(gap - target) <= slack:
        return category, (f"at the engine's time {when:.17g} the surfaces are {gap:.3g} apart, "
                          f"{within} of {aim}")
    if when == 0.0 and gap <= target + slack:
        return category, (f"at the start the surfaces are {gap:.3g} apart, already {within} "
                          f"of {aim} or closer: the query reports a contact at 0")
    exact = truth.toi if isinstance(truth.toi, float) else math.nan
    allowed = conv.toi_time_tolerance * case.duration
    short = conv.toi_time_tolerance * norm(motion.dv) * case.duration
    if allowed and (abs(when - exact) <= allowed or 0.0 <= gap <= short + slack):
        return Category.TOLERANCE, (
            f"time {when:.17g} against the exact {exact!r}, surfaces {gap:.3g} apart then: "
            f"within the declared toi_time_tolerance {conv.toi_time_tolerance:g} of the "
            f"{case.duration:g} s interval ({allowed:.3g} s, or {short:.3g} of closing travel "
            "short of contact)")
    times = sample_times(case, conv)
    rounding = precision(conv, case)  # a sample this close to touching may round either way
    earlier = [t for t in times if t < when and motion.gap(t) <= -rounding]
    if (any(math.isclose(when, t, rel_tol=1e-12, abs_tol=0.0) for t in times)
            and gap <= 0 and when >= exact and not earlier):
        return Category.TIMESTEP, (
            f"the engine samples the interval at {len(times)} evenly spaced times "
            f"(declared toi_samples): it reports the first sample that overlaps, t = "
            f"{when:.6g} (overlap {-gap:.3g}), for the contact at t = {exact!r}")
    return None


def sample_times(case: ToiCase, conv: Conventions) -> list[float]:
    """The times a sampling query tests: ``i T / (n - 1)`` for its declared ``n`` samples."""
    n = conv.toi_samples
    if n < 2:
        return []
    return [case.duration * i / (n - 1) for i in range(n)]


def _verdict(case: ToiCase, conv: Conventions, motion: Motion, reported: bool | None,
             exact: float | None) -> tuple[str, str]:
    """Why the engine's contact verdict (hit or no hit) differs from the exact one."""
    end = case.duration
    closest = motion.closest(end)
    nearest = motion.gap(closest)
    target, slack = _separation(conv, case)
    if reported is None:
        return Category.ERROR, "the engine reported no contact verdict"
    if reported and exact is None:
        if nearest <= target + slack:
            category = Category.CONVENTION if target else Category.TOLERANCE
            return category, (f"the surfaces come within {nearest:.3g} at t = {closest:.6g} "
                              f"(no exact contact), inside the declared target separation "
                              f"{target:.3g} plus toi_tolerance and precision {slack:.3g}")
        return Category.ERROR, (f"reported a contact, but the surfaces stay {nearest:.3g} apart "
                                f"at the closest (t = {closest:.6g}); no declared rule reaches it")
    # the engine saw no contact; the exact pair touches at `exact`
    if (exact is not None and exact in sample_times(case, conv)
            and motion.gap(exact) == 0.0 and not conv.touching_is_contact("sphere")):
        return Category.CONVENTION, (
            f"the first contact is an exact touch at the sample t = {exact!r} (distance 0): "
            "the engine's test counts touching spheres as apart, the time of impact as "
            "contact")
    if exact == end and conv.toi_end_excluded:
        return Category.CONVENTION, (
            f"the first contact is exactly at the interval's end t = {exact!r}, which the "
            "engine's query excludes (declared toi_end_excluded)")
    times = sample_times(case, conv)
    rounding = precision(conv, case)  # a sample this close to touching may round either way
    if times and all(motion.gap(t) > 0 or (motion.gap(t) == 0
                                            and not conv.touching_is_contact("sphere"))
                     or -rounding < motion.gap(t) < 0 for t in times):
        return Category.TIMESTEP, (
            f"the engine samples the interval at {len(times)} evenly spaced times (declared "
            f"toi_samples); the exact contact at t = {exact!r} falls between them: no sample "
            f"finds the spheres overlapping (at the end they are {motion.gap(end):.3g} apart)")
    overlap = max(0.0, -nearest)
    if target < 0 and nearest > target - slack:
        return Category.CONVENTION, (
            f"the spheres overlap at most {overlap:.3g} (t = {closest:.6g}), never the "
            f"engine's declared target overlap {-target:.3g} (less its toi_tolerance and "
            f"precision, {slack:.3g}): it reports no contact")
    if nearest > target - slack:
        return Category.TOLERANCE, (
            f"the spheres overlap at most {overlap:.3g} (t = {closest:.6g}): within "
            f"{slack:.3g} (the engine's toi_tolerance and precision) of only touching, and "
            "it reports no contact")
    return Category.ERROR, (f"reported no contact; the exact first contact is at t = {exact!r}"
                            f" (the spheres overlap by up to {max(0.0, -nearest):.3g})")

