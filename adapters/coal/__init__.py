"""coal 3.0.3 (FCL's successor, the collision library of Pinocchio and MoveIt) as an engine:
``coal`` (GJK/EPA tolerance scaled to the case) and ``coal-default`` (coal's defaults).

coal answers collision and distance queries; it has no dynamics, so ``sphere_response`` and
``sphere_scene`` are unsupported.  ``prepare`` builds a case's two geometries (a ``Box`` or a
``Sphere``), their ``Transform3s`` (the case's centre, identity rotation), the two requests
and the ``ComputeCollision`` and ``ComputeDistance`` functors of the pair (they keep the
narrow-phase solver between calls instead of building one per call: measured here, a call
costs 0.75 to 0.87 of ``coal.collide`` / ``coal.distance``'s; the geometries are kept with
them, as the functors hold bare pointers).  Nothing is built per case: ``release`` keeps
the pair idle, and the next case of its geometry sets its sizes, translations and tolerance
(see :mod:`adapters.coal.calls`).  ``query`` makes two calls, each with a
fresh result (coal appends to a result, and stops early on one that is already satisfied),
so it is repeatable:

- ``ComputeCollision(tf_a, tf_b, CollisionRequest, CollisionResult)``: ``hit`` is
  ``CollisionResult.isCollision()``;
- ``ComputeDistance(tf_a, tf_b, DistanceRequest, DistanceResult)``: ``distance`` is
  ``min_distance``, the signed distance (``enable_signed_distance`` is on by default; gap
  positive, penetration negative: the opposite sign of python-fcl's ``penetration_depth``),
  ``normal`` is ``DistanceResult.normal``, a unit vector from o1 to o2 in collision and
  apart.  A normal that is not finite (coal's EPA gives NaN when it fails, with the distance
  -DBL_MAX) is reported as Undefined with the numbers.

2-D: discs are spheres at z = 0; a 2-D box gets the z half-width 2 x the case's largest
half-width (1 if all are 0), both centred at z = 0, so z is never the axis of least overlap
nor a gap; normals come back without z.  Inputs that are not finite are not passed to coal:
it answers them without complaint but wrongly (measured: a box with a NaN or infinite
centre collides at distance 0 with a NaN normal, a box with an infinite half-width collides
at distance 0 with normal z, a sphere with a NaN centre or radius is apart at distance NaN),
so every quantity is Undefined, with the field named.

Conventions (sources in ``SOURCES``; coal files at tag v3.0.0, whose narrow phase 3.0.3
keeps; every fact below was measured here on 3.0.3):

- box extents full: ``Box(x, y, z)`` stores ``halfSide = (x, y, z) / 2``
  [geometric_shapes.h]; the adapter passes 2 x the half-widths (exact in binary).
- normal from o1 to o2 [collision_data.h: ``DistanceResult::normal``], i.e. A to B; no flip.
- verdict: a pair collides when its signed distance minus ``security_margin`` (0) is at most
  ``collision_distance_threshold``, Eigen's ``dummy_precision`` 1e-12, absolute, set in the
  ``QueryRequest`` constructor and not exposed in Python [shape_shape_func.h,
  collision_data.h].  So touching spheres collide (declared ``sphere`` True, a convention
  against the textbook) and so does a gap up to 1e-12: margin 1e-12 at every feature.
- spheres: ``sphereSphereDistance`` is analytic, ``|cb - ca| - ra - rb`` (Eigen ``norm``),
  normal ``(cb - ca) / |cb - ca|``, or (1, 0, 0) when the centres are within DBL_EPSILON
  (absolute) [details.h].  Coincident centres do not hang, unlike python-fcl.
- boxes: box-box goes through GJK and, in collision, EPA [shape_shape_func.h table].  GJK
  declares a collision as soon as its ray is shorter than ``gjk_tolerance`` (absolute,
  default 1e-6) and EPA stops within ``epa_tolerance`` (default 1e-6) [gjk.cpp,
  narrowphase_defaults.h]: a gap below the tolerance reads as distance 0, a collision.  The
  box support function inflates the side it returns for a negative direction by 1 + 1e-10
  [support_functions.cpp], so every box is 1e-10 of its half-width larger on its -x, -y and
  -z sides: face-, edge- and corner-touching boxes overlap by that much and collide
  (declared touching True for each, the textbook's rule), a gap below 1e-10 of the
  half-width reads as a collision, and distances are off by up to sqrt(3) x 1e-10 of the
  largest half-width.  (The factor is a function-level static, fixed by the first box
  support call of the process: 1 + 1e-10 if that direction has a zero component, as the
  default initial guess (1, 0, 0) always has, else 1.  The adapter always uses the default
  guess.)  Conventions have no margin relative to size, so ``rtol`` carries it: rtol 2e-10
  x the case's largest number, which bounds every half-width (for spheres, whose distances
  are analytic, it is looser than needed).  Edge- and corner-touching normals are whatever
  EPA's polytope gives; the oracle has no normal there (a tie of axes), so they are scored
  ``undefined``, and near such a touch the declared allowance over the gap covers them.
- the box support function also picks the centre on any axis whose direction component is
  within 1e-12 (absolute) of 0, and GJK starts from the unit ray (1, 0, 0): below a size of
  about 1e-7 boxes fail (EPA returns -DBL_MAX with a NaN normal, GJK gives positive
  distances for overlapping boxes), whatever the tolerance.  coal documents no such rule,
  so none is declared (``no_value`` ()): the failed query is an ``error``, its distance
  (-1.8e308) and its normal (NaN, reported Undefined) alike, with one reason.
- margins per feature and quantity: the verdict threshold 1e-12 acts on the verdict alone
  (``verdict_margins``: sphere 1e-12; face, edge, corner the GJK/EPA tolerance's absolute
  part plus it, ``coal-default`` 1e-6 + 1e-12, ``coal`` 1e-12 + 1e-12); the GJK/EPA
  tolerance also acts on box distances and normals (``margins``: face, edge, corner 1e-6
  or 1e-12; none at spheres, whose distance is analytic).  rtol 2e-10 (the box inflation;
  the tuned tolerance's relative part, 1e-12 x M <= 4e-12 x the case's largest number, and
  float64 rounding fit in it).
- no dynamics: no time step (None), no damping, no masses (``zero_mass`` "").
- negative sizes are read literally (``negative_extents`` ""): ``halfSide`` keeps its sign
  and a sphere's distance is ``|d| - ra - rb`` as given (measured: the textbook's literal
  answers).

Variants: ``coal`` sets ``gjk_tolerance`` and ``epa_tolerance`` of both requests to
``min(max(1e-12 x M, 1e-12), 1e-3)``, where M is the case's largest ``|cb_i - ca_i| + |ha_i|
+ |hb_i|`` over the axes (spheres: ``|cb - ca| + |ra| + |rb|``; GJK works on the relative
transform, so offsets do not count): relative, far below the box inflation (1e-11 and 1e-10
x M did no better, measured); floored at 1e-12 because the support function cannot resolve
directions below that; capped at 1e-3 because GJK starts from a ray of length 1.  Measured on
300 random near-touching box pairs per size (relative gaps and overlaps 1e-15 to 1e-1):
without the floor, 102 of 1,500 distances at sizes 1e-6 to 1e-2 fell beyond the declared
allowance (the worst off by 1.9% of M), with it 1; with a cap of 0.5, 117 of 1,200 at sizes
1e11 to 1e15 (the worst off by 1.1% of M), with 1e-3, 8.  ``coal-default`` builds
``CollisionRequest()`` and ``DistanceRequest()`` unchanged (tolerances 1e-6).

Measured with the adapters on the same pairs (300 per size): at sizes 1e-6 to 1e9 ``coal``
leaves 0 to 3 distances per size beyond its allowance (separated boxes that GJK declares in
collision at distance 0, once an overlap of 2.4e-11 read as a gap of 1.1e-12: inaccuracies,
``error``), and at 1e-7, 1e-8 and 1e-9 fails (NaN
normal, -DBL_MAX) on 131, 151 and 269; ``coal-default`` gets 157 of the 300 verdicts wrong at
1e-6 (all within its 1e-6 margin), fails on every pair from 1e-7 down, and on 2 at size 1 and
7 at 100 (EPA's -DBL_MAX for gaps below its tolerance).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar

from crosscheck.core import geometry
from crosscheck.core.claims import APART, OVERLAP, Claim
from crosscheck.core.contract import (
    FEATURES,
    Call,
    CallsAdapter,
    Capability,
    Conventions,
    all_capabilities,
    import_problem,
    pair_inputs,
)
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, AnyCase, PairCase, ResponseCase, SceneCase, SphereCase

COAL = "https://github.com/coal-library/coal/blob/v3.0.0/"
SOURCES = (
    COAL + "include/coal/shape/geometric_shapes.h",  # Box: halfSide = side / 2
    COAL + "include/coal/collision_data.h",  # normal o1 -> o2; collision_distance_threshold
    COAL + "include/coal/internal/shape_shape_func.h",  # verdict; box-box by GJK, sphere analytic
    COAL + "src/narrowphase/details.h",  # sphereSphereDistance
    COAL + "src/narrowphase/support_functions.cpp",  # Box support: inflate 1 + 1e-10, 1e-12
    COAL + "src/narrowphase/gjk.cpp",  # absolute tolerance; initial ray; EPA stop
    COAL + "include/coal/narrowphase/narrowphase.h",  # runGJKAndEPA; EPA failure -> -DBL_MAX
    COAL + "include/coal/narrowphase/narrowphase_defaults.h",  # tolerances 1e-6
    COAL + "src/collision.cpp",  # ComputeCollision keeps its solver
    "https://coal-library.github.io/coal/",
)
DEFAULT_TOLERANCE = 1e-6
"""``GJK_DEFAULT_TOLERANCE`` and ``EPA_DEFAULT_TOLERANCE`` (narrowphase_defaults.h)."""
COLLISION_THRESHOLD = 1e-12
"""``QueryRequest::collision_distance_threshold``: Eigen's ``dummy_precision`` for double."""
BOX_RTOL = 2e-10
"""Covers the box inflation (sqrt(3) x 1e-10 of the largest half-width) and the rest."""
TUNED_REL, TUNED_FLOOR, TUNED_CAP = 1e-12, 1e-12, 1e-3
"""The tuned GJK/EPA tolerance: ``min(max(TUNED_REL x M, TUNED_FLOOR), TUNED_CAP)``."""


