"""MuJoCo 4.0.0 (mujoco-core, float64) as an engine: ``mujoco`` (stiff) and ``mujoco-default``.

Every case runs on a compiled two-body model (two free-joint bodies with explicit
inertials, one geom each, gravity 0; see :mod:`adapters.mujoco.calls`), compiled once per
process, model text and role (detection, response; ~10 ms) and changed per case (the calls,
plain data in and out, are :mod:`adapters.mujoco.calls`): geom sizes with the bounds the
compiler derives (``geom_rbound``, ``geom_aabb``: the broad phase drops a pair whose bounds
are stale), masses (``mj_setConst``) and ``qpos``.  2-D cases lie in z = 0: discs are
spheres, a 2-D box gets the z half-width 2 x the case's largest half-width (1 if all are 0)
so z is never the axis of least overlap nor a gap; vectors come back without z.

Detection (``aabb``, ``sphere``; ``mujoco-default`` only, see below): ``query`` runs
``mj_kinematics`` (geom poses from qpos), ``mj_collision`` (the contacts, geom margin 0) and
``mj_geomDistance(m, d, A, B, 1e30, fromto)``:

- ``hit``: a contact between A and B with distance <= 0.  Not "``ncon`` > 0": a contact
  within a margin has a positive distance.  MuJoCo lists touching contacts (distance 0) and
  leaves them out of its forces (``exclude``: distance >= margin); the verdict is the
  collision pass's.
- ``distance``: ``mj_geomDistance``.  Spheres: the sphere-sphere collider run with the
  1e30 as margin, ``|cb - ca| - ra - rb``; boxes: GJK, and EPA when they overlap (native
  CCD; for polytopes its tolerance is 1e-15 absolute, not ``opt.ccd_tolerance``).  When EPA
  cannot build its polytope it returns 0 ("assume touching", engine_collision_gjk.c).
  Measured: 0.0 for 2 of 300 random overlapping box pairs at 1e6 (overlaps of 9e4 and
  2e5), for an overlap of 2e-12 between boxes of 1e-9 and of 3e-9 at an offset of 1e8, and
  -1.15e-12 for an overlap of 2e-12 between boxes of 1e-6, where the contact's ``dist``
  from ``mj_collision`` (the box-box SAT collider) is right every time.  The adapter reports
  ``mj_geomDistance`` anyway: it is MuJoCo's distance query, what a user calls for a
  distance, and the row then shows its error beside a right ``hit`` and ``normal`` (which
  come from the contact); substituting the contact's depth would hide the fault.
- ``normal``: in contact the deepest contact's ``frame[0:3]``, which points from
  ``geom[0]`` to ``geom[1]`` (A is geom 0; flipped if a contact lists B first, never seen);
  apart (distance > 0) the unit vector of ``fromto`` (A's nearest point to B's: a
  difference of two surface points, so a normal across a tiny gap tilts by ~u size / gap);
  none when those points round to the same double (a gap below the coordinates' ulp, e.g.
  0.125 at 1e15 or 5.6e-17 at 1) or without contact at distance <= 0 (corner-touching
  boxes): the engine gives no direction there.

Responses (``sphere_response``, 2-D and 3-D): stepped (:mod:`adapters.mujoco_response` says
how, and fits the stiff variant's contact to the case) until no contact is active and the
spheres no longer approach. Scenes (``sphere_scene``, 2-D and 3-D) are the scene calls of
:mod:`adapters.mujoco.calls` with the variant's ``scene_tuning``; their model, gravity and
walls (plane geoms with the spheres' contact parameters) and each variant's resting
conventions (``rest_gap``, ``rest_sink_*``, no sleeping, wall restitution) are derived in
:mod:`adapters.mujoco.scene` from MuJoCo's solref/solimp rules.

Conventions (sources in ``SOURCES``: docs of 4.0.0; source files linked at main and read at
commit a7255075, a 3.12.1 development snapshot, the newest one mirrored here; each rule
measured on the installed 4.0.0 and pinned in tests/adapters/test_mujoco.py):

- box geom size is the half-sizes [XMLreference]; normal from geom[0] to geom[1]
  (``mjContact.frame``; ``fromto`` from geom1 to geom2) [engine_support.c]: A to B, no flip.
- touching: spheres touching give a contact at distance 0 (``mjraw_SphereSphere`` rejects
  only ``|d|^2 > (r1 + r2 + margin)^2``): contact, unlike the textbook; boxes touching on a
  face or an edge give contacts at distance 0, on a corner none (the box-box collider
  clips no contact point there, measured): corner declared apart.  A 2-D corner touch is a
  3-D edge touch in the embedding, so 2-D corners collide (as the textbook says).  No
  margins (geom margin 0).
- rtol: 2^-50 in both (mjtNum is double): the precision of positions and of detection.
  ``mujoco`` also declares ``response_rtol``, the precision of its stiff contact's
  velocities, measured on random cases outside the suite (see :data:`STIFF_RTOL`).
- restitution: MuJoCo has none.  ``mujoco-default`` keeps the soft default contact (solref
  0.02 1, solimp 0.9 0.95 0.001 0.5 2, friction 1, condim 3, Euler, dt 0.002 s) and ignores
  the case's e: a 1 m/s head-on bounce of equal spheres leaves at about +-0.14 (measured).
  ``mujoco`` builds a frictionless (``condim`` 1: "Frictionless contact" [XMLreference,
  body-geom-condim]) spring-dashpot with the case's e (see mujoco_response): it declares
  friction 0 and no soft model, none of ``mujoco-default``'s; e = 0 and e outside [0, 1]
  are skipped.  No threshold; bodies already separating meet no force
  (resolves_separating False).  Contacts are sampled (``sampled_contacts``, both
  variants): ``mj_step`` finds contacts at the positions a step starts from and moves the
  bodies a whole step; a contact makes force only "below margin" [XMLreference,
  body-geom-margin; computation, margin and gap], and the default margin is 0, so
  touching spheres get none (``exclude`` = dist >= margin, engine_collision_driver.c).  A
  grazing impact whose overlap lasts less than a step (0.49 ms against 2 ms) is never
  seen overlapping: no force, the velocities unchanged (category ``timestep``).  Damping 0:
  joint damping, ``opt.viscosity`` and ``opt.density`` are 0 by default (no drag on free
  bodies).
- zero mass, zero or negative sizes: the compiler refuses them ("mass and inertia of moving
  bodies must be larger than mjMINVAL", "size 0 must be positive in geom", user_objects.cc
  and user_model.cc); a changed compiled model would not check, so such a case is compiled
  as itself and its compiler error raised: ``error`` rows, as a user gets (zero_mass "",
  negative_extents "").
- non-finite input: detection reads NaN and inf silently (``mj_geomDistance`` returns its
  1e30 cap, no contact): reported Undefined.  Responses: ``mj_step`` resets the state on a
  bad value and counts a warning; the warning is raised.
- fatal errors: ``mju_error`` ends a C program; the Python binding turns it into
  ``mujoco.FatalError`` [python.rst, Error handling].  Found here (fuzzing sizes and
  coordinates up to DBL_MAX): a sphere of radius 1.7e308 makes ``mj_collision`` fail with
  "mju_makeFrame: xaxis of contact frame undefined" (its contact normal overflows).  The
  adapter raises it as an error and compiles a new pair for the next case.  No hang was
  found (GJK and EPA are bounded by ``ccd_iterations``, stepping by ``MAX_STEPS``), so no
  ``known_hang``.  Warnings and errors go to the installed handler, never to
  ``MUJOCO_LOG.TXT`` [simulation.rst, Default handler].

This module is over 400 lines because the detection translation and both variants'
conventions are one unit; the scene and response parts live in their own modules.

Variants.  The stiff contact is a response setting only: detection is the same engine call
in both variants, so it is scored under ``mujoco-default`` alone and ``mujoco`` skips it
with that reason.  Each variant declares its own conventions: ``mujoco`` none of the
default's friction, soft model or sampled contacts (its step is fitted so that the
contact starts on one and its margin makes a touching contact active).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

from adapters import mujoco_response as response
from adapters.mujoco.calls import ONE, UNIT, Mass, engine, pair_mjcf, refusal
from adapters.mujoco.scene import (
    DEFAULT_REST,
    TUNED_REST,
    Rest,
    Tuning,
    scene_model,
    scene_settings,
)
from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core.claims import APART, OVERLAP, Claim
from crosscheck.core.contract import (
    Call,
    Capability,
    Conventions,
    all_capabilities,
    import_problem,
    refused,
)
from crosscheck.core.geometry import Vec3, to3, z_half
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, AnyCase, PairCase, ResponseCase, SceneCase, SphereCase

MJ = "https://github.com/google-deepmind/mujoco/blob/main/"
DOCS = "https://mujoco.readthedocs.io/en/4.0.0/"
SOURCES = (
    DOCS + "XMLreference.html#body-geom",
    DOCS + "XMLreference.html#body-geom-margin",  # force only below margin
    DOCS + "XMLreference.html#body-geom-condim",  # condim 1: frictionless contact
    DOCS + "computation/index.html#comargingap",  # active contact: distance below margin
    DOCS + "modeling.html#solver-parameters",
    DOCS + "APIreference/APIfunctions.html#mj-geomdistance",
    MJ + "src/engine/engine_collision_primitive.c",  # mjraw_SphereSphere
    MJ + "src/engine/engine_collision_box.c",  # box-box SAT collider
    MJ + "src/engine/engine_collision_gjk.c",  # GJK/EPA, 'assume touching'
    MJ + "src/engine/engine_support.c",  # mj_geomDistance
    MJ + "src/engine/engine_collision_driver.c",  # contact geom order, exclude
    MJ + "src/engine/engine_core_constraint.c",  # solref, solimp -> aref
    MJ + "src/engine/engine_forward.c",  # mj_checkPos/Vel/Acc reset, RK4
    MJ + "src/engine/engine_util_errmem.c",  # warnings -> MUJOCO_LOG.TXT
    MJ + "src/user/user_objects.cc",  # size must be positive
    DOCS + "programming/simulation.html#sidefaulthandler",  # legacy handler: no log file
    DOCS + "python.html#pyerror",  # mju_error -> mujoco.FatalError
    "https://arxiv.org/abs/2204.10917",  # linear dashpot, force stopped at zero
    DOCS + "modeling.html#csolverreference",  # solref formats, penetration at rest
    DOCS + "computation/index.html#soparameters",  # a1 = d aref + (1 - d) a0
    DOCS + "XMLreference.html#body-geom-type",  # plane: infinite for collisions
    DOCS + "XMLreference.html#option-flag-refsafe",  # timeconst >= 2 dt
    DOCS + "XMLreference.html#option-flag-sleep",  # sleeping: opt-in, off by default
)
DETECTION = frozenset({Kind.AABB, Kind.SPHERE})
STIFF_RTOL = 2e-4
"""The stiff contact's precision (``response_rtol``), relative to the case's largest velocity
component, measured off the suite: ``python -m tools.stiff_precision --cases 10000`` draws
10,000 random touching pairs (2-D and 3-D, mass ratios 1e-3 to 1e3, e in (0, 1], head-on
to grazing; none of them in ``cases/``) and gave a median of 9.8e-8, 99% within 5.7e-6
and a worst of 1.48e-4 (a grazing 2-D pair, B 225 times lighter: the line of centres
turns while the contact lasts); declared as that worst, rounded up."""


def sizes_of(case: PairCase) -> tuple[Vec3, Vec3]:
    """Geom sizes of A and B: radius (then 0, 0) or half-sizes (2-D: z half-width added)."""
    if isinstance(case, AabbCase):
        if case.dim == 3:
            return to3(case.a.half), to3(case.b.half)
        hz = z_half(case.a.half, case.b.half)
        return (case.a.half[0], case.a.half[1], hz), (case.b.half[0], case.b.half[1], hz)
    return (case.a.radius, 0.0, 0.0), (case.b.radius, 0.0, 0.0)


def non_finite(case: PairCase) -> str:
    """The first non-finite position or size of a detection case, in words ('' if none)."""
    named = [("a.center", case.a.center), ("b.center", case.b.center)]
    if isinstance(case, AabbCase):
        named += [("a.half", case.a.half), ("b.half", case.b.half)]
    else:
        named += [("a.radius", (case.a.radius,)), ("b.radius", (case.b.radius,))]
    for name, values in named:
        bad = [x for x in values if not math.isfinite(x)]
        if bad:
            return f"{name} holds {bad[0]!r}"
    return ""


def _conventions(rtol: float, restitution: str, time_step: float | None,
                 notes: str, rest: Rest, *, soft: bool = False, friction: float = 0.0,
                 response_rtol: float | None = None, sampled: bool = False) -> Conventions:
    return Conventions(
        box_extents="half (a box geom's size is its half-sizes)",
        normal="geom[0] to geom[1] (contact frame; mj_geomDistance's fromto from geom1 to "
               "geom2); A is geom 0: no flip",
        touching={"sphere": True, "face": True, "edge": True, "corner": False},
        margins={},
        rtol=rtol,
        restitution=restitution,
        restitution_threshold=0.0,
        resolves_separating=False,
        time_step=time_step,
        damping=0.0,
        restitution_model="soft" if soft else "",
        friction=friction,
        response_rtol=response_rtol,
        sampled_contacts=sampled,
        zero_mass="",
        negative_extents="",
        rest_gap=rest.rest_gap,
        rest_sink_steps=rest.rest_sink_steps,
        rest_sink_s2=rest.rest_sink_s2,
        sleeps=rest.sleeps,
        wall_restitution=rest.wall_restitution,
        notes=notes + rest.notes,
        sources=SOURCES,
    )


_DETECTION_NOTES = (
    "hit = a contact from mj_collision (geom margin 0) with distance <= 0: touching spheres "
    "and face- or edge-touching boxes give contacts at distance 0, corner-touching boxes none "
    "(2-D corners are 3-D edges here and do collide); distance = mj_geomDistance (GJK/EPA for "
    "boxes: may read 0.0 for overlapping boxes where EPA fails, e.g. 2 of 300 random pairs at "
    "1e6, while the contact's dist is right: reported as is); normal = the contact frame in "
    "contact, else the fromto segment.  Zero or negative sizes and zero masses: the compiler "
    "refuses them (error rows); NaN/inf positions are read silently (reported undefined).  ")
_SCENE_NOTES = (
    "Scenes (adapters/mujoco/scene.py): one compiled model of free spheres per scene; 2-D "
    "in z = 0, solver noise out of the plane dropped within 2^-40 of the scene's scale.  ")
_RESPONSE_NOTES = (
    "Responses: free spheres stepped until no contact is active and they no longer approach; "
    "resolved_at = the centres at the start of the first step whose collision pass found an "
    "active contact; a warning (bad qpos/qvel/qacc: MuJoCo resets the state) is raised.  ")


MARGIN_GAP = ("https://github.com/google-deepmind/mujoco/blob/"
              "a7255075b003506ff5f34b512d88e02df12a73c6/doc/computation/index.rst#margin-and-gap")
"""The margin-and-gap rules at the commit the adapter reads (rendered: ``DOCS`` +
computation/index.html#comargingap)."""
CLAIMS = (
    Claim("hit", ("sphere", "aabb"), 0.0,
          "Computation, margin and gap: \"No contact (distance > margin + gap): The geom "
          "surfaces, including their gap buffers, are not overlapping. No contact is "
          "generated.\" With margin and gap 0 (this variant's), a pair apart has no contact",
          MARGIN_GAP, gap=APART),
    Claim("hit", ("sphere", "aabb"), 0.0,
          "Computation, margin and gap: \"Active contact (distance <= margin): The contact is "
          "active and constraint forces are generated.\" With margin 0 (this variant's), "
          "every overlapping pair is in contact", MARGIN_GAP, gap=OVERLAP),
)
"""MuJoCo's contact rule as a claim on the verdict (margin and gap 0)."""


class MujocoDefault(SceneCallsAdapter):
    """MuJoCo as a user gets it: only geometry, masses and velocities are set."""

    name: ClassVar[str] = "mujoco-default"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "mujoco"
    package: ClassVar[str] = "mujoco-core"
    settings: ClassVar[str] = (
        "two free bodies, gravity 0; defaults: Euler, dt 0.002 s, solref 0.02 1, solimp 0.9 "
        "0.95 0.001 0.5 2, condim 3, friction 1, margin 0; response inertia 2/5 m r^2 (a solid "
        "sphere, as MuJoCo computes it from a geom's mass); 2-D boxes get z half-width 2x the "
        "largest half-width")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        Kind.AABB, Kind.SPHERE, Kind.SPHERE_RESPONSE, Kind.SPHERE_SCENE)
    claims: ClassVar[tuple[Claim, ...]] = CLAIMS
    conventions: ClassVar[Conventions] = _conventions(
        2.0**-50,
        "no coefficient of restitution: MuJoCo's default soft contact (solref 0.02 1, solimp "
        "0.9 0.95 0.001 0.5 2); the case's e is not read",
        0.002,
        _DETECTION_NOTES + _RESPONSE_NOTES + _SCENE_NOTES + (
            "Default contact: a 1 m/s head-on bounce of equal spheres leaves at about +-0.14 "
            "whatever e the case or scene asks; friction 1 acts on oblique impacts.  Contacts are "
            "sampled at step starts and make force only below the margin (0): a grazing "
            "contact shorter than a step gets none.  "),
        DEFAULT_REST, soft=True, friction=1.0, sampled=True)
    stiff: ClassVar[response.Stiff | None] = None
    scene_tuning: ClassVar[Tuning | None] = None
    """What scenes are built with (see adapters/mujoco/scene.py); None: MuJoCo's defaults."""
    condim: ClassVar[str] = ""
    """Extra MJCF attributes of the response geoms."""

    calls: ClassVar[str] = "adapters.mujoco.calls"

    def version(self) -> str:
        return str(engine().mj_versionString())

    def available(self) -> str | None:
        return import_problem(engine, "mujoco")

    binding_objects: ClassVar[tuple[str, ...]] = ("*/mujoco/_*.so", "libmujoco.so*")
    """The engine's shared objects for the instruction timer: MuJoCo's pybind11 modules
    (mujoco/_functions, _structs, ...) and libmujoco.
    """

    def binding_call(self) -> Callable[[], object]:
        """``mj_version()``: one call through the pybind11 binding into libmujoco."""
        return engine().mj_version  # type: ignore[no-any-return]

    def _refusal(self, case: PairCase, geom: str, sizes: tuple[Vec3, Vec3],
                 masses: tuple[Mass, Mass] | None) -> Exception | None:
        why = refusal(geom, sizes, masses)
        return refused(f"MuJoCo's compiler refuses this case: {why}" if why else None)

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """Detection in the compiled pair of the case's geom; never asked on a non-finite
        input (every quantity undefined: MuJoCo reads it silently)."""
        geom = "box" if isinstance(case, AabbCase) else "sphere"
        sizes = sizes_of(case)
        bad = non_finite(case)
        mjcf = pair_mjcf(geom, (UNIT[geom],) * 2, (ONE,) * 2, "")
        return Call("detection", "detect", {
            "model": mjcf, "geom": geom, "a_size": sizes[0], "b_size": sizes[1],
            "a_center": case.a.center, "b_center": case.b.center, "dim": case.dim},
            refusal=self._refusal(case, geom, sizes, None), model=mjcf,
            undefined=f"non-finite input ({bad}): MuJoCo's detection reads it silently"
            if bad else "")

    def response_call(self, case: ResponseCase) -> Call:
        """Two free spheres stepped until the contact is over (the stiff variant: its contact
        fitted to the case, :func:`adapters.mujoco_response.stiff_contact`)."""
        masses = self.masses(case)
        refused = self._refusal(case, "sphere", sizes_of(case), masses)
        contact = (None if self.stiff is None or refused is not None  # refused: never fitted
                   else response.stiff_contact(case, self.stiff))
        mjcf = pair_mjcf("sphere", (UNIT["sphere"],) * 2, (ONE,) * 2, self.condim)
        (ma, ia), (mb, ib) = masses
        return Call("response", "respond", {
            "model": mjcf, "stiff": self.stiff is not None, "a_center": case.a.center,
            "a_velocity": case.a.velocity, "a_radius": case.a.radius, "a_mass": ma,
            "a_inertia": ia, "b_center": case.b.center, "b_velocity": case.b.velocity,
            "b_radius": case.b.radius, "b_mass": mb, "b_inertia": ib, "dim": case.dim,
            "solref": None if contact is None else contact.solref,
            "timestep": None if contact is None else contact.timestep,
            "max_steps": response.MAX_STEPS},
            refusal=refused, model=mjcf)

    def scene_call(self, case: SceneCase) -> Call:
        """The scene's model (MJCF) compiled and stepped with the variant's settings."""
        inputs = scene_inputs(case)
        mjcf = scene_model(inputs["bodies"], inputs["walls"], self.scene_tuning)
        settings = scene_settings(bool(case.walls) or any(inputs["gravity"]), case.restitution,
                                  inputs["dt"], self.scene_tuning)
        return Call("scene", "step_scene", {"model": mjcf, **inputs, **settings}, model=mjcf)

    def masses(self, case: ResponseCase) -> tuple[Mass, Mass]:
        """Mass and inertia of A and B: a solid sphere's, 2/5 m r^2 (MuJoCo's for a geom)."""
        return ((case.a.mass, (0.4 * case.a.mass * case.a.radius ** 2,) * 3),
                (case.b.mass, (0.4 * case.b.mass * case.b.radius ** 2,) * 3))


