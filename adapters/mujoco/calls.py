"""MuJoCo's calls (the ``mujoco-default`` pairs and the ``mujoco`` and ``mujoco-default``
responses), plain data in and out.

A pair is the two-body model ``model`` (MJCF: two free bodies, unit geoms, unit masses), compiled
once per process and role (detection, response) and changed per case: geom sizes with the
bounds the broad phase reads, masses and inertias (then ``mj_setConst``), the stiff
variant's contact (direct ``solref`` and time step) and ``qpos``/``qvel``.  Whichever case
was set into a pair last is its ``owner``: an ask of another puts its own values back first.

Detection: ``mj_kinematics``, ``mj_collision`` (geom margin 0) and ``mj_geomDistance``; a hit
is a contact at distance <= 0, its normal the contact frame's (geom 0 to geom 1: A to B);
apart, the normal is the ``fromto`` segment's direction.

Response: from the reset start state, step until no contact is active and the bodies no
longer approach (``resolved_at``: the centres when the first collision pass found an
active contact); a MuJoCo warning (a bad value resets the state) raises, as does a contact
still active after ``max_steps`` or a 2-D response that left the plane beyond rounding.

Scene: the scene's model ``model`` (MJCF: one free sphere per body, one plane geom per wall)
compiled per scene, with the scene's iterations, time step and gravity; the stiff variant
(``stiff``) adds RK4, tolerance 1e-15, flat solimp and margins, ``substeps`` MuJoCo steps per
scene step and the direct ``solref`` of a spring-dashpot lasting one scene step.  The ask
times only ``mj_step`` (one call for the whole run when nothing is recorded) and reads
``qpos``/``qvel``; a 2-D scene must keep to z = 0 within ``plane_bound`` of its scales; a
MuJoCo warning raises.  What was measured: :mod:`adapters.mujoco.scene`.

What the pairs, responses and scenes share: detection and responses both need a compiled
two-body model whose sizes, masses and poses change per case, and both must keep MuJoCo
from writing files:

- ``engine()``: the ``mujoco`` module, imported once, lazily (an optional engine: importing
  this module does not import it).  On that import a warning handler is installed
  (``mujoco.set_mju_user_warning``): without it every MuJoCo warning is printed and
  appended to ``MUJOCO_LOG.TXT`` in the current directory (``mju_warning`` in
  ``engine_util_errmem.c``).  The handler keeps the last messages in :data:`WARNINGS`.
- ``compile_pair(geom, ...)``: two free-joint bodies with explicit inertials (a tiny sphere
  does not compile without one: its computed inertia falls below mjMINVAL), gravity 0, each
  with one geom of type ``geom`` (``sphere`` or ``box``).  Compiling costs ~10 ms; a
  :class:`Pair` is compiled once per adapter instance and kind, then changed per case with
  :func:`set_sizes` and :func:`set_masses` (what ``mj_setConst`` must follow) and ``qpos``.
  ``Pair.owner`` names the prepared case the model holds now, so a query of another
  prepared case puts its own values back first.
- ``refusal(geom, sizes, masses)``: what MuJoCo's compiler says of sizes and masses it
  would not compile (a size not > 0 or NaN: "size 0 must be positive in geom"; a moving
  body's mass or inertia not > mjMINVAL = 1e-15).  Changing a compiled model bypasses
  those checks, so the adapters ask the compiler itself: only when a number is outside
  the compiler's range, the case's own model is compiled, and its error message returned.

(Longer than 400 lines: one module is what a repro script holds verbatim; the compiled pairs,
the responses and the scenes are each about 100 to 150 lines.)
"""

import math
import time
from collections import deque
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from adapters.shared.scene import (
    check_scene,
    check_surroundings,
    in_scene_dim,
    scene_answer,
    step_and_record,
)

__all__ = ["MARGIN", "MAXIMP", "MINVAL", "ONE", "PLANE", "TOLERANCE", "UNIT", "WARNINGS", "Mass",
           "Pair", "Plane", "compile_pair", "engine", "guarded", "pair_mjcf", "refusal",
           "scene_mjcf", "set_masses", "set_sizes", "tune_stiff_model"]