METRE = (0.1, 10.0)
"""\"Shapes on the order of the meter\" (narrowphase_defaults.h), read as sizes 0.1 to 10 m."""
_ORDER_OF_METRE = (
    "narrowphase_defaults.h: \"if the considered shapes are on the order of the meter, and the "
    "convergence criterion of GJK is the default VDB criterion, setting a tolerance of 1e-6 on "
    "the GJK algorithm makes it precise up to the micro-meter. The same is true for EPA.\" "
    "(GJK_DEFAULT_TOLERANCE = EPA_DEFAULT_TOLERANCE = 1e-6; on the order of the meter read "
    "here as sizes 0.1 to 10 m)")


def _claims(tolerances: str) -> tuple[Claim, ...]:
    """coal's published precision of the distance, apart (GJK) and in collision (EPA), for a
    variant whose tolerances are ``tolerances`` (in words)."""
    return (
        Claim("distance", ("sphere", "aabb"), DEFAULT_TOLERANCE,
              "QueryRequest.gjk_tolerance: \"This tolerance determines the precision on the "
              "estimated distance between two geometries which are not in collision. It is "
              "recommended to not set this tolerance to less than 1e-6.\" " + _ORDER_OF_METRE
              + tolerances, COAL + "include/coal/collision_data.h", size=METRE, gap=APART),
        Claim("distance", ("sphere", "aabb"), DEFAULT_TOLERANCE,
              "QueryRequest.epa_tolerance: \"This tolerance determines the precision on the "
              "estimated distance between two geometries which are in collision. It is "
              "recommended to not set this tolerance to less than 1e-6.\" " + _ORDER_OF_METRE
              + tolerances, COAL + "include/coal/collision_data.h", size=METRE, gap=OVERLAP),
    )


