"""The runs a stepping engine may give for a two-body scene in open space, each exact.

A scene's truth is the exact event-driven run (:mod:`crosscheck.truth.scenes`).  An
engine that steps answers one of a few other runs, each as exactly computable, when its
declared conventions say so (:func:`candidates`; :func:`find` picks the one it gave):

- **discrete**: the contact is found at the first step start ``k dt`` at which the two
  bodies, in free flight, overlap while approaching, and resolved there along the line of
  centres, with the scene's e (what an engine that samples contacts at step starts does);
  the bodies then fly apart from where they were at ``k dt``.  The one event allows the
  positions to differ by the overlap ``depth`` there (pushed out or not), and, for an engine
  that declares ``bounce_at_step_end`` (the bounce added after the step's positions), by
  the bounce's share of one step at the closing speed (:func:`step_end_lag`);
- **speculative**: for an engine that declares ``speculative_contacts``, the impact met at
  the start of the step that holds the exact first touch and resolved along the line of
  centres there (the bodies may close the gap left there before they turn: ``depth``);
- **pass-through**: no step start finds them overlapping while approaching, and the
  bodies fly on untouched (free flight);
- a declared **speed cap** makes every run start from the capped speeds, and a declared
  **restitution threshold** makes a first impact closing slower than it inelastic (e = 0).

Each run is a final state (positions, velocities, momentum, energy) and a cause
(:class:`Fit`) that names its category.  Which run an engine gave is found once per
pair in :mod:`crosscheck.truth.scene_rules`.

Over 400 lines: the runs and :func:`find`, which tries them in one order, are one
list (the table of docs/dynamics-and-stability.md mirrors it); each run is a few lines of
its own, and splitting them would split that order.

>>> from crosscheck.core.schema import CASE_ADAPTER
>>> scene = CASE_ADAPTER.validate_python({"id": "s", "description": "d",
...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "dt": 0.25, "bodies": [
...     {"center": [0, 0], "radius": 0.5, "mass": 1, "velocity": [1, 0]},
...     {"center": [1.6, 0], "radius": 0.5, "mass": 1, "velocity": [-1, 0]}]})
>>> found = first_overlap(scene)
>>> found.step, round(found.depth, 12)
(2, 0.4)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from crosscheck.core.contract import Conventions
from crosscheck.core.geometry import Vec, approach_speed, norm
from crosscheck.core.model import Category, Observation, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from crosscheck.truth.scenes import (
    PRECISION_FACTOR,
    damping_bound,
    held,
    mean_radius,
    relative_error,
    simulated_time,
    step_travel,
    stepped_rounding,
    truth,
)


@dataclass(frozen=True, slots=True)
class Overlap:
    """The first step start at which two bodies in free flight overlap while approaching."""

    step: int
    depth: float
    """How far they overlap there (m): ``ra + rb - |pb - pa|``."""
    centres: tuple[Vec, Vec]
    """Their centres at that step start."""


def _at(case: SceneCase, k: int) -> tuple[Vec, Vec]:
    dt = case.dt or DEFAULT_DT
    a, b = case.bodies[0], case.bodies[1]
    return (tuple(p + v * k * dt for p, v in zip(a.center, a.velocity, strict=True)),
            tuple(p + v * k * dt for p, v in zip(b.center, b.velocity, strict=True)))


def overlaps(case: SceneCase, margin: float = 0.0) -> tuple[list[int], list[int]]:
    """The step starts ``k dt`` at which the first two bodies, in free flight, overlap (come
    within ``margin`` of touching) while still approaching (a contact a discrete step can
    resolve), and those at which they overlap with their centres already past the closest
    point (receding: a contact normal taken there says they are moving apart, and the step
    lets them go)."""
    a, b = case.bodies[0], case.bodies[1]
    reach = a.radius + b.radius + margin
    dv = [w - v for v, w in zip(a.velocity, b.velocity, strict=True)]
    approaching: list[int] = []
    receding: list[int] = []
    for k in range(case.step_count + 1):
        pa, pb = _at(case, k)
        d = [y - x for x, y in zip(pa, pb, strict=True)]
        if norm(d) < reach:
            closing = math.fsum(x * y for x, y in zip(d, dv, strict=True)) < 0
            (approaching if closing else receding).append(k)
    return approaching, receding


def first_overlap(case: SceneCase, margin: float = 0.0) -> Overlap | None:
    """The first step start at which the first two bodies overlap (come within ``margin``
    of touching) while approaching."""
    seen, _ = overlaps(case, margin)
    if not seen:
        return None
    k = seen[0]
    pa, pb = _at(case, k)
    apart = norm([y - x for x, y in zip(pa, pb, strict=True)])
    return Overlap(k, case.bodies[0].radius + case.bodies[1].radius - apart, (pa, pb))


def resolve(case: SceneCase, centres: tuple[Vec, Vec], restitution: float) -> tuple[Vec, Vec]:
    """The two velocities after an impulse along the line of ``centres`` (A to B) with
    ``restitution``, from the scene's velocities (unchanged if they are not approaching)."""
    a, b = case.bodies[0], case.bodies[1]
    d = [y - x for x, y in zip(*centres, strict=True)]
    length = norm(d)
    if not length > 0:
        return tuple(a.velocity), tuple(b.velocity)
    n = [x / length for x in d]
    closing = math.fsum((w - v) * x for v, w, x in zip(a.velocity, b.velocity, n, strict=True))
    if closing >= 0:
        return tuple(a.velocity), tuple(b.velocity)
    j = -(1.0 + restitution) * closing / (1.0 / a.mass + 1.0 / b.mass)
    return (tuple(v - j / a.mass * x for v, x in zip(a.velocity, n, strict=True)),
            tuple(v + j / b.mass * x for v, x in zip(b.velocity, n, strict=True)))


