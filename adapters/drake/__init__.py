"""Drake 1.51.1 (the Toyota Research Institute's robotics toolbox; its geometry engine,
``SceneGraph``) as an engine: ``drake``, 3-D sphere and box detection.

Drake's geometry queries answer detection alone here (no time of impact is asked, and
responses and scenes would need a ``MultibodyPlant``): ``prepare`` takes an idle scene graph
of two frames with one proximity geometry each (see :mod:`adapters.drake.calls`), changes its
shapes to the case's and fixes the centres as the frames' poses; ``query`` evaluates the
``QueryObject`` and makes two queries:

- ``ComputeSignedDistancePairwiseClosestPoints()``: ``distance`` is the pair's signed
  distance φ (positive apart; "If the objects touch or overlap (i.e., A ⋂ B ≠ ∅), φ ≤ 0 and
  can be interpreted as the negative penetration depth" [query_object.h]): the harness's
  signed distance, no conversion.  ``max_distance`` is left at its default, infinity ("If
  φ(A, B) > max_distance, the pair (A, B) will not be included in the results"), so the pair
  is always reported.  ``normal`` is ``nhat_BA_W`` ("always unit length and always point
  outward from B's surface" [signed_distance_pair.h]: from B to A) flipped to the
  harness's A to B when Drake's ``id_A`` is the case's A (Drake orders a pair by
  ``GeometryId`` [distance_to_shape_callback.cc], "arbitrary ... but guaranteed to be
  fixed and repeatable" [query_object.h]; the adapter reads the ids, so either order is
  right).
- ``ComputePointPairPenetration()``: ``hit`` is whether the pair is reported.

Conventions (sources in ``SOURCES``, at the tag v1.51.1; the facts below were measured here):

- box extents full: ``Box(width, depth, height)`` takes the box's dimensions
  [shape_specification.h]; the adapter passes 2 x the half-widths (exact in binary).
- normal: ``nhat_BA_W`` points from B to A [query_object.h, signed_distance_pair.h]: flipped.
- touching (the verdict is the penetration query's): "Geometries whose surfaces are just
  touching (osculating) are not considered in penetration.  Surfaces whose penetration is
  within an epsilon of osculation, are likewise not considered penetrating"
  [query_object.h].  The code that says which epsilon: a sphere pair is reported when
  ``depth = r_A - φ_B(c_A) >= 0``, so touching spheres ARE reported, at depth 0 (declared
  ``sphere`` True, against the header's sentence); a box pair goes through FCL's ``collide``
  and is dropped when ``depth <= std::numeric_limits<double>::epsilon()`` (FCL issue 375: no
  normal at osculation) [penetration_as_point_pair_callback.cc], so touching boxes do not
  collide (face, edge, corner False) and neither do boxes overlapping by up to DBL_EPSILON
  (2.2e-16 m, absolute): declared as the verdict's margin at face, edge and corner.
- the distance at touching is 0 for both pairs (measured).  The normal at distance 0:
  "For two geometries that are just touching (i.e., distance = 0), the underlying code can
  guarantee a correct value for nhat_BA_W only when one geometry is a sphere, and the other
  geometry is a sphere, a box, or a cylinder.  Otherwise ... the vector will be populated by
  NaN values" [signed_distance_pair.h]: touching boxes may get no normal, though Table 7 of
  query_object.h lists Box-Box as "Ok" (special code chooses it).  Declared as the no-value
  rule ``float64-textbook``: where the textbook itself has no normal (edge and corner
  touches, axis ties, coincident centres) a missing normal is Drake's declared behaviour; a
  missing one at a face touch stays an ``error``.  Measured: Drake gave a finite normal on
  every case of the suite it answered, also where the textbook has none (coincident sphere
  centres: ``nhat_BA_W`` (1, 0, 0)).
- precision: float64 throughout.  Sphere distances are closed-form (``|c_B - c_A| - r_B -
  r_A`` through ``DistanceToPoint`` [distance_to_shape_callback.cc]); ``rtol``
  (:data:`RTOL`) covers their rounding.  Box distances are FCL's GJK/EPA on libccd with
  Drake's hard-coded ``distance_tolerance`` 1e-6 [proximity_engine.cc; the TODO(#14731) of
  distance_to_shape_characterize_test.cc: "ProximityEngine hard codes this value to 1e-6"],
  declared as a margin of 1e-6 at every box feature on the distance and the normal (as
  coal's and FCL's GJK tolerance are); it never acts on the verdict, which is FCL's
  ``collide``.  Box-box normals away from touching are the witness points' direction,
  ``(p_WCa - p_WCb) / distance``; within 1e-14 of touching, ``CalcGradientWhenTouching``
  [distance_to_shape_callback.cc, distance_to_shape_touching.cc].
- engine faults measured on the suite (``error`` and ``crash`` rows, not declared): box
  pairs far from the origin or far apart relative to their size get GJK distances off by
  more than the tolerance (the worst relative error about 4e-3) and normals that are not
  unit vectors (the witness points disagree with the distance); near touching, the box-box
  gradient's checks fail: ``DRAKE_DEMAND`` (raised here as ``RuntimeError``) or
  ``DRAKE_UNREACHABLE`` ("Unreachable code was reached?!"), which aborts the process
  (``crash``) [distance_to_shape_touching.cc].
- Drake's published precision (Tables 1 and 4 of query_object.h) is declared as
  :attr:`Drake.claims`, never as an allowance.
- guarded inputs: a ``Box`` measure must be finite and positive ("@throws std::exception if
  any measure is not finite positive"), a ``Sphere`` radius finite and non-negative ("@throws
  std::exception if radius is not finite *non-negative*.  Note that a zero radius is
  considered valid") [shape_specification.h].  Drake documents those inputs as invalid, so
  the adapter refuses them (``ValueError`` in ``prepare``, an ``error`` row with the
  documented reason): zero or negative half-widths, negative radii, infinite or NaN sizes.
  (pydrake raises Drake's check as ``SystemExit`` [bindings/pydrake/common/module_py.cc],
  which would end the worker: the calls module turns it into ``ValueError``.)  A zero radius
  is passed.  Non-finite centres are passed: Drake raises ``RuntimeError`` ("SceneGraph
  encountered a non-finite value (e.g., NaN or infinity) on a pose input port"
  [scene_graph.cc]): an ``error`` row, Drake's own refusal (not in its API documentation).
- no dynamics: no restitution, no time step, no damping, no masses; no time of impact.
- negative sizes: refused (``negative_extents`` ""), as above.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from importlib.metadata import version as dist_version
from typing import Any, ClassVar

from crosscheck.core.claims import Claim
from crosscheck.core.contract import (
    Call,
    CallsAdapter,
    Capability,
    Conventions,
    import_problem,
    pair_inputs,
    refused,
)
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, SphereCase

DRAKE = "https://github.com/RobotLocomotion/drake/blob/v1.51.1/"
QUERY_OBJECT = DRAKE + "geometry/query_object.h"
DOXYGEN = "https://drake.mit.edu/doxygen_cxx/classdrake_1_1geometry_1_1_query_object.html"
SOURCES = (
    QUERY_OBJECT,  # signed distance, nhat_BA_W, osculation, max_distance, Tables 1, 4, 7
    DOXYGEN,
    DRAKE + "geometry/query_results/signed_distance_pair.h",  # nhat_BA_W from B to A
    DRAKE + "geometry/shape_specification.h",  # Box full measures; valid sizes
    DRAKE + "geometry/shape_specification.cc",  # DRAKE_THROW_UNLESS on the sizes
    DRAKE + "geometry/proximity/penetration_as_point_pair_callback.cc",  # depth >= 0; DBL_EPS
    DRAKE + "geometry/proximity/distance_to_shape_callback.cc",  # sphere closed form; FCL
    DRAKE + "geometry/proximity_engine.cc",  # distance_tolerance 1e-6, GST_LIBCCD
    DRAKE + "geometry/scene_graph.cc",  # non-finite poses throw
    DRAKE + "bindings/pydrake/common/module_py.cc",  # assertion failures as SystemExit
)
OSCULATION = 2.0**-52
"""``std::numeric_limits<double>::epsilon()``: a box overlap up to it is no penetration."""
DISTANCE_TOLERANCE = 1e-6
"""``ProximityEngine::distance_tolerance_`` (proximity_engine.cc), the ``distance_tolerance`` of
the FCL ``DistanceRequest`` (libccd GJK/EPA) behind every box-box signed distance."""
RTOL = 2.0**-50
"""Float64 rounding of the distance sums (4 units in the last place of the case's largest
number); see the module docstring."""

# --- claims --------------------------------------------------------------------------------
# Drake's tables (query_object.h) give the "Worst observed error (in m) for 2mm
# penetration/separation between geometries approximately 20cm in size for T = double",
# measured by distance_to_shape_characterize_test.cc and penetration_as_point_pair_
# characterize_test.cc as |reported signed distance (or -depth) - expected| alone (not the
# witness points, not the normal), on a sphere of radius 0.2 m and boxes 0.2 x 0.076 x
# 0.146 and 0.074 x 0.2 x 0.086 m (largest half-width 0.1 m), at +-2 mm, rotated and placed
# up to about 26 m from the origin (characterization_utilities.cc).  The text warns that the
# error "will vary" for larger geometries or larger distances, so the regime is a band of a
# factor 2 on each side of what was measured: sphere radius 0.1 to 0.4 m, box largest
# half-width 0.05 to 0.2 m, |gap| 1 to 4 mm (signed distance: both signs; penetration:
# overlaps only).  The suite's boxes are axis-aligned and its cases start at the origin, a
# narrower set than Drake's rotated, offset pairs.
CHARACTERIZED = DRAKE + "geometry/proximity/test/characterization_utilities.cc"
SD_TABLE = QUERY_OBJECT + "#L583-L594"
PENETRATION_TABLE = QUERY_OBJECT + "#L262-L273"
SPHERE_SIZE, BOX_SIZE = (0.1, 0.4), (0.05, 0.2)
GAP, OVERLAP, CLEAR = (-4e-3, 4e-3), (-4e-3, 0.0), 1e-3
CLAIMS = (
    Claim("distance", ("sphere",), 6e-15,
          "Table 4 (ComputeSignedDistancePairwiseClosestPoints): Sphere-Sphere 6e-15, "
          "\"Worst observed error (in m) for 2mm penetration/separation between geometries "
          "approximately 20cm in size for `T` = `double`\"",
          SD_TABLE, size=SPHERE_SIZE, gap=GAP, clear_of_touching=CLEAR, dims=(3,)),
    Claim("distance", ("aabb",), 4e-15,
          "Table 4 (ComputeSignedDistancePairwiseClosestPoints): Box-Box 4e-15, \"Worst "
          "observed error (in m) for 2mm penetration/separation between geometries "
          "approximately 20cm in size for `T` = `double`\"",
          SD_TABLE, size=BOX_SIZE, gap=GAP, clear_of_touching=CLEAR, dims=(3,)),
    Claim("distance", ("sphere",), 5e-15,
          "Table 1 (ComputePointPairPenetration): Sphere-Sphere 5e-15, \"Worst observed "
          "error (in m) for 2mm penetration between geometries approximately 20cm in size "
          "for `T` = `double`\" (a sphere pair's depth is exactly the negated signed "
          "distance the adapter reports: both are r_A - phi_B(c_A) up to the sign)",
          PENETRATION_TABLE, size=SPHERE_SIZE, gap=OVERLAP, clear_of_touching=CLEAR,
          dims=(3,)),
)
"""Drake's published precision for the suite's pairs (Box-Sphere has no kind here; the
penetration table's Box-Box 2e-15 speaks of FCL's ``collide`` depth, which the adapter does
not report: its box distance is the signed-distance query's)."""


def engine() -> Any:
    """The ``pydrake.geometry`` module, imported on first use."""
    import pydrake.geometry

    return pydrake.geometry


def rigid_transform() -> Any:
    """``pydrake.math.RigidTransform`` (the instruction timer's trivial call)."""
    from pydrake.math import RigidTransform

    return RigidTransform


def refusal(case: AabbCase | SphereCase) -> str | None:
    """Why Drake's documentation makes ``case``'s shapes invalid (None: they are valid)."""
    if isinstance(case, AabbCase):
        sizes = [*case.a.half, *case.b.half]
        if not all(math.isfinite(h) and h > 0 for h in sizes):
            return ("Drake documents a Box measure that is not finite positive as invalid "
                    f"(shape_specification.h: @throws): half-widths {case.a.half}, "
                    f"{case.b.half}")
        return None
    radii = (case.a.radius, case.b.radius)
    if not all(math.isfinite(r) and r >= 0 for r in radii):
        return ("Drake documents a Sphere radius that is not finite non-negative as invalid "
                f"(shape_specification.h: @throws): radii {radii[0]}, {radii[1]}")
    return None


class Drake(CallsAdapter):
    """Drake's SceneGraph: signed distance and penetration queries of two geometries."""

    name: ClassVar[str] = "drake"
    light_import = True  # pydrake is imported lazily (available(), prepare)
    engine: ClassVar[str] = "drake"
    package: ClassVar[str] = "drake"
    settings: ClassVar[str] = (
        "SceneGraph with one source, two frames and one proximity geometry each (Box: full "
        "widths = 2 x half-widths; Sphere), poses fixed on the source pose port; "
        "ComputeSignedDistancePairwiseClosestPoints(max_distance = inf) and "
        "ComputePointPairPenetration(); Drake's defaults otherwise; 3-D only")
    capabilities: ClassVar[frozenset[Capability]] = frozenset(
        {(Kind.AABB, 3), (Kind.SPHERE, 3)})
    conventions: ClassVar[Conventions] = Conventions(
        box_extents="full (Box(width, depth, height) takes the dimensions; the adapter "
                    "doubles half-widths)",
        normal="nhat_BA_W points from B to A: flipped to A to B",
        touching={"sphere": True, "face": False, "edge": False, "corner": False},
        margins=dict.fromkeys(("face", "edge", "corner"), DISTANCE_TOLERANCE),
        verdict_margins=dict.fromkeys(("face", "edge", "corner"), OSCULATION),
        rtol=RTOL,
        restitution="not applicable: Drake's geometry queries have no dynamics",
        time_step=None,
        damping=0.0,
        zero_mass="",
        negative_extents="",
        no_value=("float64-textbook",),
        notes=("Verdict: ComputePointPairPenetration. Touching spheres are reported (depth "
               "r_A - phi_B(c_A) >= 0); box pairs only above an overlap of DBL_EPSILON "
               "(2.2e-16 m, absolute: 'within an epsilon of osculation'), so touching boxes "
               "do not collide. Touching boxes may have no normal (signed_distance_pair.h): "
               "declared where the textbook has none. Distance: the signed distance "
               "(negative overlapping, 0 touching), max_distance infinite. Normal: "
               "-nhat_BA_W (Drake's normal points from B to A). Sizes Drake documents as "
               "invalid (a box measure not finite positive, a radius not finite "
               "non-negative) are refused; non-finite centres make Drake raise. Box "
               "distances: FCL GJK/EPA (libccd), distance_tolerance 1e-6 (hard-coded in "
               "ProximityEngine): margin 1e-6 at box features. Drake's published precision "
               "is declared as claims."),
        sources=SOURCES,
    )
    claims: ClassVar[tuple[Claim, ...]] = CLAIMS

    calls: ClassVar[str] = "adapters.drake.calls"

    def version(self) -> str:
        return dist_version("drake")

    def available(self) -> str | None:
        return import_problem(engine, "drake (pydrake)")

    binding_objects: ClassVar[tuple[str, ...]] = ("*/pydrake/*.so", "libdrake.so*")
    """The engine's shared objects for the instruction timer: pydrake's pybind11 modules
    (``pydrake/geometry/__init__.so``, ``pydrake/math`` ...) and ``libdrake.so``, which holds
    SceneGraph, the proximity engine and the FCL and libccd Drake vendors.
    """

    def binding_call(self) -> Callable[[], object]:
        """An identity ``RigidTransform()``: one C++ object made through the binding."""
        return rigid_transform()  # type: ignore[no-any-return]

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        """The signed distance and the penetration verdict; refused for sizes Drake
        documents as invalid."""
        build = "boxes" if isinstance(case, AabbCase) else "spheres"
        return Call(build, "collide_and_distance", pair_inputs(case), release="release",
                    refusal=refused(refusal(case)))