def engine() -> Any:
    """The ``coal`` module, imported on first use."""
    import coal  # type: ignore[import-untyped]

    return coal


def _numbers(case: PairCase) -> list[tuple[str, float]]:
    named = [(f"{side}.center[{i}]", x) for side, body in (("a", case.a), ("b", case.b))
             for i, x in enumerate(body.center)]
    if isinstance(case, AabbCase):
        halves = (("a", case.a.half), ("b", case.b.half))
        return named + [(f"{side}.half[{i}]", h) for side, half in halves
                        for i, h in enumerate(half)]
    return [*named, ("a.radius", case.a.radius), ("b.radius", case.b.radius)]


def non_finite(case: PairCase) -> str | None:
    """The first input that is not finite, as ``field = value``, or None."""
    return next((f"{name} = {x}" for name, x in _numbers(case) if not math.isfinite(x)), None)


def magnitude(case: PairCase) -> float:
    """M: the largest ``|cb_i - ca_i| + |ha_i| + |hb_i|`` (spheres ``|cb - ca| + |ra| + |rb|``)."""
    if isinstance(case, AabbCase):
        return max(abs(b - a) + abs(ha) + abs(hb) for a, b, ha, hb in zip(
            case.a.center, case.b.center, case.a.half, case.b.half, strict=True))
    d = geometry.norm(geometry.difference(case.a.center, case.b.center))
    return d + abs(case.a.radius) + abs(case.b.radius)