Vec3 = tuple[float, float, float]
MAXIMP = 0.9999
"""mjMAXIMP, the largest impedance MuJoCo allows: the stiff contact's ``solimp`` d0 and d_width."""
MARGIN = 2.0**-1022
"""The stiff contact's geom margin: a touching contact (distance 0) is active."""
TOLERANCE = 1e-15
"""The stiff variant's solver tolerance (``opt.tolerance``; MuJoCo's default is 1e-8)."""
PLANE = 2.0**-40
"""Largest |vz| of a 2-D response, relative to its largest speed, taken as rounding noise."""

MINVAL = 1e-15
"""mjMINVAL: the smallest mass and inertia MuJoCo's compiler accepts for a moving body."""
WARNINGS: deque[str] = deque(maxlen=16)
"""The last MuJoCo warning messages (kept by the handler instead of MUJOCO_LOG.TXT)."""
Mass = tuple[float, Vec3]
"""A body's mass and diagonal inertia."""

_MODULE: list[Any] = []
MJCF = """<mujoco model="crosscheck-pair">
  <option gravity="0 0 0"/>
  <worldbody>
    <body name="a"><freejoint/><inertial pos="0 0 0" mass="{ma}" diaginertia="{ia}"/>
      <geom name="a" type="{geom}" size="{sa}"{extra}/></body>
    <body name="b"><freejoint/><inertial pos="0 0 0" mass="{mb}" diaginertia="{ib}"/>
      <geom name="b" type="{geom}" size="{sb}"{extra}/></body>
  </worldbody>
</mujoco>"""
"""The two-body model of every pair (repro scripts embed it, filled by :func:`pair_mjcf`)."""
UNIT: dict[str, Vec3] = {"sphere": (1.0, 0.0, 0.0), "box": (1.0, 1.0, 1.0)}
"""The unit geom size of each geom type the pair is compiled with (a sphere: its radius)."""
ONE: Mass = (1.0, (1.0, 1.0, 1.0))
"""A unit mass with unit inertia: what a pair is compiled with."""


def _keep(message: str) -> None:
    WARNINGS.append(str(message))


def engine() -> Any:
    """The ``mujoco`` module, imported on first use, with the warning handler installed."""
    if not _MODULE:
        import mujoco  # type: ignore[import-untyped]

        mujoco.set_mju_user_warning(_keep)
        _MODULE.append(mujoco)
    return _MODULE[0]


@dataclass(eq=False)
class Pair:
    """A compiled two-body model and its data; ``owner``: the prepared case set in it now."""

    model: Any
    data: Any
    geom: str
    owner: object = None
    broken: bool = False
    """Set after a MuJoCo fatal error in it: the next case compiles a new pair."""


def _text(values: Sequence[float]) -> str:
    return " ".join(repr(float(x)) for x in values)


def pair_mjcf(geom: str, sizes: Sequence[Vec3], masses: Sequence[Mass], extra: str) -> str:
    """:data:`MJCF` with these geom sizes, masses and inertias (and ``extra`` geom attributes)."""
    count = 1 if geom == "sphere" else 3
    (ma, ia), (mb, ib) = masses
    return MJCF.format(geom=geom, sa=_text(sizes[0][:count]), sb=_text(sizes[1][:count]),
                       ma=repr(float(ma)), mb=repr(float(mb)), ia=_text(ia), ib=_text(ib),
                       extra=extra)


SCENE_BODY = """    <body name="s{i}"><freejoint/>
      <inertial pos="0 0 0" mass="{m}" diaginertia="{i3}"/>
      <geom name="s{i}" type="sphere" size="{r}"{extra}/></body>
"""
"""One sphere of a scene model (:func:`scene_mjcf`): a free body like the pair's."""
SCENE_PLANE = """    <geom name="w{k}" type="plane" size="0 0 1" pos="{pos}" quat="{quat}"{extra}/>
"""
"""One static wall of a scene model: a plane geom of the world body, whose local z axis is
its normal (MuJoCo's plane is a half-space for collisions: ``mjraw_PlaneSphere``)."""
Plane = tuple[Vec3, tuple[float, float, float, float]]
"""A plane geom's position and orientation quaternion (w, x, y, z)."""


