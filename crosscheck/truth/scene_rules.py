"""Why a scene quantity disagrees: the category and the reason, from declared conventions.

:func:`judge` gives a scene quantity's status, error, tolerance, category and reason
(:mod:`crosscheck.truth.scenes` holds the truth, the errors and the allowances it reads).
A disagreement gets, in this order:

1. a named rule that fires on the scene: the declared speed cap (the run is right for the
   scene with its initial speeds capped), the declared restitution threshold (a two-body
   scene whose first impact closes slower than it, right for e = 0), or a missed impact
   (:data:`PASSED_THROUGH`: the bodies passed through each other, with the per-step travel;
   ``timestep`` for an engine that declares sampled contacts when no step start finds the
   pair overlapping while approaching, else ``error``);
2. the step lag (``timestep``), the declared damping (``convention``) or the engine's
   precision (``tolerance``);
3. ``error``, with what was read.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import cast

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Category, Observation, Status, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import measure_rules
from crosscheck.truth.scene_measures import MEASURES, surrounded
from crosscheck.truth.scenes import (
    PRECISION_FACTOR,
    QUANTITIES,
    UNITS,
    aligned,
    damping_bound,
    gravity_step,
    lag_bound,
    relative_error,
    step_travel,
    tolerance,
    truth,
)

CONVENTIONS = tuple(dict.fromkeys((
    "max_speed", "restitution_threshold", "damping", *measure_rules.CONVENTIONS)))
"""The declared conventions whose rules make a scene quantity's disagreement a
``convention``: the speed cap, the restitution threshold, the damping, and the measures'
(:data:`crosscheck.truth.measure_rules.CONVENTIONS`, whose settle rows the positions
follow)."""


def _free_flight(case: SceneCase) -> tuple[Vec, ...]:
    """Every body's initial velocity: what an engine that resolved no impact ends with."""
    return tuple(tuple(b.velocity) for b in case.bodies)


def _overlap_steps(case: SceneCase) -> tuple[list[int], list[int]]:
    """The step starts ``k dt`` at which the first two bodies, in free flight, overlap while
    still approaching (a contact a discrete step can resolve), and those at which they
    overlap with their centres already past the closest point (receding: a contact normal
    taken there says they are moving apart, and the step lets them go)."""
    a, b = case.bodies[0], case.bodies[1]
    dt, reach = case.dt or DEFAULT_DT, a.radius + b.radius
    dv = [w - v for v, w in zip(a.velocity, b.velocity, strict=True)]
    approaching: list[int] = []
    receding: list[int] = []
    for k in range(case.step_count + 1):
        d = [(q + w * k * dt) - (p + v * k * dt)
             for p, v, q, w in zip(a.center, a.velocity, b.center, b.velocity, strict=True)]
        if norm(d) < reach:
            closing = math.fsum(x * y for x, y in zip(d, dv, strict=True)) < 0
            (approaching if closing else receding).append(k)
    return approaching, receding


def _along(case: SceneCase, pair: object, first: float) -> float:
    """B's position (or velocity) relative to A's along the contact normal of the exact
    first impact (at time ``first``): positive on the side B touched from (moving apart),
    negative past A (still approaching)."""
    a, b = case.bodies
    d = [(q + w * first) - (p + v * first) for p, v, q, w
         in zip(a.center, a.velocity, b.center, b.velocity, strict=True)]
    if not (isinstance(pair, tuple) and len(pair) == 2) or norm(d) == 0:
        return math.nan
    pa, pb = cast(tuple[Vec, Vec], pair)
    return math.fsum((y - x) * n for x, y, n in zip(pa, pb, d, strict=True)) / norm(d)


PASSED_THROUGH = "the bodies passed through each other"
"""The words of a missed impact in a scene row's reason (the named failure): written only by
:func:`_passed_through`, read by the stability study's ``step_travel`` walk."""