def tuned_tolerance(case: PairCase) -> float:
    """The ``coal`` variant's GJK and EPA tolerance for ``case`` (see the module docstring)."""
    return min(max(TUNED_REL * magnitude(case), TUNED_FLOOR), TUNED_CAP)


def _conventions(box_margin: float, tolerance: str) -> Conventions:
    """The declared rules of a variant whose GJK/EPA tolerance has ``box_margin`` as its
    absolute part (``tolerance``: the rule in words)."""
    return Conventions(
        box_extents="full (Box takes side lengths, halfSide = side / 2; the adapter doubles "
                    "half-widths)",
        normal="o1 to o2 (DistanceResult.normal), i.e. A to B; no flip",
        touching=dict.fromkeys(FEATURES, True),
        margins=dict.fromkeys(("face", "edge", "corner"), box_margin),
        verdict_margins={"sphere": COLLISION_THRESHOLD, **dict.fromkeys(
            ("face", "edge", "corner"), box_margin + COLLISION_THRESHOLD)},
        rtol=BOX_RTOL,
        restitution="not applicable: coal has no dynamics",
        time_step=None,
        damping=0.0,
        zero_mass="",
        negative_extents="",
        notes=("Verdict: signed distance <= 1e-12 (collision_distance_threshold, absolute), so "
               "touching spheres collide and a gap up to 1e-12 does. Sphere distances are "
               f"analytic. Box-box is GJK/EPA, tolerance {tolerance}; the box support "
               "function inflates each box's negative sides by 1e-10 of its half-width, so "
               "every touching box feature collides: declared in rtol 2e-10, as conventions "
               "have no margin relative to size. Below a size of about 1e-7 boxes fail (EPA "
               "-DBL_MAX, NaN normal): a NaN normal is reported Undefined. Non-finite inputs "
               "are not passed to coal (it answers them wrongly without complaint). Negative "
               "sizes read literally (measured here)."),
        sources=SOURCES,
    )


