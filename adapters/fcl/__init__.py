"""FCL 0.7.0 through python-fcl 0.7.0.11 as an engine: ``fcl``, and its CCD solvers as variants.

The calls, plain data in and out, are :mod:`adapters.fcl.calls`.
Times of impact (``sphere_toi``, 2-D at z = 0 and 3-D) are described in :mod:`adapters.fcl.ccd`:
``fcl`` asks ``continuousCollide`` with python-fcl's default request (conservative
advancement, translation motion); ``fcl-ccd-naive`` (:class:`FclCcdNaive`, ``sphere_toi``
only) asks it with ``CCDC_NAIVE``.  ``fcl-ccd-ray-shooting`` and ``fcl-ccd-polynomial``
stay in the registry, so that each solver is a row of the report, but declare no
capability: FCL 0.7.0 computes neither for two spheres (``continuousCollide`` returns -1,
"not computed"), so every ``sphere_toi`` case is a ``skip`` whose reason cites FCL's source
(:data:`adapters.fcl.ccd.UNSUPPORTED`), not a wrong answer.

FCL answers collision and distance queries; it has no dynamics, so ``sphere_response`` is
unsupported.  A case becomes two ``CollisionObject`` s (a ``Box`` or ``Sphere`` at the
case's centre, identity rotation): no world, client or broadphase.  Nothing is built per
case: ``release`` keeps the pair idle, and the next case of its geometry sets its sizes and
translations (see :mod:`adapters.fcl.calls`).  ``query`` makes two calls, each with
fresh result objects, so it is repeatable (``query_without(prepared, {"distance"})`` makes
only the first: the runner's way round the declared hang below):

- ``collide(A, B, CollisionRequest(enable_contact=True, num_max_contacts=1))``: ``hit`` is
  ``CollisionResult.is_collision``; in collision, ``normal`` is the contact's normal.
- ``distance(A, B, DistanceRequest(enable_nearest_points=True,
  enable_signed_distance=True))``: ``distance`` is its value (gap positive, penetration
  negative).  Without a collision and with a distance > 0, ``normal`` is the unit vector
  from A's nearest point to B's (world frame).  Without a collision and with a distance
  <= 0 (edge-touching boxes), or without nearest points, the engine gives no direction:
  ``normal`` is None.

Both use the default narrow phase, ``GST_LIBCCD``.  2-D: discs are spheres at z = 0; a 2-D
box gets the z half-width 2 x the case's largest half-width (1 if all are 0), both centred
at z = 0, so the z overlap exceeds any x or y overlap and z is never the axis of least
overlap nor a gap; normals come back without z.

Conventions (sources in ``SOURCES``; FCL files at tag v0.7.0):

- box extents full: ``Box(x, y, z)`` takes side lengths [fcl.pyx]; the adapter passes 2 x
  the half-widths (exact in binary).  ``Contact.normal`` points "from o1 to o2"
  [contact.h]: A to B, no flip.
- touching is contact for spheres (``sphereSphereIntersect`` rejects only ``len > r1 +
  r2``) and for face-touching boxes (``boxBox2`` separates only on ``s2 > 0``).  Edge- and
  corner-touching boxes do NOT collide here: ``boxBox2`` finds an intersection but clips
  no contact point, and with ``enable_contact`` a collision is recorded only through its
  contacts [shape_collision_traversal_node-inl.h]; with ``enable_contact=False`` the same
  pair collides (measured).  Declared per feature: sphere, face: contact; edge, corner:
  apart.
- margin 1e-6: ``GJKSolver_libccd``'s distance and collision tolerances
  [gjk_solver_libccd-inl.h].  ``collide`` is analytic for both pairs (sphere-sphere,
  ``boxBox2``); the signed distance is GJK/EPA on support functions, with no special path
  for two spheres [issue 345].  rtol 2^-50 (float64 throughout).
- no dynamics: no time step (None), no damping, no masses (``zero_mass`` "").
- negative sizes are not read as magnitudes (``negative_extents`` ""): a sphere of negative
  radius answers exactly as the textbook's literal |d| - ra - rb, a box with one negative
  half-width as the literal textbook formula too; a box with all half-widths negative
  answers as neither (measured here: 2.5 where the literal formula gives 3.2 and the
  magnitudes -1.5).

Known hang: only the signed distance hangs on coincident sphere centres, so
``hanging_quantities`` names ``distance`` alone; ``hit`` and ``normal`` come from ``collide``
(the normal is the contact's: the distance call adds nothing in collision).

Facts measured: signed sphere distances are exact when the centres differ only in x and
otherwise off by about the tolerance (a 0.5 overlap reads -0.49999958, a touch on a 3-4-5
diagonal +1.2e-7), but the declared margin is the solver's tolerance, not a bound on its
error: on 20,000 random unit-scale pairs (radii 0.1 to 2, centres 0.5 to 1.5 x the radius
sum apart) overlapping ones were off by a median 5e-7, 99th percentile 9e-7, worst 1.2e-4,
separated ones by a median 5e-7, 99th percentile 2.6e-5, worst 1.3e-3 (27% beyond 1e-6; in
the suite up to 1.6e-6); and the nearest points of separated spheres off by up to 4e-4 rad
in direction.  Box-box distances along x are exact at unit scale (the absolute GJK tolerance
shows on 1e-9 boxes: a 2e-9 gap reads 4.5e-9), but boxes apart along y or z, or on a
diagonal, may read far off: unit 2-D boxes 16 apart along -y read 16.1245 with a normal
0.124 rad off (cases/cover.toml found it; the open upstream bug [issue 508]: unit cubes 3
apart along y read 3.16228 with the libccd solver, the one used here; along x they are
right).  It is an engine error, not a convention: nothing FCL documents explains it.
Coincident sphere centres hang the signed distance (EPA with a zero search direction) [issue
346]; box-box signed distance may hang too [issue 578]; NaN or infinite inputs crash it
(segmentation fault), except an infinite centre, for which it returns DBL_MAX and no nearest
points.  Coincident spheres collide with contact normal (0, 0, 0); coincident boxes with the
axis of least overlap, x on a tie.  A zero-size box on another's corner, or a subnormal gap,
reads -1 (the "mostly -1" of a failed signed distance [distance_request.h]).  With
``enable_contact=False`` the Contact's normal and depth are uninitialised memory.  """

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar

from adapters.fcl import ccd as fcl_toi
from adapters.shared import toi_refusal
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
    refused,
)
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, AnyCase, ResponseCase, SphereCase, ToiCase

FCL = "https://github.com/flexible-collision-library/fcl/"
TREE = FCL + "blob/v0.7.0/include/fcl/narrowphase/"
SOURCES = (
    "https://github.com/BerkeleyAutomation/python-fcl/blob/master/src/fcl/fcl.pyx",
    TREE + "contact.h",
    TREE + "distance_request.h",
    TREE + "detail/primitive_shape_algorithm/sphere_sphere-inl.h",
    TREE + "detail/primitive_shape_algorithm/box_box-inl.h",
    TREE + "detail/traversal/collision/shape_collision_traversal_node-inl.h",
    TREE + "detail/gjk_solver_libccd-inl.h",
    FCL + "issues/345",
    FCL + "issues/346",
    FCL + "issues/578",
    FCL + "issues/508",
)
GJK_TOLERANCE = 1e-6
TOI_NOTES = (
    "Times of impact: continuousCollide with python-fcl's default request (conservative "
    "advancement, CCDM_TRANS); toi = time_of_contact x duration; normal from the case's "
    "centres at that time (the binding gives no contact normal), none where they coincide "
    "then (declared no_value float64-centre-line). Target separation 0; it "
    "stops once a step is <= 1e-4 of the interval (t_err, hard-coded), so the surfaces may "
    "be up to 1e-4 x the closing travel apart: declared toi_time_tolerance 1e-4 (of the "
    "interval). A first touch exactly at the interval's end reads as no contact (toc < 1 "
    "required): declared toi_end_excluded.")
"""``GJKSolver_libccd``'s default ``distance_tolerance`` and ``collision_tolerance``."""


CLAIMS = (
    Claim("distance", ("sphere", "aabb"), GJK_TOLERANCE,
          "DistanceRequest: \"the distance computation routine computes only the exact positive "
          "distance when the two objects are not in collision\"; distance_tolerance, \"the "
          "threshold used in GJK algorithm to stop distance iteration\", defaults to 1e-6 "
          "(DistanceRequest and GJKSolver_libccd, the GST_LIBCCD solver python-fcl uses)",
          TREE + "distance_request.h", gap=APART),
    Claim("distance", ("sphere", "aabb"), GJK_TOLERANCE,
          "DistanceRequest.enable_signed_distance: \"FCL will perform additional collision "
          "checking when the two objects are in collision in order to get the exact negative "
          "distance, which is the negated penetration depth\" (primitive shapes with "
          "GST_LIBCCD: \"SD_1: Signed distance is computed using convexity based methods\"), "
          "GJKSignedDistance stopping at distance_tolerance 1e-6",
          TREE + "distance_request.h", gap=OVERLAP),
)
"""FCL's published accuracy of the signed distance (:mod:`crosscheck.core.claims`): its GJK
distance tolerance, apart and in collision (detail/gjk_solver_libccd-inl.h passes
``distance_tolerance`` to both ``GJKDistance`` and ``GJKSignedDistance``)."""