def final_state(case: SceneCase, start: int, centres: tuple[Vec, Vec],
                velocities: tuple[Vec, Vec]) -> Observation:
    """The state at the end of the run of bodies at ``centres`` at step ``start`` flying on
    with ``velocities`` (total momentum and kinetic energy included)."""
    dt = case.dt or DEFAULT_DT
    left = (case.step_count - start) * dt
    positions = tuple(tuple(p + v * left for p, v in zip(c, w, strict=True))
                      for c, w in zip(centres, velocities, strict=True))
    masses = [b.mass for b in case.bodies]
    momentum = tuple(math.fsum(m * v[i] for m, v in zip(masses, velocities, strict=True))
                     for i in range(case.dim))
    energy = math.fsum(0.5 * m * math.fsum(x * x for x in v)
                       for m, v in zip(masses, velocities, strict=True))
    return Observation(positions=positions, velocities=velocities, momentum=momentum,
                       energy=energy)


def free_flight(case: SceneCase) -> Observation:
    """The pass-through run: every body keeps its velocity to the end."""
    return final_state(case, 0, _at(case, 0), (tuple(case.bodies[0].velocity),
                                                tuple(case.bodies[1].velocity)))


def two_bodies_in_open_space(case: SceneCase) -> bool:
    """The scene the runs of this module describe: two bodies, no gravity, no walls."""
    return (len(case.bodies) == 2 and not case.walls
            and not any(case.gravity or ()))


# --- which run the engine gave ------------------------------------------------------------


def scene_speed_cap(case: SceneCase, conventions: Conventions) -> float | None:
    """The declared speed cap at the scene's ``dt`` (None: none).

    A cap that acts at the end of every step (``"step"``) is a translation per step
    (Box2D's ``b2_maxTranslation``): declared as ``max_speed`` at the engine's
    ``time_step``, it is ``max_speed x time_step / dt`` at the scene's step.  A cap per
    coordinate (PyBullet's multibody clamp) and one before the bounce (Rapier's) are speeds.
    """
    if conventions.max_speed is None:
        return None
    if conventions.max_speed_at != "step":
        return conventions.max_speed
    per_step = conventions.max_speed * (conventions.time_step or (case.dt or DEFAULT_DT))
    return per_step / (case.dt or DEFAULT_DT)