class CoalTuned(CallsAdapter):
    """coal with its GJK/EPA tolerance scaled to each case."""

    name: ClassVar[str] = "coal"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "coal"
    package: ClassVar[str] = "coal"
    settings: ClassVar[str] = (
        "gjk_tolerance = epa_tolerance = min(max(1e-12 x M, 1e-12), 1e-3) in both requests, M "
        "the case's largest |cb_i - ca_i| + |ha_i| + |hb_i| (spheres |cb - ca| + |ra| + |rb|); "
        "otherwise CollisionRequest()/DistanceRequest() defaults (DefaultGJK, DefaultGuess, "
        "128 GJK / 64 EPA iterations, security_margin 0); ComputeCollision and ComputeDistance "
        "functors; 2-D: z = 0, boxes get z half-width 2 x the largest half-width")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.AABB, Kind.SPHERE)
    tuned: ClassVar[bool] = True
    conventions: ClassVar[Conventions] = _conventions(
        TUNED_FLOOR, "min(max(1e-12 x M, 1e-12), 1e-3) (M: the case's magnitude)")
    claims: ClassVar[tuple[Claim, ...]] = _claims(
        "; this variant sets both to min(max(1e-12 x M, 1e-12), 1e-3), at most 1e-6 at these "
        "sizes, so the default's 1e-6 is the precision claimed")

    calls: ClassVar[str] = "adapters.coal.calls"

    def version(self) -> str:
        return str(engine().__version__)

    def available(self) -> str | None:
        return import_problem(engine, "coal")

    binding_objects: ClassVar[tuple[str, ...]] = (
        "coal_pywrap*.so", "libcoal.so*", "eigenpy_pywrap*.so", "libeigenpy.so*",
        "libboost_python*.so*")
    """The engine's shared objects for the instruction timer: coal's Boost.Python module, libcoal,
    and the eigenpy and Boost.Python conversions it calls.
    """

    def binding_call(self) -> Callable[[], object]:
        """An identity ``coal.Transform3s()``: one C++ object made through the binding."""
        return engine().Transform3s  # type: ignore[no-any-return]

    def unsupported(self, case: AnyCase) -> str | None:
        if isinstance(case, ResponseCase | SceneCase):
            return "coal has no dynamics: collision and distance queries only"
        return super().unsupported(case)

    def tolerance(self, case: PairCase) -> float | None:
        """The GJK/EPA tolerance this variant sets for ``case`` (None: coal's default)."""
        return tuned_tolerance(case) if self.tuned else None

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """The collision and the signed distance; never asked on a non-finite input (every
        quantity undefined: coal answers it wrongly without complaint)."""
        bad = non_finite(case)
        tolerance = None if bad else self.tolerance(case)
        why = f"coal answers non-finite input wrongly without complaint: {bad}" if bad else ""
        build = "boxes" if isinstance(case, AabbCase) else "spheres"
        return Call(build, "collide_and_distance", {**pair_inputs(case), "tolerance": tolerance},
                    release="release", undefined=why)


class CoalDefault(CoalTuned):
    """coal out of the box: CollisionRequest() and DistanceRequest() unchanged."""

    name: ClassVar[str] = "coal-default"
    settings: ClassVar[str] = (
        "CollisionRequest() and DistanceRequest() unchanged (gjk_tolerance = epa_tolerance = "
        "1e-6, DefaultGJK, DefaultGuess, 128 GJK / 64 EPA iterations, security_margin 0); "
        "ComputeCollision and ComputeDistance functors; 2-D: z = 0, boxes get z half-width "
        "2 x the largest half-width")
    tuned: ClassVar[bool] = False
    conventions: ClassVar[Conventions] = _conventions(
        DEFAULT_TOLERANCE, "1e-6 absolute (coal's default: a gap below it reads as a collision "
                           "at distance 0)")
    claims: ClassVar[tuple[Claim, ...]] = _claims("; this variant keeps the defaults")