def scene_mjcf(spheres: Sequence[tuple[float, Mass]], extra: str,
               planes: Sequence[Plane] = (), plane_extra: str = "") -> str:
    """The model of a scene: :data:`MJCF`'s world with one free sphere per (radius, mass)
    (bodies ``s0``, ``s1``, ...; their poses go into ``qpos`` after compiling) and one
    static plane geom per (position, quaternion) (geoms ``w0``, ``w1``, ... of the world
    body, with ``plane_extra`` attributes: the compiler numbers the world's geoms first, so
    they are geoms 0, 1, ... and the spheres follow); without planes, the open-space model
    as before."""
    head, tail = MJCF.split("  <worldbody>\n")[0], "  </worldbody>\n</mujoco>"
    bodies = "".join(SCENE_BODY.format(i=i, m=repr(float(mass)), i3=_text(inertia),
                                       r=repr(float(radius)), extra=extra)
                     for i, (radius, (mass, inertia)) in enumerate(spheres))
    walls = "".join(SCENE_PLANE.format(k=k, pos=_text(pos), quat=_text(quat), extra=plane_extra)
                    for k, (pos, quat) in enumerate(planes))
    return (head.replace("crosscheck-pair", "crosscheck-scene") + "  <worldbody>\n" + bodies
            + walls + tail)


def compile_pair(geom: str, extra: str = "") -> Pair:
    """Two free bodies of unit mass, each with one unit geom of type ``geom``.

    ``extra``: more geom attributes, as MJCF text (e.g. ``' condim="1"'``).
    """
    mujoco = engine()
    model = mujoco.MjModel.from_xml_string(pair_mjcf(geom, (UNIT[geom],) * 2, (ONE,) * 2, extra))
    return Pair(model, mujoco.MjData(model), geom)


@contextmanager
def guarded(pair: Pair) -> Iterator[None]:
    """Run engine calls on ``pair``; a MuJoCo fatal error (``mju_error``, which exits a C
    program) becomes a RuntimeError and marks the pair broken."""
    try:
        yield
    except engine().FatalError as exc:
        pair.broken = True
        raise RuntimeError(f"MuJoCo fatal error (mju_error): {exc}") from None


def set_sizes(pair: Pair, sizes: Sequence[Vec3]) -> None:
    """Geom sizes (radius; box half-sizes) with the bounds the compiler derives from them:
    ``geom_rbound`` (bounding sphere) and ``geom_aabb`` (local box), both used by the
    broad phase (a stale bound drops the pair before the narrow phase)."""
    m = pair.model
    for g, size in enumerate(sizes):
        m.geom_size[g] = size
        if pair.geom == "sphere":
            r = size[0]
            m.geom_rbound[g] = r
            m.geom_aabb[g] = (0.0, 0.0, 0.0, r, r, r)
        else:
            m.geom_rbound[g] = math.sqrt(math.fsum(h * h for h in size))
            m.geom_aabb[g] = (0.0, 0.0, 0.0, *size)


def set_masses(pair: Pair, masses: Sequence[Mass]) -> None:
    """Body masses and inertias, then ``mj_setConst``: it recomputes what the compiler derived
    from them (``body_invweight0``, the constraint solver's diagonal estimate)."""
    m = pair.model
    for body, (mass, inertia) in enumerate(masses, start=1):
        m.body_mass[body] = mass
        m.body_inertia[body] = inertia
    engine().mj_setConst(m, pair.data)


def _in_range(sizes: Sequence[Vec3], masses: Sequence[Mass]) -> bool:
    return (all(x > 0.0 for size in sizes for x in size)  # NaN is not > 0
            and all(x > MINVAL for mass, inertia in masses for x in (mass, *inertia)))


def refusal(geom: str, sizes: Sequence[Vec3], masses: Sequence[Mass] | None = None) -> str | None:
    """MuJoCo's compiler error for these sizes and masses (None: it compiles them).

    Detection bodies have unit masses (``masses`` None).  A sphere's size is its radius
    alone (the other two numbers are not read).
    """
    used: list[Vec3] = [(s[0], 1.0, 1.0) if geom == "sphere" else s for s in sizes]
    weights = masses or (ONE, ONE)
    if _in_range(used, weights):
        return None
    try:
        engine().MjModel.from_xml_string(pair_mjcf(geom, sizes, weights, ""))
    except ValueError as exc:
        return str(exc).strip().splitlines()[0]
    return None