def capped(case: SceneCase, conventions: Conventions) -> SceneCase | None:
    """``case`` with every initial velocity under the declared cap (None: no cap, or no body
    over it).  Box2D clips the velocity it integrates with and keeps it, PyBullet clamps
    each coordinate and Rapier the speed before integrating, so starting capped is the same
    motion."""
    cap = scene_speed_cap(case, conventions)
    if cap is None:
        return None
    slow = [conventions.clip(tuple(b.velocity), cap) for b in case.bodies]
    if all(tuple(v) == tuple(b.velocity) for v, b in zip(slow, case.bodies, strict=True)):
        return None
    bodies = tuple(b.model_copy(update={"velocity": v})
                   for b, v in zip(case.bodies, slow, strict=True))
    return case.model_copy(update={"bodies": bodies})


@dataclass(frozen=True, slots=True)
class Fit:
    """The run an engine's final state is, found once per pair: its category, its cause in
    words with the numbers, its final state, and what one event lets the positions differ."""

    category: str
    cause: str
    state: Observation
    depth: float = 0.0
    """How far (m) the event lets a centre differ from ``state`` (a pushed-out overlap)."""
    lag: float = 0.0
    """Of which the declared bounce at the step's end (m; :func:`step_end_lag`)."""

    def slack(self, case: SceneCase, conventions: Conventions, quantity: str) -> float:
        """The allowance of ``quantity`` against ``state`` (the errors' units): the
        precision (and a declared response precision, ``response_rtol``, on the bounce's
        velocities: twice that on the energy), the event's depth (positions) and the
        declared damping."""
        damp = damping_bound(case, conventions)
        response = conventions.response_rtol or 0.0  # the declared precision of a bounce
        precise = PRECISION_FACTOR * conventions.rtol + response * (2 if quantity == "energy"
                                                                    else 1)
        rounded = stepped_rounding(case)  # float64 over the steps: the contact's normal too
        reach = case.bodies[0].radius + case.bodies[1].radius
        # the line of centres from positions held to the precision tilts the impulse
        tilt = 2 * held(case, conventions) / reach if reach > 0 else 0.0
        if quantity == "positions":
            travel = damp * max(norm(b.velocity) for b in case.bodies) * float(
                simulated_time(case))
            return (held(case, conventions) + self.depth + travel + rounded) / mean_radius(case)
        precise += 2 * rounded / mean_radius(case) + tilt
        if quantity == "energy":
            return precise + damp * (2.0 - damp)
        return precise + damp

    def judged(self, what: str, name: str, off: float, slack: float,
               conventions: Conventions) -> tuple[str, str]:
        """The category and reason of a row (``what``: its error in words) whose ``name``
        (a quantity, or the drift) is ``off`` from this run's with ``slack`` allowed: the
        run's category within the slack (an error run's row follows it), else ``error``."""
        if not off <= slack:
            return Category.ERROR, (
                f"{what}: the engine's run is {self.cause} (its positions and velocities "
                f"match it), but its {name}: off by {off:.3g} from that run's, beyond the "
                f"{slack:.3g} its precision and declared damping allow")
        if self.category == Category.ERROR:
            return self.category, (f"{what}: the engine's run is {self.cause}, an error its "
                                   f"{name} follows (it is that run's to {off:.3g})")
        allowed = ("the precision"
                   + (", the overlap at the contact" if name == "positions" and self.depth
                      else "")
                   + (f", the declared bounce at the step's end ({self.lag:.3g} m)"
                      if name == "positions" and self.lag > 0 else "")
                   + (", the declared damping" if conventions.damping > 0 else ""))
        return self.category, (f"{what}; the engine's run is {self.cause}: against that run "
                               f"its {name}: off by {off:.3g}, within {slack:.3g} "
                               f"({allowed})")

    def explains(self, case: SceneCase, conventions: Conventions, quantity: str,
                 value: Value) -> float | None:
        """The error of ``value`` against the run's state when within its slack, else None."""
        want = self.state.get(quantity)
        if want is None or isinstance(want, Undefined) or isinstance(value, Undefined):
            return None
        off = relative_error(case, quantity, value, want)
        return off if off <= self.slack(case, conventions, quantity) else None