class MujocoStiff(MujocoDefault):
    """MuJoCo with a stiff, frictionless spring-dashpot contact fitted to each response case."""

    name: ClassVar[str] = "mujoco"
    settings: ClassVar[str] = (
        "responses only: two free bodies, gravity 0, condim 1 (frictionless), RK4, solver "
        "tolerance 1e-15, solimp flat 0.9999, direct solref (-w0^2, -2 zeta w0) with w0 = "
        "relative speed / (10 sqrt(P R 2^-52)) capped at 1e9 / speed and zeta giving the "
        "case's e, dt = contact duration / 256, geom margin 2^-1022; inertia = mass (no "
        "rotation takes part)")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_RESPONSE,
                                                                     Kind.SPHERE_SCENE)
    claims: ClassVar[tuple[Claim, ...]] = ()  # detection is scored under mujoco-default only
    conventions: ClassVar[Conventions] = _conventions(
        2.0**-50,
        "no coefficient of restitution in MuJoCo: a linear spring-dashpot (direct solref) "
        "whose restitution, force stopped at zero, is the case's e; e = 0 and e outside "
        "[0, 1] skipped",
        None,
        _RESPONSE_NOTES + _SCENE_NOTES + (
            "Scenes: the stiff frictionless contact with the scene's e lasting one scene step "
            "in 8 RK4 sub-steps (e = 1 head-on: velocities exchanged within 5e-4 "
            "measured, beyond the declared response_rtol of a pair response, so such "
            "scene rows read error; momentum to rounding); a touching chain answers as one "
            "block.  Contacts are sampled "
            "(declared sampled_contacts, as the default variant's): MuJoCo has no "
            "continuous collision detection, mj_step finds contacts at the positions each "
            "sub-step starts from, and the stiff contact is fitted to act over one scene "
            "step, so a pair that crosses the overlap window in less than a scene step "
            "(step travel above 1) is not turned back: it passes through, as a sampling "
            "engine's pair does.  "
            "Stiff contact fitted per case (adapters/mujoco_response.py), frictionless "
            "(condim 1) with the case's e: no friction, no soft model.  The time step is the "
            "contact's duration / 256, so no single time_step is declared.  response_rtol: "
            "the velocities' precision, the worst error over the largest velocity component "
            "on random touching pairs outside the suite (python -m tools.stiff_precision "
            "--cases 10000), rounded up.  Detection is the same engine call as "
            "mujoco-default's and is scored there only.  "),
        TUNED_REST, response_rtol=STIFF_RTOL, sampled=True)
    stiff: ClassVar[response.Stiff | None] = response.Stiff()
    scene_tuning: ClassVar[Tuning | None] = Tuning()
    condim: ClassVar[str] = ' condim="1"'

    def unsupported(self, case: AnyCase) -> str | None:
        if case.kind_enum in DETECTION:
            return ("mujoco (stiff) sets contact dynamics only: detection is the same engine "
                    "call as mujoco-default's and is scored there")
        if isinstance(case, ResponseCase | SceneCase) and (why := response.restitution_refusal(
                case.restitution)):
            return f"mujoco (stiff): {why}"
        return super().unsupported(case)

    def masses(self, case: ResponseCase) -> tuple[Mass, Mass]:
        """Mass, and inertia equal to it: frictionless contact through the centres, no torque."""
        return ((case.a.mass, (case.a.mass,) * 3), (case.b.mass, (case.b.mass,) * 3))
