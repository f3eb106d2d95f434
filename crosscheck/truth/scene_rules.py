"""Why a scene quantity disagrees: the category and the reason, from declared conventions.

:func:`judge` gives a scene quantity's status, error, tolerance, category and reason
(:mod:`crosscheck.truth.scenes` holds the truth and the errors).  The explanation is found
once per pair run and applied to each quantity with the quantity's own numbers, in this
order:

1. the engine's declared precision cannot hold the scene: ``2 rtol`` of its largest
   coordinate is at least the bodies' mean radius (``tolerance``, every quantity);
2. the run the engine gave (two bodies in open space, :mod:`crosscheck.truth.scene_runs`):
   the first of the exact runs a declared rule makes (a speed cap, a restitution threshold,
   a soft or predictive bounce: ``convention``), the discrete run (the contact found at the
   first step start that finds the bodies overlapping while approaching, resolved along
   the line of centres there: ``timestep``) or the pass-through (:data:`PASSED_THROUGH`:
   ``timestep`` for an engine that declares sampled contacts when no step start finds the
   pair overlapping while approaching, else ``error``) whose positions and velocities the
   engine matches; each quantity is then judged against that run's state, within the
   precision, the event's overlap (positions) and the declared damping;
3. a resting scene's settle offsets (the ``settle`` row's category) or a drop's bounces,
   each judged against its own one-step bound (:mod:`crosscheck.truth.drop_rules`);
   Scenes whose impacts chain (more bodies, or walls) are judged by what every run of their
   impacts keeps (momentum, and the energy at e = 1), the energy only never gained where a
   declared restitution threshold or a bounce taken at the step's start
   (``bounce_from_step_start``, a chain within one step) takes a bounce;
4. per quantity: the declared damping (``convention``: momentum, energy), the declared
   precision (``tolerance``), one step of gravity on a resting body, or one impact seen a
   step late (positions within one step's travel at the top speed: ``timestep``);
5. ``error``, with what was read.

No allowance sums over the run: each is one event's bound or a declared value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import cast

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Category, Observation, Status, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth import drop_rules, measure_rules, motion_rules, scene_runs
from crosscheck.truth.scene_measures import MEASURES, surrounded, top_speed
from crosscheck.truth.scene_runs import PASSED_THROUGH
from crosscheck.truth.scenes import (
    PRECISION_FACTOR,
    QUANTITIES,
    aligned,
    coarse,
    damping_bound,
    extent,
    gravity_step,
    held,
    mean_radius,
    relative_error,
    step_travel,
    stepped_rounding,
    tolerance,
    truth,
    units,
)

__all__ = ["CONVENTIONS", "PASSED_THROUGH", "coarse", "judge"]

CONVENTIONS = tuple(dict.fromkeys((
    "max_speed", "restitution_threshold", "bounce_from_step_start", "restitution_model",
    "damping", *measure_rules.CONVENTIONS)))
"""The declared conventions whose rules make a scene quantity's disagreement a
``convention``: the speed cap, the restitution threshold, a bounce taken from the approach
at the step's start, a soft or predictive bounce, the damping, and the measures'
(:data:`crosscheck.truth.measure_rules.CONVENTIONS`)."""


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


def _slowed_pass(case: SceneCase, what: str, observed: Observation,
                 exact: Observation) -> tuple[str, str] | None:
    """Two bodies that end past each other along the exact contact normal, still closing,
    where the exact run keeps them apart, with velocities no run explains: a pass-through
    that changed their speeds (named, ``error``)."""
    impacts, velocities = exact.impacts, observed.velocities
    if not (impacts and scene_runs.two_bodies_in_open_space(case)
            and isinstance(velocities, tuple)):
        return None
    mine, want = (_along(case, observed.positions, impacts[0]),
                  _along(case, exact.positions, impacts[0]))
    closing = _along(case, velocities, impacts[0])
    if not (want > 0 and mine < 0 and closing < 0):
        return None
    return Category.ERROR, (
        f"{what}: {PASSED_THROUGH} at step travel {step_travel(case):.3g} (|vb - va| dt / "
        f"2(ra + rb), dt = {case.dt or DEFAULT_DT:.3g} s): B ends {-mine:.3g} past A along "
        f"the exact contact normal, still closing at {-closing:.3g} m/s along it, where the "
        f"exact run leaves it {want:.3g} on its side, and its velocities are no run's a "
        "declared rule or the step gives")


def _run(case: SceneCase, conventions: Conventions, quantity: str, value: Value, what: str,
         observed: Observation, exact: Observation) -> tuple[str, str] | None:
    """The quantity judged against the run the engine gave (two bodies in open space)."""
    fit = scene_runs.find(case, conventions, observed, exact)
    if fit is None:
        return None
    off = _off(case, quantity, value, fit.state.get(quantity))
    return fit.judged(f"{what} against the exact run", quantity, off,
                      fit.slack(case, conventions, quantity), conventions)


def _speed_cap(case: SceneCase, conventions: Conventions, quantity: str, value: Value,
               what: str) -> tuple[str, str] | None:
    """A scene of more bodies, right (within the precision) for its speeds capped."""
    slow = scene_runs.capped(case, conventions)
    if slow is None or scene_runs.two_bodies_in_open_space(case):
        return None
    want = truth(slow).get(quantity)
    if want is None or isinstance(want, Undefined):
        return None
    there = relative_error(case, quantity, value, want)
    if there > PRECISION_FACTOR * conventions.rtol + 1e-9:
        return None
    return Category.CONVENTION, (
        f"{what}: the engine caps speeds at {scene_runs.scene_speed_cap(case, conventions):.4g}"
        f" m/s (declared max_speed, acting {conventions.max_speed_at}); against the exact "
        f"run with the capped speeds the error is {there:.3g}")


def _conserving(case: SceneCase, conventions: Conventions, quantity: str, what: str,
                observed: Observation, exact: Observation) -> tuple[str, str] | None:
    """Positions and velocities of a scene whose impacts chain (more than two bodies, or
    walls; no gravity): no one-event bound follows an impact met a step late through the
    impacts after it, so the run is judged by what every run of its impacts keeps, whenever
    they are met: momentum (no walls) and, at e = 1, the kinetic energy (else no gain), each
    within the precision and the declared damping.  Kept: ``timestep``, or ``convention``
    when the first impact closes below a declared restitution threshold, or when an impact
    of the exact run comes less than a step after another of the same body and the engine
    takes its bounces from the approach at the step's start (declared
    ``bounce_from_step_start``: :func:`~crosscheck.truth.motion_rules.chained`); the energy
    may then be lost, never gained; else None."""
    if (quantity not in ("positions", "velocities") or case.gravity is not None
            or scene_runs.two_bodies_in_open_space(case) or not exact.impacts):
        return None
    damp = damping_bound(case, conventions)
    allowed = (PRECISION_FACTOR * conventions.rtol + damp * (2.0 - damp)
               + 2 * stepped_rounding(case) / mean_radius(case) + 1e-12)
    kept: list[str] = []
    if not case.walls:
        pm = _off(case, "momentum", observed.momentum, exact.momentum)
        if not pm <= allowed:
            return None
        kept.append(f"momentum to {pm:.3g}")
    energy, start = observed.energy, exact.energy
    if not isinstance(energy, float) or not isinstance(start, float):
        return None
    initial = math.fsum(0.5 * b.mass * norm(b.velocity) ** 2 for b in case.bodies)
    gained = (energy - initial) / initial if initial > 0 else 0.0
    below = motion_rules.below_threshold(case, conventions, exact)
    pe = _off(case, "energy", energy, start)
    if case.restitution >= 1 and not below and not pe <= allowed:
        below = motion_rules.chained(case, conventions)  # a bounce the engine may not give
        if not below:
            return None
    if case.restitution >= 1 and not below:
        kept.append(f"the kinetic energy to {pe:.3g}")
    elif gained > allowed:
        return None
    else:
        kept.append(f"no kinetic energy gained (change {gained:+.3g})")
    if below:
        return Category.CONVENTION, (
            f"{what}: {below}, so the run's impacts are not the exact run's; the engine's run "
            f"keeps {' and '.join(kept)}, within the {allowed:.3g} its precision and "
            "declared damping allow")
    return Category.TIMESTEP, (
        f"{what}: {len(case.bodies)} bodies" + (f" and {len(case.walls)} walls"
                                                if case.walls else "")
        + f", {len(exact.impacts)} impacts in the exact run: an impact met at a step start "
        "moves every impact after it, so no one-event bound holds for the final state; the "
        f"engine's run keeps {' and '.join(kept)}, within the {allowed:.3g} its precision "
        "and declared damping allow, as every run of these impacts does")


def _unkept(case: SceneCase, quantity: str, observed: Observation,
            exact: Observation) -> str:
    """What a scene of chained impacts failed to keep (its error's numbers), '' otherwise."""
    if (quantity not in ("positions", "velocities") or case.gravity is not None
            or scene_runs.two_bodies_in_open_space(case) or not exact.impacts):
        return ""
    parts = [f"energy off by {_off(case, 'energy', observed.energy, exact.energy):.3g}"]
    if not case.walls:
        parts.insert(0, "momentum off by "
                     f"{_off(case, 'momentum', observed.momentum, exact.momentum):.3g}")
    return (f"; with {len(exact.impacts)} chained impacts the run does not keep what every "
            f"run of them keeps ({', '.join(parts)}, relative)")


def _off(case: SceneCase, quantity: str, value: Value | None, want: Value | None) -> float:
    if value is None or want is None or isinstance(value, Undefined) or isinstance(
            want, Undefined):
        return math.inf
    return relative_error(case, quantity, value, want)


def _category(case: SceneCase, conventions: Conventions, quantity: str, err: float,
              what: str, moved: float) -> tuple[str, str]:
    damp = damping_bound(case, conventions)
    damped = damp * (2.0 - damp) if quantity == "energy" else damp
    if quantity in ("momentum", "energy") and conventions.damping > 0 and err <= damped:
        return Category.CONVENTION, (
            f"{what}: the engine damps velocities (declared {conventions.damping:g} per s, up "
            f"to {damp:.3g} of a speed over the run, {damped:.3g} of the {quantity})")
    precision = PRECISION_FACTOR * conventions.rtol
    if quantity == "positions":
        precision = held(case, conventions) / mean_radius(case)
    if err <= precision:
        return Category.TOLERANCE, (
            f"{what}, within the engine's declared precision: {PRECISION_FACTOR:g} x rtol "
            f"{conventions.rtol:.3g}" + (f" of the coordinates ({extent(case):.3g}) = "
                                         f"{precision:.3g} mean radii"
                                         if quantity == "positions" else f" = {precision:.3g}"))
    stepped = gravity_step(case, quantity)
    if surrounded(case) and stepped > 0 and err <= stepped:
        return Category.TIMESTEP, (
            f"{what}, within one step of gravity on every body (|g| dt = {stepped:.3g}, in the "
            "same units): what a resting body carries between its contact's solves")
    dt = case.dt or DEFAULT_DT
    late = top_speed(case) * dt / mean_radius(case)
    if quantity == "positions" and err <= late:
        return Category.TIMESTEP, (
            f"{what}, within one step's travel at the top speed (v dt = {late:.3g} mean radii, "
            f"dt = {dt:.3g} s): one impact seen a step late")
    steps = f"{case.step_count} steps of dt = {dt:.3g} s"
    also = "" if quantity == "positions" or not math.isfinite(moved) else (
        f" (positions {moved:.3g} mean radii off)")
    return Category.ERROR, (f"{what}{also} after {steps}; not explained by one step's lag at "
                            "an impact, nor by the declared damping or precision")


def _aligned(case: SceneCase, impacts: Sequence[float] | None) -> str:
    on_step = aligned(case, impacts or ())
    if not on_step:
        return ""
    return (f"; note: {len(on_step)} impact(s) of the exact run fall on a step boundary "
            f"(t = {on_step[0]:.6g} = k x dt), where a step-late engine meets them on time")


def explain(case: SceneCase, conventions: Conventions, quantity: str, value: Value, err: float,
            exact: Observation, observed: Observation) -> tuple[str, str]:
    """The category and reason of a final-state quantity's disagreement (module docstring)."""
    what = f"{quantity} off by {err:.3g} {units(case, quantity)}"
    why = coarse(case, conventions)
    if why:
        return Category.TOLERANCE, f"{what}: {why}"
    named = (_run(case, conventions, quantity, value, what, observed, exact)
             or measure_rules.settled_positions(case, conventions, quantity, err, observed,
                                                exact)
             or drop_rules.inherited(case, conventions, quantity, what, observed, exact)
             or _speed_cap(case, conventions, quantity, value, what))
    if named:
        return named
    positions = observed.positions
    moved = (relative_error(case, "positions", positions, exact.positions)
             if isinstance(positions, tuple) and isinstance(exact.positions, tuple)
             else math.inf)
    category, reason = _category(case, conventions, quantity, err, what, moved)
    if (category == Category.ERROR and quantity == "energy"
            and isinstance(value, float) and isinstance(exact.energy, float)
            and value <= exact.energy):
        below = motion_rules.unbounced(case, conventions, exact)
        if below:
            return Category.CONVENTION, f"{what}, all of it lost: {below}"
    if category == Category.ERROR:
        return (_conserving(case, conventions, quantity, what, observed, exact)
                or _slowed_pass(case, what, observed, exact)
                or (category, reason + _unkept(case, quantity, observed, exact)))
    return category, reason


def judge(case: SceneCase, conventions: Conventions, quantity: str, value: Value, want: Value,
          exact: Observation, observed: Observation,
          default_tol: float) -> tuple[Status, float, float, str, str]:
    """Status, relative error, tolerance, category and reason of one scene quantity."""
    if quantity in MEASURES:
        return measure_rules.judge(case, conventions, quantity, value, want, exact, observed,
                                   default_tol)
    tol = tolerance(case, quantity, default_tol)
    if isinstance(value, Undefined):
        return (Status.DISAGREE, math.inf, tol, Category.ERROR,
                f"engine gave undefined ({value.reason}) where the reference is defined")
    err = relative_error(case, quantity, value, want)
    if err <= tol:
        return Status.AGREE, err, tol, "", ""
    category, reason = explain(case, conventions, quantity, value, err, exact, observed)
    assert quantity in QUANTITIES
    return Status.DISAGREE, err, tol, category, reason + _aligned(case, exact.impacts)