def _closing(case: SceneCase, centres: tuple[Vec, Vec]) -> float:
    """How fast the scene's two bodies close along the line of ``centres`` (NaN: none)."""
    return approach_speed(*centres, case.bodies[0].velocity, case.bodies[1].velocity)


def _bounce(case: SceneCase, conventions: Conventions, centres: tuple[Vec, Vec],
            observed: Observation) -> tuple[float, str]:
    """The restitution the engine's run takes at an impact along the line of ``centres``:
    0 below a declared threshold; for a declared soft or predictive contact the e' of its
    own velocities (kept if in [0, e]); else the scene's e."""
    speed = _closing(case, centres)
    threshold = conventions.restitution_threshold
    if threshold > 0 and case.restitution > 0 and speed < threshold:
        return 0.0, (f"the impact closes at {speed:.3g} m/s along the line of centres, below "
                     f"the declared restitution threshold {threshold:g} m/s: no bounce")
    velocities = observed.velocities
    if conventions.bounce_may_lose and isinstance(velocities, tuple) and speed > 0:
        after = approach_speed(*centres, velocities[0], velocities[1])
        kept = -after / speed
        if -1e-6 <= kept <= case.restitution + 1e-6:
            model = conventions.restitution_model
            return max(kept, 0.0), (
                f"the declared {model} contact model sets the bounce: its velocities keep "
                f"e' = {kept:.3g} of the approach along the line of centres, where the "
                f"scene asks e = {case.restitution:g}")
    return case.restitution, ""


def _words(*parts: str) -> str:
    return "; ".join(p for p in parts if p)


def centres_at(case: SceneCase, t: float) -> tuple[Vec, Vec]:
    a, b = case.bodies[0], case.bodies[1]
    return (tuple(p + v * t for p, v in zip(a.center, a.velocity, strict=True)),
            tuple(p + v * t for p, v in zip(b.center, b.velocity, strict=True)))


def _exact(start: SceneCase, restitution: float) -> Observation:
    return truth(start.model_copy(update={"restitution": restitution}))


def _pass(start: SceneCase, conventions: Conventions, cap: str) -> Fit:
    seen, past = overlaps(start, contact_distance(conventions))
    sampled = (f"no step start finds the two within {contact_distance(conventions):.3g} m "
               "of touching while approaching" + (
                   f" (at the start of step {past[0]} they overlap, but with their centres "
                   "already past each other: moving apart along the line of centres)"
                   if past else ""))
    head = (f"{PASSED_THROUGH} at step travel {step_travel(start):.3g} (|vb - va| dt / "
            f"2(ra + rb), dt = {start.dt or DEFAULT_DT:.3g} s)")
    if conventions.sampled_contacts and not seen:
        return Fit(Category.TIMESTEP, _words(cap, f"{head}: the engine looks for contacts "
                                             f"only at step starts (declared sampled_contacts)"
                                             f", and {sampled}"), free_flight(start))
    where = (f"they overlap, approaching, at the start of step {seen[0]}" if seen
             else sampled)
    declared = ("" if conventions.sampled_contacts
                else "; the engine does not declare sampled contacts")
    return Fit(Category.ERROR, _words(cap, f"{head}: {where}{declared}"), free_flight(start))


