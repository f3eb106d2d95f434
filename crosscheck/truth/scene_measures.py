"""Scene measures under gravity and between walls: what they are, on both sides.

A scene with ``gravity`` or ``walls`` (:func:`surrounded`) is run exactly by
:mod:`reference_impl.gravity` (or, with walls and no gravity, by the faster
:mod:`reference_impl.events`); an engine records its states every :func:`record_every` steps
(:class:`~crosscheck.core.model.Trajectory`).  Six measures are scene quantities of their own:

- ``settle`` (m): every body's signed gap to the ground at the end (negative: sunk into it);
  defined when the exact run ends with every body resting; the error is the largest
  difference from the exact gaps;
- ``jitter`` (m/s): the largest speed of any body over the run's second half; defined when
  every body rests in the exact run over all of it (exact: 0);
- ``energy_drift`` (1/s): ``(E(T) - E(0)) / (E_scale T)`` with the total energy ``E``
  (kinetic, plus ``-m g . (p - p0)`` under gravity) and :func:`energy_scale`; every scene;
- ``apex`` (m): body 0's apex heights above the ground (the gap) between its bounces; the
  error is the largest ``|engine / exact - 1|`` over the bounces both have;
- ``bounce_time`` (s): the times of body 0's bounces on the ground; the error is the largest
  difference over the bounces both have;
- ``divergence`` (s): the first recorded time at which a centre is further than
  ``diverge_at`` mean radii from the exact one (the simulated time when never); the error
  is the share of the run left, ``1 - t / T``.

The exact apexes and bounce times count only bounces an engine stepping at ``dt`` can
resolve: a flight of at least :data:`MIN_FLIGHT_STEPS` steps before the bounce, and its apex
within the run.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

from crosscheck.core.geometry import Vec, norm
from crosscheck.core.model import Trajectory, Undefined, Value
from crosscheck.core.schema import DEFAULT_DT, SceneCase
from reference_impl import scene_measures as plain

MEASURES = ("settle", "jitter", "energy_drift", "apex", "bounce_time", "divergence")
MAX_SAMPLES = 20_000
"""Recorded body states per scene at most (bodies x samples): the stride grows past it."""
MIN_FLIGHT_STEPS = 4
"""An exact bounce counts (apex, bounce time) when the flight before it lasts this many
steps or more: a shorter flight is below what stepping at dt can show."""


def gravity(case: SceneCase) -> Vec:
    """The scene's gravity (zeros when it declares none)."""
    return tuple(case.gravity) if case.gravity else (0.0,) * case.dim


def surrounded(case: SceneCase) -> bool:
    """The scene has gravity or walls (else it is open space, scored as before)."""
    return bool(case.walls) or any(gravity(case))


def record_every(case: SceneCase) -> int:
    """Steps between recorded states: 0 (none) in open space, else every step while
    bodies x steps stays within :data:`MAX_SAMPLES`, else the smallest stride that does."""
    if not surrounded(case):
        return 0
    return max(1, math.ceil(case.step_count * len(case.bodies) / MAX_SAMPLES))


def sample_steps(case: SceneCase) -> list[int]:
    """The steps after which a state is recorded (0: the start; the last step always)."""
    every, steps = record_every(case), case.step_count
    if every == 0:
        return []
    return [*range(0, steps, every), steps]


def ground(case: SceneCase) -> int | None:
    """The index of the first wall facing gravity (a ground), or None."""
    return plain.ground(gravity(case), walls(case))


def walls(case: SceneCase) -> list[tuple[Vec, float]]:
    """The scene's walls as ``(normal, offset)`` pairs."""
    return [(tuple(w.normal), w.offset) for w in case.walls]


def bodies(case: SceneCase) -> list[tuple[Vec, float, float, Vec]]:
    """The scene's bodies as ``(centre, radius, mass, velocity)``."""
    return [(tuple(b.center), b.radius, b.mass, tuple(b.velocity)) for b in case.bodies]


def gap(case: SceneCase, wall: int, center: Sequence[float], radius: float) -> float:
    """A sphere's signed gap to wall ``wall`` (negative: penetrating)."""
    return plain.gap(walls(case), wall, center, radius)


def top_speed(case: SceneCase) -> float:
    """The largest speed a body can reach in the exact run: its initial speed, plus what
    falling from its height above the ground adds (walls and impacts with e <= 1 add none).

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> top_speed(CASE_ADAPTER.validate_python({"id": "d", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "gravity": [0, -2],
    ...     "walls": [{"normal": [0, 1]}], "bodies": [{"center": [0, 5], "radius": 1,
    ...     "mass": 1, "velocity": [3, 0]}]}))
    5.0
    """
    g, floor = norm(gravity(case)), ground(case)
    speeds = []
    for b in case.bodies:
        v2 = math.fsum(v * v for v in b.velocity)
        if g > 0 and floor is not None:
            v2 += 2 * g * max(gap(case, floor, b.center, b.radius), 0.0)
        speeds.append(math.sqrt(v2))
    return max(speeds, default=0.0)


