"""Why a scene measure disagrees (``settle``, ``jitter``, ``energy_drift``, ``apex``,
``bounce_time``, ``divergence``): its error, tolerance, category and reason.

The measures are defined in :mod:`crosscheck.truth.scene_measures`.  Each error is compared
with a float64 tolerance (what a float64 simulation of the exact run can be off by); a
disagreement gets a category from the engine's declared conventions and one event's bound,
each cited with the number it allows (a precision that cannot hold the scene at all makes
every measure ``tolerance``, :func:`~crosscheck.truth.scenes.coarse`):

- ``settle``: the declared rest band ``rest_gap`` (per contact below the body) and the soft
  contact's sink ``rest_sink_s2 |g|`` (``convention``), then the step's sink
  ``rest_sink_steps |g| dt**2`` (``timestep``), or the precision alone (``tolerance``);
- ``jitter``: the precision (a position held to it moves ``held / dt``: ``tolerance``),
  then one step of gravity, ``|g| dt``, for an engine that declares a step sink or sampled
  contacts (``timestep``);
- ``energy_drift`` of a resting scene: what its settle offsets and jitter hold;
- ``apex``, ``bounce_time``, the other ``energy_drift`` and ``divergence`` rows:
  :mod:`crosscheck.truth.motion_rules` (each bounce from the engine's own previous state,
  the two-body run the engine gave, the precision, the declared contact rules).

Anything else is an ``error``, with what was read.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import replace
from typing import cast

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.kinds import quantity_named
from crosscheck.core.model import Category, Observation, Status, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import motion_rules
from crosscheck.truth import scene_measures as sm
from crosscheck.truth.scenes import (
    PRECISION_FACTOR,
    coarse,
    extent,
    held,
    mean_radius,
    simulated_time,
)

CONVENTIONS = ("rest_gap", "rest_sink_s2", "restitution_model", "restitution_threshold",
               "damping")
"""The declared conventions whose rules make a measure's disagreement a ``convention``: the
rest band and the soft sink, a soft restitution, the restitution threshold, the damping
(fields of :class:`~crosscheck.core.conventions.Conventions`)."""
ULPS = 8.0
"""A float64 simulation's rounding, in units of the ulp of the scene's largest coordinate."""

Judged = tuple[Status, float, float, str, str]
Rule = Callable[[SceneCase, Conventions, str, Value, Value, float, Observation, Observation],
                tuple[str, str]]
"""A measure's rule: its category and reason (the row's tolerance is bound in beforehand)."""


_extent = extent
_mean_radius = mean_radius


def tolerance(case: SceneCase, quantity: str, default: float) -> float:
    """The float64 tolerance of a measure: ``default`` relative, and never below
    :data:`ULPS` ulps of the scene's coordinates for a length."""
    g = norm(sm.gravity(case))
    duration = float(simulated_time(case))
    length = max(default * _mean_radius(case), ULPS * math.ulp(_extent(case)))
    return {"settle": length,
            "jitter": max(default * math.sqrt(2 * g * _mean_radius(case)),
                          length / (case.dt or DEFAULT_DT)),
            "energy_drift": default,
            "apex": max(default, length / _mean_radius(case)),
            "bounce_time": max(default * duration, ULPS * math.ulp(duration)),
            "divergence": default}[quantity]


def error(case: SceneCase, quantity: str, value: Value, want: Value) -> float:
    """The error of one measure (see :mod:`crosscheck.truth.scene_measures`)."""
    if isinstance(value, Undefined):
        return math.inf
    if quantity in ("settle", "bounce_time", "apex"):
        mine, exact = cast(Vec, value), cast(Vec, want)
        pairs = list(zip(mine, exact, strict=False))
        if not pairs:
            return 0.0 if not exact else math.inf
        if quantity == "apex":
            return max(abs(x / y - 1.0) if y > 0 else abs(x - y) for x, y in pairs)
        return max(abs(x - y) for x, y in pairs)
    if quantity == "divergence":
        end = float(simulated_time(case))
        return 1.0 - float(cast(float, value)) / end if end > 0 else 0.0
    return abs(float(cast(float, value)) - float(cast(float, want)))