def step_end_lag(start: SceneCase, conventions: Conventions, centres: tuple[Vec, Vec],
                 restitution: float, gap: float = 0.0) -> float:
    """How far (m) a centre may trail a run resolved at a step start when the engine adds
    the bounce at the end of that step (declared ``bounce_at_step_end``; 0 otherwise): the
    bodies close the ``gap`` left there and stop, and part with the bounce ``e`` x closing a
    step late, each centre by its share ``m_other / (ma + mb)`` of
    ``(1 + e) gap + e closing dt``.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> scene = CASE_ADAPTER.validate_python({"id": "s", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "dt": 0.25, "bodies": [
    ...     {"center": [0, 0], "radius": 0.5, "mass": 1, "velocity": [1, 0]},
    ...     {"center": [1.6, 0], "radius": 0.5, "mass": 1, "velocity": [-1, 0]}]})
    >>> step_end_lag(scene, Conventions(bounce_at_step_end=True), _at(scene, 2), 1.0)
    0.25
    """
    if not conventions.bounce_at_step_end:
        return 0.0
    a, b = start.bodies[0], start.bodies[1]
    share = max(a.mass, b.mass) / (a.mass + b.mass) if a.mass > 0 and b.mass > 0 else 1.0
    closing = max(_closing(start, centres), 0.0)
    return share * ((1.0 + restitution) * max(gap, 0.0)
                    + restitution * closing * (start.dt or DEFAULT_DT))


def _lag_words(start: SceneCase, centres: tuple[Vec, Vec], restitution: float, lag: float,
               k: int) -> str:
    """The reason's words for a declared bounce at the step's end (``lag`` m; '' if 0)."""
    if not lag > 0:
        return ""
    closing = max(_closing(start, centres), 0.0)
    return (f"the engine adds the bounce at the end of step {k}, after that step's positions "
            f"(declared bounce_at_step_end): e x closing = {restitution:g} x {closing:.3g} "
            f"m/s a step of {start.dt or DEFAULT_DT:.3g} s late, each centre up to {lag:.3g} "
            "m behind")


def _room(start: SceneCase, found: Overlap, conventions: Conventions,
          restitution: float) -> float:
    """How far a centre may differ from the discrete run: the overlap pushed out, or, for a
    contact made within the declared verdict margin before the bodies touch, the gap left
    plus one step at the closing speed (the solver may close it before it turns them); and
    a declared bounce at the step's end (:func:`step_end_lag`)."""
    if found.depth >= 0:
        return found.depth + step_end_lag(start, conventions, found.centres, restitution)
    gap = -found.depth
    closes = gap + max(_closing(start, found.centres), 0.0) * (start.dt or DEFAULT_DT)
    return max(closes, step_end_lag(start, conventions, found.centres, restitution, gap))


def _speculative(start: SceneCase, conventions: Conventions, observed: Observation,
                 first: float, cap: str) -> Fit:
    """The run of an engine that declares speculative contacts: the impact met at the start
    ``k dt`` of the step that holds the exact first touch, resolved along the line of
    centres there.  Within that step the solver may first close the gap left at ``k dt``
    and turn the bodies at its end: each centre may differ by that gap plus one step at
    the closing speed along the line of centres (``depth``)."""
    dt = start.dt or DEFAULT_DT
    k = max(0, math.floor(first / dt))
    if k * dt >= first and k > 0:  # a touch exactly on a step start is met by the step before
        k -= 1
    centres = centres_at(start, k * dt)
    e, bounce = _bounce(start, conventions, centres, observed)
    gap = max(0.0, math.dist(*centres) - math.fsum(b.radius for b in start.bodies[:2]))
    closing = max(_closing(start, centres), 0.0)
    where = (f"the contact made at the start of step {k} (t = {k * dt:.4g} s, the step that "
             f"holds the exact touch at {first:.4g} s; gap {gap:.3g} m) for the gap the step "
             "closes (declared speculative_contacts), resolved along the line of centres there")
    category = Category.CONVENTION if cap or bounce else Category.TIMESTEP
    lag = step_end_lag(start, conventions, centres, e, gap)
    return Fit(category, _words(cap, bounce, where, _lag_words(start, centres, e, lag, k)),
               final_state(start, k, centres, resolve(start, centres, e)),
               max(gap + closing * dt, lag), lag)


