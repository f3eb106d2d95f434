"""A scene script's gravity, walls and measures: inputs, recording and the measures as script text.

Every scene script (:mod:`~crosscheck.studies.repro.scenes`, ``scenes_box2d``,
``scenes_mujoco``, ``scenes_rapier``) gets the scene's ``GRAVITY`` (zeros in open space),
its ``WALLS`` (``(normal, offset)`` pairs, :class:`adapters.scene.Wall`) and ``RECORD_EVERY``
(:func:`crosscheck.truth.scene_measures.record_every`: 0 in open space) as inputs, and
:data:`FUNCTIONS`: a compact copy of the harness's measures and of the adapters' recording
loop, as script text.  The engine part steps the scene with ``record(step, read)`` when it
has gravity or walls (states every ``RECORD_EVERY`` steps, as ``adapters.scene.
step_and_record`` records them), else with a plain loop, and ends with :data:`FINISH`, which
computes every measure as ``scene_measures.engine_measures`` does.  :func:`answer_lines`
prints them: all five an engine's run gives with gravity or walls (``divergence`` is judged
by crosscheck against the exact trajectory: a comment with the recorded value), and in open
space ``energy_drift`` only (the others are not defined without a ground and a trajectory:
a comment).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from crosscheck.core.schema import SceneCase
from crosscheck.studies.repro.code import literal, vector
from crosscheck.truth import scene_measures
from crosscheck.truth.scenes import QUANTITIES

Input = tuple[str, str, str, str]

MEASURED = ("settle", "jitter", "energy_drift", "apex", "bounce_time")
"""The measures a script computes from the engine's states (every one but ``divergence``)."""
OPEN_SPACE = tuple(q for q in scene_measures.MEASURES if q != "energy_drift")
"""The measures an open-space scene has no value for (no ground, no recorded trajectory)."""

FUNCTIONS = '''\
# The harness's scene measures, computed from the engine's states as crosscheck computes
# them.  Each function mirrors the one of the same name in crosscheck/truth/scene_measures.py
# (norm: crosscheck/core/geometry.py; record: step_and_record in adapters/scene.py); None
# stands for a measure with no value (crosscheck records null).
def norm(v):
    return math.sqrt(math.fsum(x * x for x in v))


def ground():
    # the index of the first wall facing gravity (a ground), or None
    for k, (normal, _) in enumerate(WALLS):
        if math.fsum(n * x for n, x in zip(normal, GRAVITY, strict=True)) < 0:
            return k
    return None


def gap(wall, center, radius):
    # a sphere's signed gap to wall number `wall` (negative: penetrating)
    normal, offset = WALLS[wall]
    return math.fsum(n * x for n, x in zip(normal, center, strict=True)) - offset - radius


def energy_scale():
    # initial kinetic energy, plus under gravity each body's m |g| h (h: its centre's height
    # above the ground; its radius when there is none)
    g, floor = norm(GRAVITY), ground()
    kinetic = math.fsum(0.5 * m * math.fsum(v * v for v in u) for _, _, m, u in BODIES)
    if g == 0.0:
        return kinetic
    heights = [gap(floor, c, 0.0) if floor is not None else r for c, r, _, _ in BODIES]
    return kinetic + math.fsum(b[2] * g * h for b, h in zip(BODIES, heights, strict=True))


def total_energy(positions, velocities):
    # kinetic energy plus -m g . (p - p0) (potential from each body's start)
    return math.fsum(
        0.5 * b[2] * math.fsum(v * v for v in vel)
        - b[2] * math.fsum(q * (x - x0) for q, x, x0 in zip(GRAVITY, p, b[0], strict=True))
        for b, p, vel in zip(BODIES, positions, velocities, strict=True))


def drift(energy_end, duration):
    # (E(T) - E(0)) / (E_scale T), E(0) the initial kinetic energy
    start = math.fsum(0.5 * m * math.fsum(v * v for v in u) for _, _, m, u in BODIES)
    scale = energy_scale()
    return (energy_end - start) / ((scale if scale > 0 else 1.0) * max(duration, 1e-300))


def bounces(trajectory):
    # body 0's bounces: a record where its normal velocity turned from closing (through
    # records of exactly 0 too) to opening; the apex after it, the largest gap before the
    # velocity turns closing again
    floor = ground()
    if floor is None:
        return (), ()
    times, positions, velocities = trajectory
    normal = WALLS[floor][0]
    heights = [gap(floor, ps[0], BODIES[0][1]) for ps in positions]
    speeds = [math.fsum(n * v for n, v in zip(normal, vs[0], strict=True)) for vs in velocities]
    apexes, bounced = [], []
    top, rising, falling = -math.inf, False, False
    for k in range(1, len(speeds)):
        falling = speeds[k - 1] < 0 or (falling and speeds[k - 1] == 0)  # through a 0 too
        if falling and speeds[k] > 0:
            bounced.append(times[k])
            top, rising = heights[k], True
        elif rising:
            top = max(top, heights[k])
            if speeds[k] <= 0:
                apexes.append(top)
                rising = False
    return tuple(apexes), tuple(bounced)


def engine_measures(positions, velocities, trajectory):
    # every measure but divergence (crosscheck judges that against the exact trajectory)
    duration = STEPS * DT
    out = {"energy_drift": drift(total_energy(positions, velocities), duration)}
    floor = ground()
    out["settle"] = None if floor is None else tuple(
        gap(floor, p, b[1]) for p, b in zip(positions, BODIES, strict=True))
    if trajectory is None:
        return out | {"jitter": None, "apex": None, "bounce_time": None}
    times, _, speeds = trajectory
    half = [k for k, t in enumerate(times) if t >= duration / 2]
    out["jitter"] = max((norm(v) for k in half for v in speeds[k]), default=0.0)
    if floor is None:
        out["apex"] = out["bounce_time"] = None
    else:
        out["apex"], out["bounce_time"] = bounces(trajectory)
    return out


def record(step, read):
    # call step() STEPS times, reading the state at the start and after every RECORD_EVERY
    # steps (and after the last): (times, positions, velocities)
    times, positions, velocities = [], [], []
    done = 0
    while True:
        p, v = read()
        times.append(done * DT)
        positions.append(p)
        velocities.append(v)
        if done >= STEPS:
            break
        chunk = min(RECORD_EVERY, STEPS - done)
        for _ in range(chunk):
            step()
        done += chunk
    return times, positions, velocities
'''
"""The measures and the recording loop as script text (see the module docstring)."""

