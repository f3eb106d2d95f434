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
lengths it divides).  ``hit`` is right or wrong.  A normal's length must be 1 to the
engine's precision: within the normal's bound at ``max(u, rtol)`` (:func:`unit_allowance`)
it is judged by its direction (its category found as usual; its error is taken on the
vector as given, so a length off 1 counts in it), beyond it, or zero, it is an ``error``
with its length.

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
  discrete tests at ``(i / (n - 1)) T``, rounded as the engine rounds them, 2 for the two
  ends) reported exactly the first sample that overlaps, or saw no contact because it fell
  between its samples (a sample within the engine's precision of touching may round either
  way: a pair touching at the start can read apart there);
- ``convention`` also: no contact for a first touch exactly at the interval's end, by an
  engine that declares the end excluded (``toi_end_excluded``);
- ``error``: none of these.  A normal gets the category of its time when it is right
  for the time the engine reported.

**No value.**  A contact whose ``toi`` or ``normal`` has no finite value is an ``error``,
or a ``convention`` under a rule the engine declares (``no_value``, the rules of
:mod:`crosscheck.truth.no_value`: the textbook's coincident centres, the centres
coinciding at the engine's time), as for pairs.  Without a reported contact the two have
no value because of the verdict, and take its category, except ``tolerance``: a precision
explains a verdict, never a missing number, so those rows are ``error`` (or a declared
rule's ``convention``).
"""

from __future__ import annotations

import math
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
from crosscheck.truth import no_value
from crosscheck.truth.bounds import (
    U,
    by_direction,
    direction,
    error_of,
    failed,
    length_off,
    not_unit,
)
from crosscheck.truth.toi_bounds import K_TOI, Motion, bound, precision, unit_allowance
from reference_impl.toi import time_of_impact

__all__ = ["CONVENTIONS", "K_TOI", "NO_CONTACT", "Motion", "bound", "explain", "judge",
           "missing", "no_contact", "precision", "sample_times", "target_separation", "truth",
           "unit_allowance"]

CONVENTIONS = ("toi_target", "touching", "toi_end_excluded", "no_value")
"""The declared conventions whose rules make a disagreement a ``convention`` (see the module
docstring; fields of :class:`~crosscheck.core.conventions.Conventions`)."""
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


def judge(case: ToiCase, conv: Conventions, quantity: str, value: Value, truth: Observation,
          observed: Observation) -> tuple[Status, float, float, str, str]:
    """Status, error, tolerance, category and reason of one quantity (the truth is defined)."""
    want = truth.get(quantity)
    assert want is not None and not isinstance(want, Undefined)
    tol = bound(case, quantity, truth)
    if quantity == "normal" and isinstance(value, tuple) and not failed(value):
        vec = cast(Vec, value)
        allowed = unit_allowance(case, conv, truth)
        if not length_off(vec) <= allowed:
            return Status.DISAGREE, math.inf, tol, Category.ERROR, not_unit(vec, allowed,
                                                                            conv.rtol)
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
    if quantity == "hit" or not reported:
        category, why = _verdict(case, conv, motion, reported, exact)
        if quantity != "hit" and category == Category.TOLERANCE and failed(value):
            return missing(case, conv, quantity, value, observed, f"its verdict: {why}")
        return category, why
    if failed(value):  # a contact reported, and this quantity of it without a value
        return missing(case, conv, quantity, value, observed)
    if when is None:
        return Category.ERROR, (f"{quantity} off by {err:.3g}; the engine reported a contact "
                                f"with no finite time ({observed.toi!r}) to judge it at")
    rule = _at_time(case, conv, motion, when, truth)
    if quantity == "toi":
        return rule or (Category.ERROR, _unexplained(motion, when, exact, err, "toi"))
    vec, judged = cast(Vec, value), ""
    if (unit := direction(vec)) != vec:  # judged by its direction, its length being right
        judged = by_direction(vec, unit_allowance(case, conv, truth), conv.rtol)
        err = error_of("normal", unit, cast(Vec, truth.normal))
    right_then = _normal_then(motion, unit, when)
    if rule and right_then is not None and right_then <= bound(
            case, "normal", truth, max(U, conv.rtol)):
        category, why = rule
        return category, (f"{judged}normal right for the engine's time {when:.17g} (off by "
                          f"{right_then:.3g} rad from the direction then): {why}")
    return Category.ERROR, judged + _unexplained(motion, when, exact, err, "normal")


def missing(case: ToiCase, conv: Conventions, quantity: str, value: Value,
            observed: Observation, verdict: str = "") -> tuple[str, str]:
    """A quantity without a finite value: ``convention`` under a declared no-value rule
    (:mod:`crosscheck.truth.no_value`), else ``error``.  ``verdict``: why the engine saw no
    contact, when that is within its precision (a precision explains a verdict, never a
    missing number)."""
    failed_answers = no_value.failure(observed, quantity, value)
    rule = no_value.declared(case, conv, quantity, observed)
    if rule:
        return Category.CONVENTION, (f"no value by a declared rule: {failed_answers}, and its "
                                     f"rule {rule}")
    because = (f" ({verdict}; a precision explains the verdict, not a missing value)"
               if verdict else "")
    return Category.ERROR, (f"no finite answer: {failed_answers}{because}; no declared "
                            "convention says the engine gives none for this case")


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
    if when in times and gap <= 0 and when >= exact and not earlier:
        return Category.TIMESTEP, (
            f"the engine samples the interval at {len(times)} evenly spaced times "
            f"(declared toi_samples): it reports the first sample that overlaps, t = "
            f"{when:.6g} (overlap {-gap:.3g}), for the contact at t = {exact!r}")
    return None


def sample_times(case: ToiCase, conv: Conventions) -> list[float]:
    """The times a sampling query tests, rounded as the engine rounds them: the normalised
    time ``i / (n - 1)`` for its declared ``n`` samples, then scaled by the interval,
    ``(i / (n - 1)) T`` (FCL's naive solver, ``t = i / (S)(n_iter - 1)``, and the adapter's
    ``time_of_contact x duration``; the textbook's two ends, 0 and ``T``, are the same).
    ``T i / (n - 1)`` can be an ulp away, and a reported sample must be found exactly:

    >>> (5 / 9) * 1e6, 1e6 * 5 / 9
    (555555.5555555556, 555555.5555555555)
    """
    n = conv.toi_samples
    if n < 2:
        return []
    return [(i / (n - 1)) * case.duration for i in range(n)]


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
        close = [t for t in times if -rounding < motion.gap(t) < 0]
        if close:
            return Category.TIMESTEP, (
                f"the engine samples the interval at {len(times)} evenly spaced times "
                f"(declared toi_samples); at the sample t = {close[0]!r} the spheres overlap "
                f"by {-motion.gap(close[0]):.3g}, within the {rounding:.3g} its precision "
                f"(rtol {conv.rtol:.3g} of the case's magnitudes) may round either way, and no "
                f"other sample finds them overlapping")
        return Category.TIMESTEP, (
            f"the engine samples the interval at {len(times)} evenly spaced times (declared "
            f"toi_samples); the exact contact at t = {exact!r} falls between them: no sample "
            f"finds the spheres overlapping (at the end they are {motion.gap(end):.3g} apart)")
    overlap = max(0.0, -nearest)
    if target < 0 and nearest > target - slack and slack < -target:
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