def flown(start: SceneCase, t0: float, centres: tuple[Vec, Vec],
           velocities: tuple[Vec, Vec]) -> Observation:
    """The final state of bodies at ``centres`` at time ``t0`` flying on with
    ``velocities``."""
    left = float(simulated_time(start)) - t0
    ends = (tuple(p + v * left for p, v in zip(centres[0], velocities[0], strict=True)),
            tuple(p + v * left for p, v in zip(centres[1], velocities[1], strict=True)))
    return final_state(start, start.step_count, ends, velocities)


def _swept(start: SceneCase, conventions: Conventions, observed: Observation,
           cap: str) -> Fit | None:
    """The run of an engine that sweeps its bodies (no sampled contacts) and aims its time
    of impact at a declared overlap (``toi_target`` < 0: Box2D's bullets, three linear slops
    deep): the impact met where the surfaces overlap by that much, resolved along the line
    of centres there; each centre may differ by the overlap and the query's tolerance."""
    target = conventions.toi_target
    if conventions.sampled_contacts or conventions.speculative_contacts or not target < 0:
        return None
    a, b = start.bodies[0], start.bodies[1]
    reach = a.radius + b.radius + target
    dp = [y - x for x, y in zip(a.center, b.center, strict=True)]
    dv = [w - v for v, w in zip(a.velocity, b.velocity, strict=True)]
    qa = math.fsum(x * x for x in dv)
    qb = math.fsum(x * y for x, y in zip(dp, dv, strict=True))
    qc = math.fsum(x * x for x in dp) - reach * reach
    disc = qb * qb - qa * qc
    if not (qa > 0 and reach > 0 and disc >= 0 and qb < 0):
        return None
    t = qc / (-qb + math.sqrt(disc))  # the first root, without cancellation
    if not 0 <= t <= float(simulated_time(start)):
        return None
    t = _aimed(start, conventions, observed, dp, dv, t)
    centres = centres_at(start, t)
    e, bounce = _bounce(start, conventions, centres, observed)
    depth = a.radius + b.radius - math.dist(*centres)
    where = (f"the contact met at t = {t:.4g} s where the surfaces overlap by {depth:.3g} m "
             f"(the declared toi_target {-target:.3g} m, to its toi_tolerance "
             f"{conventions.toi_tolerance:.3g} m: a swept engine's time of impact), resolved "
             "along the line of centres there")
    category = Category.CONVENTION if cap or bounce else Category.TIMESTEP
    return Fit(category, _words(cap, bounce, where),
               flown(start, t, centres, resolve(start, centres, e)),
               -target + conventions.toi_tolerance)


def _aimed(start: SceneCase, conventions: Conventions, observed: Observation,
           dp: list[float], dv: list[float], t: float) -> float:
    """The time at which the line of centres is the direction of the engine's own impulse on
    B, when the surfaces overlap there by the declared ``toi_target`` to its
    ``toi_tolerance`` (the query may stop anywhere in that band); else ``t``."""
    velocities = observed.velocities
    if not (isinstance(velocities, tuple) and len(velocities) == 2):
        return t
    b = start.bodies[1]
    push = [float(y) - x for x, y in zip(b.velocity, velocities[1], strict=True)]
    if not norm(push) > 0:
        return t
    n = [x / norm(push) for x in push]
    along = math.fsum(x * y for x, y in zip(dv, n, strict=True))
    across = [x - along * y for x, y in zip(dv, n, strict=True)]
    if not math.fsum(x * x for x in across) > 0:
        return t
    # the time at which dp + dv t has no part across n (least squares in 3-D)
    off = [x - math.fsum(p * q for p, q in zip(dp, n, strict=True)) * y
           for x, y in zip(dp, n, strict=True)]
    seen = -math.fsum(x * y for x, y in zip(off, across, strict=True)) / math.fsum(
        x * x for x in across)
    reach = norm([p + v * seen for p, v in zip(dp, dv, strict=True)])
    overlap = start.bodies[0].radius + b.radius - reach
    band = conventions.toi_tolerance + PRECISION_FACTOR * conventions.rtol * reach
    return seen if abs(overlap + conventions.toi_target) <= band else t