FINISH = """\
measures = engine_measures(positions, velocities, TRAJECTORY)
settle, jitter, energy_drift = measures["settle"], measures["jitter"], measures["energy_drift"]
apex, bounce_time = measures["apex"], measures["bounce_time"]
"""
"""The end of a scene's engine part: the measures from the final state and ``TRAJECTORY``
(None in open space)."""


def surrounded(case: SceneCase) -> bool:
    """The scene has gravity or walls: its script records states and prints every measure."""
    return scene_measures.surrounded(case)


def inputs(case: SceneCase) -> tuple[Input, ...]:
    """``GRAVITY``, ``WALLS`` and ``RECORD_EVERY``: the script's inputs beside the bodies."""
    walls = "(" + "".join(f"\n    ({vector(tuple(map(float, w.normal)))}, "
                          f"{literal(float(w.offset))})," for w in case.walls) + (
        "\n)" if case.walls else ")")
    every = scene_measures.record_every(case)
    return (("GRAVITY", vector(tuple(map(float, scene_measures.gravity(case)))), "gravity",
             repr(scene_measures.gravity(case))),
            ("WALLS", walls, "walls (normal, offset): solid where normal . x <= offset",
             repr(tuple((tuple(w.normal), w.offset) for w in case.walls))),
            ("RECORD_EVERY", repr(every), "states recorded every (steps)",
             "0: open space, none" if not every else
             f"every step while bodies x steps <= {scene_measures.MAX_SAMPLES}"))


def stepping(step: str, read: str) -> str:
    """The statements that step the scene: ``record`` with ``read`` (a function's name) when
    the scene has gravity or walls, else a plain loop (``TRAJECTORY = None`` then).  ``step``
    is one step's statement."""
    return (f"if RECORD_EVERY:  # record the states every RECORD_EVERY steps, as the adapter\n"
            f"    TRAJECTORY = record(lambda: {step}, {read})\n"
            f"else:  # open space: no trajectory\n"
            f"    TRAJECTORY = None\n"
            f"    for _ in range(STEPS):\n"
            f"        {step}\n")


def printed(case: SceneCase) -> tuple[str, ...]:
    """The quantities a scene script prints as ``<quantity> = <JSON text>``: the final state and
    the measures it computes (open space: ``energy_drift`` only)."""
    return (*QUANTITIES, *(MEASURED if surrounded(case) else ("energy_drift",)))


def answer_lines(case: SceneCase, rows: Sequence[dict[str, Any]]) -> list[str]:
    """The printing statements of a scene script: each printed quantity, then a comment on the
    measures it does not compute, with what the run recorded for ``divergence``."""
    lines = [f'print("{q} = " + encode({q}))' for q in printed(case)]
    if surrounded(case):
        recorded = next((str(r["value"]) for r in rows if r["quantity"] == "divergence"),
                        "nothing (not in this run)")
        note = ("# divergence: computed by crosscheck against the exact run's trajectory (the "
                f"first recorded time a centre is more than diverge_at = {case.diverge_at!r} "
                f"mean radii from the exact one), not by this script; the run recorded "
                f"{recorded}")
    else:
        note = (f"# {', '.join(OPEN_SPACE)}: none in open space (no ground and no recorded "
                "trajectory); crosscheck records null")
    return [*lines, f"print({note!r})"]