def _passed_through(case: SceneCase, conventions: Conventions, quantity: str, err: float,
                    observed: Observation, truth: Observation) -> tuple[str, str] | None:
    """A missed impact of a two-body scene: the engine resolved no impact (its velocities
    are still the initial ones, to its precision and damping) or the bodies end past each
    other along the exact contact normal while the exact run keeps them apart.  Named,
    with the travel, never a small position error."""
    velocities, impacts = observed.velocities, truth.impacts
    if (not impacts or len(case.bodies) != 2 or surrounded(case)
            or not isinstance(velocities, tuple) or quantity not in QUANTITIES):
        return None
    if quantity != "positions" and err <= PRECISION_FACTOR * conventions.rtol:
        return None  # right to the engine's precision: a conserved quantity
    unchanged = relative_error(case, "velocities", velocities, _free_flight(case))
    mine, exact = (_along(case, observed.positions, impacts[0]),
                   _along(case, truth.positions, impacts[0]))
    closing = _along(case, velocities, impacts[0])
    free = unchanged <= max(PRECISION_FACTOR * conventions.rtol, DEFAULT_TOL_FLOOR,
                            damping_bound(case, conventions))
    if not (free or (exact > 0 and mine < 0 and closing < 0)):
        return None
    travel = step_travel(case)
    what = (f"the engine resolved none of the {len(impacts)} impact(s) of the exact run "
            f"(final velocities the initial ones, to {unchanged:.2g})" if free else
            f"B ends {-mine:.3g} past A along the exact contact normal, still closing at "
            f"{-closing:.3g} m/s along it, where the exact run leaves it {exact:.3g} on its side "
            f"(velocities changed by {unchanged:.3g} of the top speed on the way)")
    head = (f"{quantity} off by {err:.3g} {UNITS[quantity]}: {PASSED_THROUGH} "
            f"at step travel {travel:.3g} (|vb - va| dt / 2(ra + rb), dt = "
            f"{case.dt or DEFAULT_DT:.3g} s): {what}")
    seen, past = _overlap_steps(case)
    sampled = ("no step start finds the two overlapping while approaching"
               + (f" (at the start of step {past[0]} they overlap, but with their centres "
                  "already past each other: moving apart along the line of centres)"
                  if past else ""))
    if conventions.sampled_contacts and not seen:
        return Category.TIMESTEP, (
            f"{head}; the engine looks for contacts only at step starts (declared "
            f"sampled_contacts), and {sampled}")
    where = (f"they overlap, approaching, at the start of step {seen[0]}" if seen
             else sampled)
    declared = ("" if conventions.sampled_contacts
                else "; the engine does not declare sampled contacts")
    return Category.ERROR, f"{head}; {where}{declared}"


DEFAULT_TOL_FLOOR = 1e-9
"""The least relative change of velocity that counts as an impact resolved (below the
default scene tolerance, :data:`~crosscheck.truth.score.DEFAULT_RTOL`)."""


def scene_speed_cap(case: SceneCase, conventions: Conventions) -> float | None:
    """The declared speed cap at the scene's ``dt`` (None: none).

    A cap that acts at the end of every step (``"step"``) is a translation per step
    (Box2D's ``b2_maxTranslation``): declared as ``max_speed`` at the engine's
    ``time_step``, it is ``max_speed x time_step / dt`` at the scene's step.  A cap that
    acts before the bounce (``"before restitution"``, Rapier's ``max_linear_velocity``)
    is a speed: a bounce may exceed it within a step, and the next step brings it back, so
    two spheres exchanging speeds stay under it.
    """
    if conventions.max_speed is None:
        return None
    if conventions.max_speed_at == "before restitution":
        return conventions.max_speed
    per_step = conventions.max_speed * (conventions.time_step or (case.dt or DEFAULT_DT))
    return per_step / (case.dt or DEFAULT_DT)


def capped(case: SceneCase, conventions: Conventions) -> SceneCase | None:
    """``case`` with every initial speed clipped to the declared cap (None: no cap, or no
    body over it).  Box2D clips the velocity it integrates with and keeps it, and Rapier
    clamps it before integrating, so starting capped is the same motion."""
    cap = scene_speed_cap(case, conventions)
    if cap is None:
        return None
    over = [norm(b.velocity) > cap for b in case.bodies]
    if not any(over):
        return None
    bodies = tuple(b.model_copy(update={"velocity": tuple(v * cap / norm(b.velocity)
                                                          for v in b.velocity)}) if o else b
                   for b, o in zip(case.bodies, over, strict=True))
    return case.model_copy(update={"bodies": bodies})