def _rubbed(start: SceneCase, conventions: Conventions, observed: Observation,
            contact: tuple[float, tuple[Vec, Vec], float, str]) -> Fit | None:
    """The run met at ``contact`` (time, centres, depth, its words) with the engine's own
    velocities after it, when a declared friction explains them: momentum kept, the bounce
    along the line of centres the scene's e, and a tangential impulse within ``mu`` times the
    normal one (as for a response, :mod:`crosscheck.truth.contact_model`)."""
    velocities = observed.velocities
    mu = conventions.friction
    if not (mu > 0 and isinstance(velocities, tuple) and len(velocities) == 2):
        return None
    t0, centres, depth, where = contact
    a, b = start.bodies[0], start.bodies[1]
    va, vb = (tuple(float(x) for x in v) for v in velocities)
    d = [y - x for x, y in zip(*centres, strict=True)]
    if not (norm(d) > 0 and all(math.isfinite(x) for x in va + vb)):
        return None
    n = [x / norm(d) for x in d]
    top = max(norm(a.velocity), norm(b.velocity))
    slack = (PRECISION_FACTOR * conventions.rtol + damping_bound(start, conventions)) * top
    slack += 1e-12 * top
    moved_a = [y - x for x, y in zip(a.velocity, va, strict=True)]
    moved_b = [y - x for x, y in zip(b.velocity, vb, strict=True)]
    drift = norm([a.mass * x + b.mass * y for x, y in zip(moved_a, moved_b, strict=True)])
    before = math.fsum((w - v) * x for v, w, x in zip(a.velocity, b.velocity, n, strict=True))
    after = math.fsum((w - v) * x for v, w, x in zip(va, vb, n, strict=True))
    if not (before < 0 and drift <= (a.mass + b.mass) * slack):
        return None
    kept = -after / before
    if abs(kept - start.restitution) > 2 * slack / -before:
        return None
    impulse = [b.mass * x for x in moved_b]
    normal = math.fsum(j * x for j, x in zip(impulse, n, strict=True))
    tangential = norm([j - normal * x for j, x in zip(impulse, n, strict=True)])
    if tangential > mu * abs(normal) + 2 * b.mass * slack or tangential <= 2 * b.mass * slack:
        return None
    state = flown(start, t0, centres, (va, vb))
    return Fit(Category.CONVENTION, _words(where, (
        f"declared friction {mu:g}: the engine's velocities after it keep the momentum (to "
        f"{drift:.3g}) and e = {kept:.4g} along the line of centres, with a tangential "
        f"impulse {tangential:.3g} within {mu:g} x the normal one {abs(normal):.3g} (the "
        "textbook is frictionless)")), state, depth)