def engine() -> Any:
    """The ``fcl`` module, imported on first use."""
    import fcl

    return fcl


def z_half(case: AabbCase) -> float:
    """The z half-width of both boxes of a 2-D case (:func:`crosscheck.core.geometry.z_half`)."""
    return geometry.z_half(case.a.half, case.b.half)


class Fcl(CallsAdapter):
    """FCL's ``collide`` (verdict, contact normal) and signed ``distance``."""

    name: ClassVar[str] = "fcl"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "python-fcl"
    package: ClassVar[str] = "python-fcl"
    settings: ClassVar[str] = (
        "collide: CollisionRequest(enable_contact=True, num_max_contacts=1); distance: "
        "DistanceRequest(enable_nearest_points=True, enable_signed_distance=True); "
        "GST_LIBCCD; 2-D: z = 0, boxes get z half-width 2 x the largest half-width")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        Kind.AABB, Kind.SPHERE, Kind.SPHERE_TOI)
    solver: ClassVar[str] = "conservative advancement"
    """Times of impact: the CCD solver (a key of :data:`adapters.fcl_toi.SOLVERS`)."""
    conventions: ClassVar[Conventions] = Conventions(
        box_extents="full (Box takes side lengths; the adapter doubles half-widths)",
        normal="o1 to o2 (Contact.normal), i.e. A to B; no flip",
        touching={"sphere": True, "face": True, "edge": False, "corner": False},
        margins=dict.fromkeys(FEATURES, GJK_TOLERANCE),
        rtol=2.0**-50,
        restitution="not applicable: FCL has no dynamics",
        time_step=None,
        damping=0.0,
        zero_mass="",
        negative_extents="",
        no_value=(fcl_toi.CENTRE_LINE,),
        toi_time_tolerance=1e-4,
        toi_end_excluded=True,
        notes=("Touching spheres and face-touching boxes collide; edge- or corner-touching "
               "boxes do not (no contact point with enable_contact). Signed distance is "
               "GJK/EPA, within 1e-6 (not for boxes apart along y or z, or on a diagonal: "
               "unit boxes 16 apart along -y read 16.1245, the open upstream issue 508); "
               "coincident sphere centres hang it (only the distance: "
               "collide answers, so hit and normal are still scored). Negative radii and "
               "half-widths read literally, not as magnitudes (measured here). " + TOI_NOTES),
        sources=SOURCES + fcl_toi.SOURCES,
    )
    claims: ClassVar[tuple[Claim, ...]] = CLAIMS

    calls: ClassVar[str] = "adapters.fcl.calls"

    def version(self) -> str:
        return str(engine().__version__)

    def available(self) -> str | None:
        return import_problem(engine, "fcl")

    binding_objects: ClassVar[tuple[str, ...]] = (
        "fcl.cpython-*.so", "libfcl-*.so*", "libccd-*.so*")
    """The engine's shared objects for the instruction timer: python-fcl's Cython module and the
    libfcl and libccd it bundles (python_fcl.libs/).
    """

    def binding_call(self) -> Callable[[], object]:
        """An identity ``fcl.Transform()``: one C++ object made through the Cython binding."""
        return engine().Transform  # type: ignore[no-any-return]

    def unsupported(self, case: AnyCase) -> str | None:
        if isinstance(case, ResponseCase):
            return "fcl has no dynamics: collision and distance queries only"
        return super().unsupported(case)

    def known_hang(self, case: AnyCase) -> str | None:
        if isinstance(case, SphereCase) and list(case.a.center) == list(case.b.center):
            return "fcl's signed distance loops on coincident sphere centres (fcl issue 346)"
        return None

    def hanging_quantities(self, case: AnyCase) -> frozenset[str]:
        """Only ``distance``: ``collide`` answers the verdict and the contact's normal."""
        return frozenset({"distance"}) if self.known_hang(case) else frozenset()

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """``collide`` and the signed ``distance`` (``partial``: ``collide`` alone)."""
        build = "boxes" if isinstance(case, AabbCase) else "spheres"
        return Call(build, "collide_and_distance", pair_inputs(case), release="release",
                    partial="collide_only")

    def toi_call(self, case: ToiCase) -> Call:
        """``continuousCollide`` with the variant's solver; refused for inputs FCL would take
        unchecked (:func:`adapters.shared.toi_refusal`)."""
        a, b = case.a, case.b
        inputs: dict[str, Any] = {
            "a_center": a.center, "a_radius": a.radius, "a_velocity": a.velocity,
            "b_center": b.center, "b_radius": b.radius, "b_velocity": b.velocity,
            "duration": case.duration}
        return Call("sweep", "continuous", {**inputs, "solver": fcl_toi.SOLVERS[self.solver]},
                    refusal=refused(toi_refusal(**inputs)))