def _speed_cap(case: SceneCase, conventions: Conventions, quantity: str, err: float,
               value: Value, tol: float, impacts: int | None) -> tuple[str, str] | None:
    """The error explained by the declared speed cap: right (within the tolerance or the
    step lag) for the scene with its initial speeds capped."""
    slow = capped(case, conventions)
    if slow is None:
        return None
    want = truth(slow).get(quantity)
    if want is None or isinstance(want, Undefined):
        return None
    there = relative_error(case, quantity, value, want)
    lag = lag_bound(case, impacts or 0) if quantity == "positions" else 0.0
    if there > max(tol, lag, PRECISION_FACTOR * conventions.rtol):
        return None
    top = max(norm(b.velocity) for b in case.bodies)
    cap, step = conventions.max_speed or 0.0, conventions.time_step
    declared = (f"declared max_speed {cap:.4g} m/s at its time step {step:.3g} s: "
                f"{cap * step:.3g} m per step" if conventions.max_speed_at == "step" and step
                else f"declared max_speed {cap:.4g} m/s, acting {conventions.max_speed_at}")
    return Category.CONVENTION, (
        f"{quantity} off by {err:.3g} {UNITS[quantity]}: the engine caps speeds at "
        f"{scene_speed_cap(case, conventions):.4g} m/s at dt = {case.dt or DEFAULT_DT:.3g} s "
        f"({declared}), and the top initial speed is {top:.4g}; against the exact run with "
        f"the capped speeds the error is {there:.3g}")


def _first_approach(case: SceneCase, first: float) -> float:
    """The normal approach speed of the exact run's first impact (at time ``first``): the
    initial velocities still hold then, so it is found from the bodies that touch."""
    bodies = case.bodies
    for i, a in enumerate(bodies):
        for b in bodies[i + 1:]:
            d = [(q + w * first) - (p + v * first) for p, v, q, w
                 in zip(a.center, a.velocity, b.center, b.velocity, strict=True)]
            length = norm(d)
            if abs(length - (a.radius + b.radius)) <= 1e-9 * (a.radius + b.radius):
                dv = [w - v for v, w in zip(a.velocity, b.velocity, strict=True)]
                return -math.fsum(x * y for x, y in zip(dv, d, strict=True)) / length
    return math.nan


def _threshold(case: SceneCase, conventions: Conventions, quantity: str, err: float,
               value: Value, tol: float, impacts: Sequence[float] | None) -> (
                   tuple[str, str] | None):
    """The error explained by the declared restitution threshold: the first impact closes
    slower than it, and the engine's answer is the exact run's with no bounce (e = 0).

    Two-body scenes only: with more bodies an e = 0 exact run can collapse into endlessly
    many impacts (inelastic collapse), and one impact's speed does not settle the others.
    """
    threshold = conventions.restitution_threshold
    if not (threshold > 0 and case.restitution > 0 and impacts and len(case.bodies) == 2
            and not surrounded(case)):
        return None
    speed = _first_approach(case, impacts[0])
    if not speed < threshold:
        return None
    want = truth(case.model_copy(update={"restitution": 0.0})).get(quantity)
    if want is None or isinstance(want, Undefined):
        return None
    there = relative_error(case, quantity, value, want)
    lag = lag_bound(case, len(impacts)) if quantity in ("positions", "velocities") else 0.0
    if there > max(tol, lag, PRECISION_FACTOR * conventions.rtol):
        return None
    late = f" (within the step lag {lag:.3g})" if there > tol and there <= lag else ""
    return Category.CONVENTION, (
        f"{quantity} off by {err:.3g} {UNITS[quantity]}: the first impact closes at "
        f"{speed:.3g} m/s along the line of centres, below the engine's restitution threshold "
        f"{threshold:g} m/s (declared: no bounce below it); against the exact run with e = 0 "
        f"the error is {there:.3g}{late}")