def candidates(case: SceneCase, conventions: Conventions, observed: Observation,
               exact: Observation) -> list[Fit]:
    """The runs (module docstring) a two-body scene in open space may be, in the order they
    are tried: from the initial speeds, then from the capped ones; for each the exact contact
    (only when a declared rule changes it), the discrete one, then none."""
    out: list[Fit] = []
    starts: list[tuple[SceneCase, str]] = [(case, "")]
    slow = capped(case, conventions)
    if slow is not None:
        top = max(norm(b.velocity) for b in case.bodies)
        starts.append((slow, (
            f"the engine caps speeds at {scene_speed_cap(case, conventions):.4g} m/s "
            f"(declared max_speed {conventions.max_speed:.4g}, acting "
            f"{conventions.max_speed_at}, at every step) and the top initial speed is "
            f"{top:.4g}")))
    for start, cap in starts:
        impacts = (exact if start is case else _exact(start, start.restitution)).impacts
        if impacts:
            e, bounce = _bounce(start, conventions, centres_at(start, impacts[0]), observed)
            if cap or bounce:
                touch = centres_at(start, impacts[0])
                held_back = (max(_closing(start, touch), 0.0) * (start.dt or DEFAULT_DT)
                             if conventions.restitution_model == "predictive" else 0.0)
                out.append(Fit(Category.CONVENTION, _words(
                    cap, bounce, "the contact met where the bodies touch" + (
                        " (a predictive contact clamps the motion at the hit and bounces "
                        "it the step after: up to one step at the closing speed)"
                        if held_back else "")), _exact(start, e), held_back))
        swept = _swept(start, conventions, observed, cap)
        if swept is not None:
            out.append(swept)
        if impacts and conventions.speculative_contacts:
            out.append(_speculative(start, conventions, observed, impacts[0], cap))
        found = first_overlap(start, contact_distance(conventions))
        if found is not None:
            e, bounce = _bounce(start, conventions, found.centres, observed)
            state = final_state(start, found.step, found.centres,
                                resolve(start, found.centres, e))
            where = (f"the contact found at the start of step {found.step} (t = "
                     f"{found.step * (start.dt or DEFAULT_DT):.4g} s), the first step start "
                     f"at which the bodies are within {contact_distance(conventions):.3g} m "
                     f"of touching (overlap {found.depth:.3g} m) while approaching, and "
                     "resolved along the line of centres there")
            category = Category.CONVENTION if cap or bounce else Category.TIMESTEP
            lag = step_end_lag(start, conventions, found.centres, e, -found.depth)
            out.append(Fit(category, _words(cap, bounce, where, _lag_words(
                start, found.centres, e, lag, found.step)), state,
                _room(start, found, conventions, e), lag))
        out.append(_pass(start, conventions, cap))
        if impacts:
            met = (impacts[0], centres_at(start, impacts[0]), 0.0,
                   _words(cap, "the contact met where the bodies touch"))
            out += [f for f in (_rubbed(start, conventions, observed, met),) if f]
        if found is not None:
            dt = start.dt or DEFAULT_DT
            at = (found.step * dt, found.centres,
                  _room(start, found, conventions, start.restitution),
                  _words(cap, f"the contact found at the start of step {found.step}"))
            out += [f for f in (_rubbed(start, conventions, observed, at),) if f]
    return out


def find(case: SceneCase, conventions: Conventions, observed: Observation,
         exact: Observation) -> Fit | None:
    """The first run of :func:`candidates` whose positions and velocities the engine's final
    state matches within its slack (None: none, the exact run itself matches, or not a
    two-body scene in open space)."""
    if not two_bodies_in_open_space(case) or not exact.impacts:
        return None
    positions, velocities = observed.positions, observed.velocities
    if not (isinstance(positions, tuple) and isinstance(velocities, tuple)):
        return None
    if _matches(Fit("", "", exact), case, conventions, positions, velocities):
        return None  # the exact run itself: each quantity is judged on its own
    for fit in candidates(case, conventions, observed, exact):
        if _matches(fit, case, conventions, positions, velocities):
            return fit
    return None


def _matches(fit: Fit, case: SceneCase, conventions: Conventions, positions: Value,
             velocities: Value) -> bool:
    return (fit.explains(case, conventions, "positions", positions) is not None
            and fit.explains(case, conventions, "velocities", velocities) is not None)


def contact_distance(conventions: Conventions) -> float:
    """How close to touching a step start must bring two spheres for the engine to make a
    contact: its declared verdict margin at a sphere (a prediction distance), else 0."""
    return max(conventions.verdict_margin_for("sphere"), 0.0)


PASSED_THROUGH = "the bodies passed through each other"
"""The words of a missed impact in a scene row's reason (the named failure), read by the
stability study's ``step_travel`` walk."""