def tune_stiff_model(m: Any) -> None:
    """RK4, solver tolerance 1e-15, and every geom's margin and flat solimp (the stiff
    variant's pairs and scenes)."""
    m.opt.integrator = engine().mjtIntegrator.mjINT_RK4
    m.opt.tolerance = TOLERANCE
    for g in range(m.ngeom):
        m.geom_margin[g] = MARGIN
        m.geom_solimp[g] = (MAXIMP, MAXIMP, 0.001, 0.5, 2.0)


Answer = dict[str, Any]
Vec = tuple[float, ...]
IDENTITY = (1.0, 0.0, 0.0, 0.0)
DISTMAX = 1e30
"""``distmax`` of ``mj_geomDistance``: above any distance in the suite."""

_PAIRS: dict[tuple[str, str, bool], Pair] = {}


def _pair(role: str, mjcf: str, geom: str, stiff: bool) -> Pair:
    """The compiled pair of ``role``, compiled on first use (again after a fatal error)."""
    key = (role, mjcf, stiff)
    if key not in _PAIRS or _PAIRS[key].broken:
        mujoco = engine()
        model = mujoco.MjModel.from_xml_string(mjcf)
        _PAIRS[key] = Pair(model, mujoco.MjData(model), geom)
        if stiff:
            tune_stiff_model(model)
    return _PAIRS[key]


def _qpos(a_center: Vec, b_center: Vec) -> tuple[float, ...]:
    a, b = ((float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0)
            for v in (a_center, b_center))
    return (*a, *IDENTITY, *b, *IDENTITY)


def _place(p: dict[str, Any]) -> None:
    """Put a detection case's sizes and pose into its pair."""
    set_sizes(p["pair"], p["sizes"])
    p["pair"].data.qpos[:] = p["qpos"]
    p["pair"].owner = p


def detection(model: str, geom: str, a_size: Vec, b_size: Vec, a_center: Vec, b_center: Vec,
              dim: int) -> dict[str, Any]:
    """The case set into the detection pair of ``geom`` (sizes: a radius then 0, 0, or a
    box's half-sizes)."""
    p = {"pair": _pair("detection", model, geom, False), "sizes": (a_size, b_size),
         "qpos": _qpos(a_center, b_center), "dim": dim, "fromto": np.zeros(6)}
    _place(p)
    return p


def _unit(v: Any) -> Vec | None:
    """``v`` normalised; None for a zero, overflowing or NaN vector (no direction)."""
    length = math.hypot(*(float(x) for x in v))
    return tuple(float(x) / length for x in v) if 0.0 < length < math.inf else None


def detect(p: dict[str, Any]) -> Answer:
    """One collision pass and one distance query."""
    mujoco, m, d = engine(), p["pair"].model, p["pair"].data
    if p["pair"].owner is not p:
        _place(p)
    with guarded(p["pair"]):
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        distance = float(mujoco.mj_geomDistance(m, d, 0, 1, DISTMAX, p["fromto"]))
    hit, normal = False, None
    if d.ncon:
        deepest = int(np.argmin(d.contact.dist))
        if d.contact.dist[deepest] <= 0.0:
            sign = 1.0 if d.contact.geom[deepest][0] == 0 else -1.0
            hit, normal = True, _unit(sign * d.contact.frame[deepest][:3])
    if not hit and distance > 0.0:
        fromto = p["fromto"]
        start, end = fromto[:3].tolist(), fromto[3:].tolist()  # Python floats: inf, no warning
        normal = _unit([b - a for a, b in zip(start, end, strict=True)])
    if normal is not None:
        normal = normal[:p["dim"]]
    return {"hit": hit, "distance": distance, "normal": normal}


def _apply(p: dict[str, Any]) -> None:
    """Put a response case's sizes, masses and contact into its pair's model."""
    m = p["pair"].model
    set_sizes(p["pair"], p["sizes"])
    if p["solref"] is not None:
        m.opt.timestep = p["timestep"]
        for g in range(2):
            m.geom_solref[g] = p["solref"]
    set_masses(p["pair"], p["masses"])
    p["pair"].owner = p


