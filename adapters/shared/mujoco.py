"""MuJoCo setup shared by its pair calls and its scene runner: the import with its warning handler,
compiled pairs, the compiler's refusals, the stiff variant's model settings; plain (the
standard library only), so a repro script holds this source (until the scenes are calls of
:mod:`adapters.mujoco.calls`, which then holds it).

What it is for: detection and responses (:mod:`adapters.mujoco.calls`) both need a compiled
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
"""

import math
from collections import deque
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

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