def judge(case: SceneCase, conventions: Conventions, quantity: str, value: Value, want: Value,
          truth: Observation, observed: Observation, default_tol: float) -> Judged:
    """Status, error, tolerance, category and reason of one scene measure."""
    tol = tolerance(case, quantity, default_tol)
    if isinstance(value, Undefined):
        return (Status.DISAGREE, math.inf, tol, Category.ERROR,
                f"engine gave undefined ({value.reason}) where the reference is defined")
    err = error(case, quantity, value, want)
    if err <= tol:
        return Status.AGREE, err, tol, "", ""
    why = coarse(case, conventions)
    if why:
        return (Status.DISAGREE, err, tol, Category.TOLERANCE,
                f"{quantity} off by {err:.3g} {quantity_named(quantity).words}: {why}")
    rules: dict[str, Rule] = {"settle": _settle, "jitter": _jitter,
                              "energy_drift": functools.partial(_energy_drift, tol=tol),
                              "apex": motion_rules.apex,
                              "bounce_time": motion_rules.bounce_time,
                              "divergence": _divergence}
    rule = rules[quantity]
    category, reason = rule(case, conventions, quantity, value, want, err, truth, observed)
    steps = f"{case.step_count} steps of dt = {case.dt or DEFAULT_DT:.3g} s"
    return Status.DISAGREE, err, tol, category, f"{reason} ({steps})"


def _contacts_below(case: SceneCase) -> list[int]:
    """For each body, how many resting contacts are stacked below it (1: on the ground)."""
    floor = sm.ground(case)
    if floor is None:
        return [1] * len(case.bodies)
    heights = [sm.gap(case, floor, b.center, b.radius) for b in case.bodies]
    order = sorted(range(len(heights)), key=heights.__getitem__)
    return [order.index(i) + 1 for i in range(len(heights))]