def response(model: str, stiff: bool, a_center: Vec, a_velocity: Vec, a_radius: float,
             a_mass: float, a_inertia: tuple[float, float, float], b_center: Vec,
             b_velocity: Vec, b_radius: float, b_mass: float,
             b_inertia: tuple[float, float, float], dim: int,
             solref: tuple[float, float] | None, timestep: float | None,
             max_steps: int) -> dict[str, Any]:
    """The case set into the response pair (``solref`` None: MuJoCo's default contact and
    step; else the stiff variant's contact and time step)."""
    va, vb = ((float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0)
              for v in (a_velocity, b_velocity))
    p = {"pair": _pair("response", model, "sphere", stiff), "dim": dim,
         "sizes": ((a_radius, 0.0, 0.0), (b_radius, 0.0, 0.0)),
         "masses": ((a_mass, a_inertia), (b_mass, b_inertia)), "solref": solref,
         "timestep": timestep, "qpos": _qpos(a_center, b_center),
         "qvel": (*va, 0.0, 0.0, 0.0, *vb, 0.0, 0.0, 0.0), "max_steps": max_steps}
    _apply(p)
    return p


def _active(d: Any) -> bool:
    """Whether the last collision pass found a contact in the constraint problem."""
    return bool(d.ncon) and bool((d.contact.exclude == 0).any())


def _approaching(d: Any) -> bool:
    """Whether B moves towards A along their line of centres (False for NaN)."""
    with np.errstate(all="ignore"):  # huge or non-finite input: the answer is False
        gap = d.qpos[7:10] - d.qpos[0:3]
        return bool((d.qvel[6:9] - d.qvel[0:3]) @ gap < 0.0)


def _warned(d: Any) -> str:
    """MuJoCo's warnings of this step, in words ('' if none): the messages the handler kept,
    and the counters (a reset clears them, so they show only what came after the last one)."""
    mujoco = engine()
    counts = d.warning.number
    if not counts.any():
        return ""
    names = [f"{mujoco.mjtWarning(i).name} x{n}" for i, n in enumerate(counts) if n]
    return f"{' | '.join(WARNINGS) or 'no message'} (counters: {', '.join(names)})"


def _centres(d: Any, dim: int) -> tuple[Vec, Vec]:
    return (tuple(float(x) for x in d.qpos[0:dim]), tuple(float(x) for x in d.qpos[7:7 + dim]))


def respond(p: dict[str, Any]) -> Answer:
    """Step the case from its start until its contact is over."""
    mujoco, m, d = engine(), p["pair"].model, p["pair"].data
    if p["pair"].owner is not p:
        _apply(p)
    mujoco.mj_resetData(m, d)
    WARNINGS.clear()
    d.qpos[:], d.qvel[:] = p["qpos"], p["qvel"]
    with guarded(p["pair"]):
        return _step(mujoco, m, d, p["dim"], p["max_steps"])


def _step(mujoco: Any, m: Any, d: Any, dim: int, max_steps: int) -> Answer:
    """The stepping loop of :func:`respond`."""
    resolved: tuple[Vec, Vec] | None = None
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    for _ in range(max_steps):
        if resolved is None and _active(d):
            resolved = _centres(d, dim)
        mujoco.mj_step(m, d)
        if warned := _warned(d):
            raise RuntimeError(f"MuJoCo warned while stepping, and a bad value resets the "
                               f"state: {warned}")
        mujoco.mj_kinematics(m, d)  # the collision pass the next step starts with
        mujoco.mj_collision(m, d)
        if not _active(d) and not _approaching(d):
            return _observed(d, dim, resolved)
    raise RuntimeError(f"contact still active after {max_steps} steps of {m.opt.timestep:.3g} s")


def _observed(d: Any, dim: int, resolved: tuple[Vec, Vec] | None) -> Answer:
    """The velocities and where the contact began; 2-D: the motion must have stayed in z = 0
    (within ``PLANE`` x the largest speed: the solver's rounding noise)."""
    va = tuple(float(x) for x in d.qvel[0:3])
    vb = tuple(float(x) for x in d.qvel[6:9])
    if dim == 2 and not max(abs(va[2]), abs(vb[2])) <= PLANE * max(map(abs, (*va, *vb))):
        raise RuntimeError(f"2-D response left the plane z = 0: vz = {va[2]!r}, {vb[2]!r}")
    return {"v1": va[:dim], "v2": vb[:dim], "resolved_at": resolved}