def _ccd_conventions(solver: str, notes: str, samples: int = 0) -> Conventions:
    return Conventions(
        toi_samples=samples,
        normal="from A's centre to B's at the reported time (computed: the binding gives no "
               "contact normal); none where the centres coincide then",
        no_value=(fcl_toi.CENTRE_LINE,),
        touching={"sphere": True},
        rtol=2.0**-50,
        restitution="not applicable: FCL has no dynamics",
        notes=f"continuousCollide with ccd_solver_type {fcl_toi.SOLVERS[solver]} (CCDM_TRANS, "
              f"GST_LIBCCD, num_max_iterations 10, toc_err 1e-4: the request's defaults). "
              + notes,
        sources=fcl_toi.SOURCES,
    )


class FclCcdNaive(Fcl):
    """FCL's naive CCD: 10 discrete collision tests evenly spaced over the interval."""

    name: ClassVar[str] = "fcl-ccd-naive"
    settings: ClassVar[str] = (
        "continuousCollide: ContinuousCollisionRequest(ccd_solver_type=CCDC_NAIVE), "
        "otherwise defaults; 2-D: z = 0")
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE_TOI)
    claims: ClassVar[tuple[Claim, ...]] = ()  # times of impact only: no distance to claim
    solver: ClassVar[str] = "naive"
    conventions: ClassVar[Conventions] = _ccd_conventions(
        "naive", "Samples collide() at t = i / 9 of the interval, i = 0..9 (min(10, "
                 "ceil(1 / toc_err)) tests) and reports the first sample in collision: a "
                 "contact between samples is missed, a found one is late by up to 1/9 of the "
                 "interval (declared toi_samples 10).", samples=10)


class FclCcdRayShooting(FclCcdNaive):
    """FCL's ray-shooting CCD: not implemented in FCL 0.7.0 for two geometries, so no
    ``sphere_toi`` case is supported (every row a ``skip`` with FCL's source)."""

    name: ClassVar[str] = "fcl-ccd-ray-shooting"
    settings: ClassVar[str] = (
        "continuousCollide: ContinuousCollisionRequest(ccd_solver_type=CCDC_RAY_SHOOTING), "
        "otherwise defaults; 2-D: z = 0")
    capabilities: ClassVar[frozenset[Capability]] = frozenset()
    solver: ClassVar[str] = "ray shooting"
    conventions: ClassVar[Conventions] = _ccd_conventions(
        "ray shooting", "Not implemented for two geometries (an empty branch): FCL returns -1 "
                        "(not computed) and leaves is_collide False. The variant supports no "
                        "case: every sphere_toi row is a skip citing continuous_collision-inl.h.")

    def unsupported(self, case: AnyCase) -> str | None:
        if isinstance(case, ToiCase):
            return f"{self.name}: {fcl_toi.UNSUPPORTED[self.solver]}"
        return super().unsupported(case)


class FclCcdPolynomial(FclCcdRayShooting):
    """FCL's polynomial-solver CCD: BVH meshes only, so no ``sphere_toi`` case is supported
    (every row a ``skip`` with FCL's source)."""

    name: ClassVar[str] = "fcl-ccd-polynomial"
    settings: ClassVar[str] = (
        "continuousCollide: ContinuousCollisionRequest(ccd_solver_type="
        "CCDC_POLYNOMIAL_SOLVER), otherwise defaults; 2-D: z = 0")
    solver: ClassVar[str] = "polynomial"
    conventions: ClassVar[Conventions] = _ccd_conventions(
        "polynomial", "BVH meshes only: for two spheres FCL prints 'Warning! Invalid "
                      "continuous collision checking' to stderr and returns -1 (not computed). "
                      "The variant supports no case: every sphere_toi row is a skip citing "
                      "continuous_collision-inl.h.")
