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
"""

import math
from typing import Any

import numpy as np

from adapters.shared.mujoco import (
    PLANE,
    WARNINGS,
    Pair,
    engine,
    guarded,
    set_masses,
    set_sizes,
    tune_stiff_model,
)

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