def scene(model: str, bodies: tuple[Any, ...], dim: int, restitution: float, dt: float,
          iterations: int | None, gravity: Vec, walls: tuple[Any, ...], steps: int,
          record_every: int, stiff: bool, substeps: int, solref: Vec | None,
          plane_bound: float) -> dict[str, Any]:
    """The scene's compiled model and data at the start (see the module docstring)."""
    check_scene(bodies, dim, restitution, dt)
    check_surroundings(gravity, walls, dim)
    mujoco = engine()
    try:
        m = mujoco.MjModel.from_xml_string(model)
    except ValueError as exc:
        raise ValueError(f"MuJoCo's compiler refuses this scene: {exc}") from None
    if iterations is not None:
        m.opt.iterations = iterations
    m.opt.timestep = dt
    m.opt.gravity[:] = (*gravity, 0.0, 0.0)[:3]
    if stiff:
        tune_stiff_model(m)  # every geom, the planes too
        m.opt.timestep = dt / substeps
        m.geom_solref[:] = solref
    d = mujoco.MjData(m)
    pad = (0.0,) * (3 - dim)
    for i, (center, _, _, velocity) in enumerate(bodies):
        d.qpos[7 * i:7 * i + 7] = (*center, *pad, 1.0, 0.0, 0.0, 0.0)
        d.qvel[6 * i:6 * i + 6] = (*velocity, *pad, 0.0, 0.0, 0.0)
    mujoco.mj_forward(m, d)
    reach = max((abs(x) + r for c, r, _, _ in bodies for x in c), default=0.0)
    speed = max((abs(x) for _, _, _, v in bodies for x in v), default=0.0)
    # gravity is a speed scale too: a body at rest carries up to |g| dt between solves
    speed = max(speed, math.hypot(*gravity) * dt)
    return {"model": m, "data": d, "substeps": substeps, "dim": dim, "count": len(bodies),
            "scales": (reach, speed), "radius": max((r for _, r, _, _ in bodies), default=0.0),
            "plane": plane_bound, "dt": dt, "steps": steps, "record_every": record_every,
            "bodies": bodies, "gravity": gravity, "walls": walls}


def scene_state(built: dict[str, Any]) -> tuple[Any, Any]:
    """Every centre and velocity in the scene's dimension: a 2-D scene's plane check scales
    with the larger of the start's and the current in-plane magnitudes (gravity speeds bodies
    up)."""
    d, dim, count = built["data"], built["dim"], built["count"]
    qpos = d.qpos.reshape(count, 7)[:, :3]
    qvel = d.qvel.reshape(count, 6)[:, :3]
    reach, speed = built["scales"]
    if dim == 2 and count:
        reach = max(reach, float(np.abs(qpos[:, :2]).max()) + built["radius"])
        speed = max(speed, float(np.abs(qvel[:, :2]).max()))
    return (in_scene_dim(dim, qpos, "position", built["plane"] * reach),
            in_scene_dim(dim, qvel, "velocity", built["plane"] * speed))


def step_scene(built: dict[str, Any], clock: Any = time.perf_counter) -> Answer:
    """Step the scene to its end (only ``mj_step`` is timed, by ``clock``): the final state,
    the measures and the trajectory.  Without recording, the whole run is one ``mj_step(m, d,
    steps x substeps)`` call."""
    mujoco, m, d = engine(), built["model"], built["data"]
    steps, every, substeps = built["steps"], built["record_every"], built["substeps"]
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    WARNINGS.clear()
    if every > 0:
        wall_s, records = step_and_record(lambda: mujoco.mj_step(m, d, substeps),
                                          lambda: scene_state(built), steps, every, clock)
    else:
        wall_s, records = step_and_record(lambda: mujoco.mj_step(m, d, steps * substeps),
                                          lambda: scene_state(built), min(steps, 1), 0, clock)
    if d.warning.number.any():
        raise RuntimeError(f"MuJoCo warned while stepping, and a bad value resets the state: "
                           f"{' | '.join(WARNINGS) or 'no message'}")
    return scene_answer(built["bodies"], built["gravity"], built["walls"], built["dt"], steps,
                        scene_state(built), records, wall_s)