def energy_scale(case: SceneCase) -> float:
    """The initial kinetic energy, plus under gravity each body's ``m |g| h`` with ``h`` its
    centre's height above the ground (its centre's height over the scene when none)."""
    return plain.energy_scale(gravity(case), walls(case), bodies(case))


def total_energy(case: SceneCase, positions: Sequence[Vec], velocities: Sequence[Vec]) -> float:
    """Kinetic energy plus ``-m g . (p - p0)`` (potential from each body's start)."""
    return plain.total_energy(gravity(case), bodies(case), positions, velocities)


def drift(case: SceneCase, energy_end: float, duration: float) -> float:
    """``(E(T) - E(0)) / (E_scale T)`` (E(0) = the initial kinetic energy)."""
    return plain.drift(gravity(case), walls(case), bodies(case), energy_end, duration)


def bounces(case: SceneCase, trajectory: Trajectory) -> tuple[Vec, Vec]:
    """Body 0's bounce times and apexes in recorded states: a bounce is a record at which the
    normal velocity (along the ground's normal) has turned from closing to opening, and the
    apex after it the largest gap before the velocity turns closing again (an apex not
    reached by the end is not counted).  Returns ``(apexes, times)``.

    >>> from crosscheck.core.schema import CASE_ADAPTER
    >>> case = CASE_ADAPTER.validate_python({"id": "d", "description": "d",
    ...     "kind": "sphere_scene", "dim": 2, "duration": 1.0, "gravity": [0, -10],
    ...     "walls": [{"normal": [0, 1]}], "bodies": [{"center": [0, 1], "radius": 1,
    ...     "mass": 1, "velocity": [0, 0]}]})
    >>> heights, speeds = [1.0, 0.0, 1.0, 2.0, 1.5], [-1.0, 1.0, 1.0, -1.0, -1.0]
    >>> run = Trajectory((0.0, 0.1, 0.2, 0.3, 0.4), tuple(((0.0, h + 1),) for h in heights),
    ...                  tuple(((0.0, v),) for v in speeds), (0.0,) * 5)
    >>> bounces(case, run)
    ((2.0,), (0.1,))
    """
    apexes, times = plain.bounces(gravity(case), walls(case), bodies(case), trajectory.times,
                                  trajectory.positions, trajectory.velocities)
    return apexes, times


def engine_measures(case: SceneCase, positions: Sequence[Vec], velocities: Sequence[Vec],
                    trajectory: Trajectory | None) -> dict[str, Value]:
    """What an engine's run gives for every measure but ``divergence`` (judged against the
    exact trajectory, :func:`divergence`)."""
    duration = case.step_count * (case.dt or DEFAULT_DT)
    track = None if trajectory is None else (
        trajectory.times, trajectory.positions, trajectory.velocities)
    found = plain.engine_measures(gravity(case), walls(case), bodies(case), duration,
                                  positions, velocities, track)
    out: dict[str, Value] = {q: Undefined(v) if isinstance(v, str) else v
                             for q, v in found.items()}
    return out | {"divergence": Undefined(NOT_RECORDED)}


NO_GROUND = plain.NO_GROUND
NOT_RECORDED = plain.NOT_RECORDED


def divergence(case: SceneCase, mine: Trajectory, exact: Trajectory) -> float:
    """The first recorded time at which a centre is more than ``diverge_at`` mean radii from
    the exact one (the run's end time when none is)."""
    reach = case.diverge_at * math.fsum(b.radius for b in case.bodies) / len(case.bodies)
    for t, ps, qs in zip(mine.times, mine.positions, exact.positions, strict=False):
        if any(not norm([x - y for x, y in zip(p, q, strict=True)]) <= reach
               for p, q in zip(ps, qs, strict=True)):
            return t
    return mine.times[-1] if mine.times else 0.0


def exact_bounces(case: SceneCase, events: Sequence[tuple[Fraction, int, Fraction]]
                  ) -> tuple[Vec, Vec]:
    """Exact apexes and bounce times of body 0 from its ground bounces ``(time, body,
    outgoing normal speed)``: apex ``u**2 / 2|g|`` above the ground (its gap at the bounce
    is 0 up to a rounded event time), kept while the flight before the bounce lasts
    :data:`MIN_FLIGHT_STEPS` steps and the apex falls within the run."""
    g = Fraction(norm(gravity(case)))
    dt = Fraction(case.dt or DEFAULT_DT)
    end = case.step_count * dt
    apexes: list[float] = []
    times: list[float] = []
    last = Fraction(0)
    for t, body, u in events:
        if body != 0 or g == 0:
            continue
        if t - last < MIN_FLIGHT_STEPS * dt and times:
            break
        last = t
        times.append(float(t))
        if t + u / g <= end:
            apexes.append(float(u * u / (2 * g)))
    return tuple(apexes), tuple(times)