def settle_bands(case: SceneCase, conventions: Conventions
                 ) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Per body, the offsets from its exact gap explained by the declared contact model
    (the rest band per contact below it, and the soft sink of the weight of up to every body
    carried) and, wider, by the step (``rest_sink_steps |g| dt**2`` per contact, either way:
    gravity integrated before or after the contact), each widened by :func:`held`."""
    g, dt, n = norm(sm.gravity(case)), case.dt or DEFAULT_DT, len(case.bodies)
    lo, hi = conventions.rest_gap
    soft = conventions.rest_sink_s2 * g
    step = conventions.rest_sink_steps * g * dt * dt
    slack = held(case, conventions)
    out = []
    for below in _contacts_below(case):
        model = (below * (lo - n * soft) - slack, below * hi + slack)
        out.append((model, (model[0] - below * step, model[1] + below * step)))
    return out


def _settle(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
            want: Value, err: float, truth: Observation, observed: Observation
            ) -> tuple[str, str]:
    category, worst = _settle_category(case, conventions, value, want)
    g, dt = norm(sm.gravity(case)), case.dt or DEFAULT_DT
    lo, hi = conventions.rest_gap
    gaps = ", ".join(f"{x:.3g}" for x in cast(Vec, value))
    declared = (f"declared rest band {lo:.3g} .. {hi:.3g} m per contact, soft sink "
                f"{conventions.rest_sink_s2:g} s^2 x |g| = {conventions.rest_sink_s2 * g:.3g} m "
                f"per body carried, step {conventions.rest_sink_steps:g} |g| dt^2 = "
                f"{conventions.rest_sink_steps * g * dt * dt:.3g} m per contact, precision "
                f"{held(case, conventions):.3g} m")
    head = f"settle off by {err:.3g} m (gaps to the ground {gaps} m)"
    if category == Category.ERROR:
        return category, (f"{head}: one body is {worst:.3g} m from its exact gap, beyond the "
                          f"{declared}")
    word = {str(Category.TIMESTEP): "the step's allowance",
            str(Category.TOLERANCE): "the precision",
            str(Category.CONVENTION): "the rest band and soft sink"}[category]
    return category, f"{head}, within {word} ({declared})"


def _settle_category(case: SceneCase, conventions: Conventions, value: Value, want: Value
                     ) -> tuple[str, float]:
    """The settle row's category and the worst offset: every body within the model band
    (``convention``; within the precision alone: ``tolerance``) or the step's band
    (``timestep``), else ``error``."""
    offsets = [x - y for x, y in zip(cast(Vec, value), cast(Vec, want), strict=False)]
    if all(abs(off) <= held(case, conventions) for off in offsets):
        return Category.TOLERANCE, max(offsets, key=abs, default=0.0)
    category = Category.CONVENTION
    for off, (model, stepped) in zip(offsets, settle_bands(case, conventions), strict=False):
        if model[0] <= off <= model[1]:
            continue
        if stepped[0] <= off <= stepped[1]:
            category = Category.TIMESTEP
            continue
        return Category.ERROR, off
    return category, max(offsets, key=abs, default=0.0)


def _jitter(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
            want: Value, err: float, truth: Observation, observed: Observation
            ) -> tuple[str, str]:
    g, dt = norm(sm.gravity(case)), case.dt or DEFAULT_DT
    stepped = conventions.rest_sink_steps > 0 or conventions.sampled_contacts
    rounding = held(case, conventions) / dt
    if err <= rounding:
        return Category.TOLERANCE, (
            f"jitter {err:.3g} m/s at rest, within what the engine's declared precision "
            f"allows: a position held to {held(case, conventions):.3g} m ({PRECISION_FACTOR:g} "
            f"x rtol {conventions.rtol:.3g} of the coordinates) moves by that per step, "
            f"{rounding:.3g} m/s at dt = {dt:.3g} s")
    if stepped and err <= g * dt:
        return Category.TIMESTEP, (
            f"jitter {err:.3g} m/s at rest, within one step of gravity |g| dt = {g * dt:.3g} "
            "m/s (the engine integrates gravity before it resolves the contact: declared "
            "rest_sink_steps or sampled_contacts)")
    return Category.ERROR, (f"jitter {err:.3g} m/s at rest, beyond one step of gravity "
                            f"{g * dt:.3g} m/s" + ("" if stepped else
                                                   " (no step sink declared)"))


def _resting_energy(case: SceneCase, conventions: Conventions, quantity: str, err: float,
                    truth: Observation, observed: Observation) -> tuple[str, str] | None:
    """A resting scene's energy drift explained by where the bodies settled: the potential
    energy of the settle offsets (and the kinetic energy of the jitter), when the settle
    row itself is explained."""
    want, mine = truth.settle, observed.settle
    if quantity != "energy_drift" or not isinstance(want, tuple) or not isinstance(mine, tuple):
        return None
    category, _ = _settle_category(case, conventions, mine, want)
    if category == Category.ERROR:
        return None
    g = norm(sm.gravity(case))
    speed = observed.jitter if isinstance(observed.jitter, float) else 0.0
    energy = math.fsum(b.mass * (g * abs(x - y) + 0.5 * speed * speed)
                       for b, x, y in zip(case.bodies, mine, want, strict=True))
    reach = energy / ((sm.energy_scale(case) or 1.0) * float(simulated_time(case)))
    if err > reach * (1.0 + 1e-9):
        return None
    return category, (f"energy_drift off by {err:.3g} of the energy scale per s, within the "
                      f"{reach:.3g} that the settle offsets (m |g| x offset) and the jitter "
                      f"explain, settled as the rest conventions allow ({category})")


def _energy_drift(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
                  want: Value, err: float, truth: Observation, observed: Observation,
                  tol: float = 0.0) -> tuple[str, str]:
    resting = _resting_energy(case, conventions, quantity, err, truth, observed)
    if resting is not None:
        return resting
    return motion_rules.energy_drift(case, conventions, quantity, value, want, err, truth,
                                     observed, tol)


def _divergence(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
                want: Value, err: float, truth: Observation, observed: Observation
                ) -> tuple[str, str]:
    impacts = [x for x in (truth.impacts or ()) if x <= float(cast(float, value))]
    if (not impacts and isinstance(observed.settle, tuple)
            and isinstance(truth.settle, tuple)):
        category, _ = _settle_category(case, conventions, observed.settle, truth.settle)
        if category != Category.ERROR:
            reach = case.diverge_at * _mean_radius(case)
            return category, (
                f"the trajectory left {case.diverge_at:g} mean radii ({reach:.3g} m) of the "
                f"exact one at t = {float(cast(float, value)):.4g} s ({err:.3g} of the run): "
                f"the bodies settled where the rest conventions allow (the settle row: "
                f"{category})")
    return motion_rules.divergence(case, conventions, quantity, value, want, err, truth,
                                   observed)


def settled_positions(case: SceneCase, conventions: Conventions, quantity: str, err: float,
                      observed: Observation, truth: Observation) -> tuple[str, str] | None:
    """A resting scene's position error that is its settle offsets: the ``settle`` row's
    category, when the positions are off by no more than the largest offset from the exact
    gaps (and the precision)."""
    want, mine = truth.settle, observed.settle
    if quantity != "positions" or not isinstance(want, tuple) or not isinstance(mine, tuple):
        return None
    category, worst = _settle_category(case, conventions, mine, want)
    offsets = [abs(x - y) for x, y in zip(mine, want, strict=False)]
    reach = (max(offsets, default=0.0) + held(case, conventions)) / _mean_radius(case)
    if category == Category.ERROR or err > reach:
        return None
    return category, (f"positions off by {err:.3g} mean radii: the bodies settled "
                      f"{worst:.3g} m from their exact gaps to the ground, as the settle row "
                      f"explains ({category}), and are off by no more than that")


def complete(case: SceneCase, observed: Observation, truth: Observation) -> Observation:
    """``observed`` with its ``divergence`` from the exact trajectory (else left as it is)."""
    mine, exact = observed.trajectory, truth.trajectory
    if mine is None or exact is None:
        return observed
    return replace(observed, divergence=sm.divergence(case, mine, exact))