def _category(case: SceneCase, conventions: Conventions, quantity: str, err: float,
              impacts: int | None, positions_err: float) -> tuple[str, str]:
    steps = f"{case.step_count} steps of dt = {case.dt or DEFAULT_DT:.3g} s"
    damp = damping_bound(case, conventions)
    damped = damp * (2.0 - damp) if quantity == "energy" else damp
    if quantity in ("momentum", "energy") and conventions.damping > 0 and err <= damped:
        return Category.CONVENTION, (
            f"{quantity} off by {err:.3g} {UNITS[quantity]}: the engine damps velocities "
            f"(declared {conventions.damping:g} per s, up to {damp:.3g} of a speed over the "
            f"run, {damped:.3g} of the {quantity})")
    walled = surrounded(case)
    stepped = gravity_step(case, quantity)
    if walled and stepped > 0 and err <= stepped:
        return Category.TIMESTEP, (
            f"{quantity} off by {err:.3g} {UNITS[quantity]}, within one step of gravity on "
            f"every body (|g| dt = {stepped:.3g} of the scale): what a resting body carries "
            f"between its contact's solves ({steps})")
    lagged = ("positions", "velocities", "momentum", "energy") if walled else (
        "positions", "velocities")
    if impacts is not None and quantity in lagged:
        lag = lag_bound(case, impacts)
        lag = lag * (2.0 + lag) if quantity == "energy" else lag
        also = "" if quantity == "positions" else (
            f" (positions too: {positions_err:.3g} mean radii)")
        if err <= lag and positions_err <= lag:
            return Category.TIMESTEP, (
                f"{quantity} off by {err:.3g} {UNITS[quantity]}{also}, within the {lag:.3g} "
                f"that resolving each of the {impacts} impacts up to one step late allows "
                f"({steps})")
        reach = lag + damp * (1.0 + lag)
        if conventions.damping > 0 and err <= reach and positions_err <= reach:
            return Category.CONVENTION, (
                f"{quantity} off by {err:.3g} {UNITS[quantity]}{also}, within the step lag "
                f"{lag:.3g} plus the declared damping ({conventions.damping:g} per s: up to "
                f"{damp:.3g})")
    precision = PRECISION_FACTOR * conventions.rtol
    if quantity in ("velocities", "momentum", "energy") and err <= precision:
        return Category.TOLERANCE, (
            f"{quantity} off by {err:.3g} {UNITS[quantity]}, within the engine's declared "
            f"precision: {PRECISION_FACTOR:g} x rtol {conventions.rtol:.3g} = {precision:.3g} "
            f"(velocities held at that relative precision) ({steps})")
    return Category.ERROR, (f"{quantity} off by {err:.3g} {UNITS[quantity]} after {steps}; "
                            "not explained by the step lag, nor by the declared damping or "
                            "precision (the scene conventions the scoring reads)")



def _aligned(case: SceneCase, impacts: Sequence[float] | None) -> str:
    on_step = aligned(case, impacts or ())
    if not on_step:
        return ""
    return (f"; note: {len(on_step)} impact(s) of the exact run fall on a step boundary "
            f"(t = {on_step[0]:.6g} = k x dt), where a step-late engine meets them on time")


def judge(case: SceneCase, conventions: Conventions, quantity: str, value: Value, want: Value,
          truth: Observation, observed: Observation,
          default_tol: float) -> tuple[Status, float, float, str, str]:
    """Status, relative error, tolerance, category and reason of one scene quantity.

    A velocity error counts as step lag only when the positions are within the lag too:
    a late contact tilts velocities no more than it displaces the bodies.
    """
    if quantity in MEASURES:
        return measure_rules.judge(case, conventions, quantity, value, want, truth, observed,
                                   default_tol)
    tol = tolerance(case, quantity, default_tol)
    if isinstance(value, Undefined):
        return (Status.DISAGREE, math.inf, tol, Category.ERROR,
                f"engine gave undefined ({value.reason}) where the reference is defined")
    err = relative_error(case, quantity, value, want)
    if err <= tol:
        return Status.AGREE, err, tol, "", ""
    positions = observed.positions
    moved = (relative_error(case, "positions", positions, truth.positions)
             if isinstance(positions, tuple) and isinstance(truth.positions, tuple) else math.inf)
    impacts = truth.impacts
    count = None if impacts is None else len(impacts)
    named = (_speed_cap(case, conventions, quantity, err, value, tol, count)
             or measure_rules.settled_positions(case, conventions, quantity, err, observed,
                                                truth)
             or _threshold(case, conventions, quantity, err, value, tol, impacts)
             or _passed_through(case, conventions, quantity, err, observed, truth))
    category, reason = named or _category(case, conventions, quantity, err, count, moved)
    return Status.DISAGREE, err, tol, category, reason + _aligned(case, impacts)
