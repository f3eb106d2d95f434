"""FCL's continuous collision (``fcl.continuousCollide``) for ``sphere_toi`` cases: what each
solver does, its sources and the reasons of the variants that skip (the calls are
:mod:`adapters.fcl.calls`).

Used by the ``fcl`` adapter (python-fcl's default request: conservative advancement) and by
the variant ``fcl-ccd-naive`` (:mod:`adapters.fcl`).  The variants
``fcl-ccd-ray-shooting`` and ``fcl-ccd-polynomial`` are rows of the report too, but FCL
computes neither solver for two spheres: they support no case and skip every one with the
reason in :data:`UNSUPPORTED` (their ``query`` still makes the call, for the repro script).

``prepare`` builds two ``CollisionObject`` s (``Sphere(radius)`` at the case's start
centres, identity rotation; 2-D at z = 0), their end transforms ``center + velocity x
duration`` (float64, here) and the ``ContinuousCollisionRequest``; ``query`` makes the one
call ``continuousCollide(a, end_a, b, end_b, request, result)`` with a fresh
``ContinuousCollisionResult`` (python-fcl keeps the minimum of the time already in a
result object and the new one, so a reused result would remember an earlier query).

FCL's motion is ``CCDM_TRANS`` (``TranslationMotion``: the start transform moved linearly
to the end one over a normalised time in [0, 1]): ``toi`` = ``time_of_contact x
duration`` (one rounding, none for a duration of 1).  The binding exposes only
``is_collide`` and ``time_of_contact`` (not FCL's ``contact_tf1``/``contact_tf2``, no
contact point or normal), so ``normal`` is computed here from the case's centres at the
reported time (:func:`adapters.shared.centre_normal`, float64): Undefined where they
coincide then, the rule the adapters declare (``no_value`` :data:`CENTRE_LINE`, a rule of
:mod:`crosscheck.truth.no_value`).  Without a collision: ``hit`` False, ``toi`` and
``normal`` Undefined ("no contact in the interval").

What each solver does (FCL 0.7.0, include/fcl/narrowphase/continuous_collision-inl.h):

- ``CCDC_CONSERVATIVE_ADVANCEMENT`` (python-fcl's default; FCL's own C++ default is
  ``CCDC_NAIVE``): a start in collision is ``toc`` 0; otherwise it advances by ``distance /
  bound`` (the distance of the shapes over the bound on their approach along the
  nearest-points direction, ``ShapeConservativeAdvancementTraversalNode::leafTesting``)
  until a step is at most ``t_err`` = 1e-4 (normalised time; hard-coded in the traversal
  node, ``toc_err`` of the request is not read there), and reports a contact only for
  ``toc < 1``: a first touch exactly at the interval's end reads as no contact.  The
  target separation is 0 (touching); where it stops, the surfaces are up to 1e-4 x the
  bound (the closing travel over the whole interval) apart, a tolerance relative to the
  motion that a length (``toi_tolerance``) cannot state: declared 0, said in the notes.
  Measured: a head-on approach is found in one step, exactly.
- ``CCDC_NAIVE``: ``n = min(num_max_iterations, ceil(1 / toc_err))`` = 10 discrete
  collision tests at ``t = i / (n - 1)``, i = 0..9 (t = 0, 1/9, ..., 1), and the first in
  collision is the ``toc``: a sampled answer, which misses any contact between samples.
- ``CCDC_RAY_SHOOTING``: not implemented (an empty branch for two geometries): FCL returns
  -1 and leaves the result at no collision.
- ``CCDC_POLYNOMIAL_SOLVER``: BVH meshes only; for spheres it prints "Warning! Invalid
  continuous collision checking" to stderr and returns -1.

FCL's return value -1 is its "not computed": the engine does not support the query, so the
two variants declare every ``sphere_toi`` case unsupported (``skip`` rows, the reason citing
``continuous_collision-inl.h``) and are never asked in a run.  Asked directly,
the call answers Undefined for every quantity, with the reason, rather than read the
untouched result as "no contact".
"""

CCD = "https://github.com/flexible-collision-library/fcl/blob/v0.7.0/include/fcl/narrowphase/"
SOURCES = (
    "https://github.com/BerkeleyAutomation/python-fcl/blob/master/src/fcl/fcl.pyx",
    "https://github.com/BerkeleyAutomation/python-fcl/blob/master/src/fcl/collision_data.py",
    CCD + "continuous_collision-inl.h",  # CONTINUOUS
    CCD + "continuous_collision_request.h",
    CCD + "detail/conservative_advancement_func_matrix-inl.h",
    CCD + "detail/traversal/distance/shape_conservative_advancement_traversal_node-inl.h",
)
T_ERR = 1e-4
"""``ShapeConservativeAdvancementTraversalNode::t_err``: the last step (normalised time)."""
NAIVE_SAMPLES = 10
"""``min(num_max_iterations = 10, ceil(1 / toc_err = 1e-4))``: the naive solver's tests."""
CONTINUOUS = CCD + "continuous_collision-inl.h"
"""``continuousCollide``: which solver runs for which pair of objects, and its -1."""
UNSUPPORTED = {
    "ray shooting": (
        "FCL 0.7.0's continuousCollide does not compute CCDC_RAY_SHOOTING for two geometries "
        "(its branch for a pair of OT_GEOM objects is empty): it returns -1, 'not computed', "
        "and leaves the result at no collision, so no sphere pair can be asked [" + CONTINUOUS
        + "]"),
    "polynomial": (
        "FCL 0.7.0's continuousCollide runs CCDC_POLYNOMIAL_SOLVER for two BVH meshes only "
        "(OT_BVH); for two spheres it prints 'Warning! Invalid continuous collision checking' "
        "and returns -1, 'not computed', so no sphere pair can be asked [" + CONTINUOUS
        + "]"),
}
"""Why the variants of the solvers FCL does not compute for spheres skip every case."""
CENTRE_LINE = "float64-centre-line"
"""The no-value rule the FCL adapters declare for a time of impact's normal (computed here
from the centres at the reported time, none where they coincide)."""
SOLVERS = {"conservative advancement": "CCDC_CONSERVATIVE_ADVANCEMENT",
           "naive": "CCDC_NAIVE", "ray shooting": "CCDC_RAY_SHOOTING",
           "polynomial": "CCDC_POLYNOMIAL_SOLVER"}
"""The solvers by the name the variants use, and their ``CCDSolverType`` member."""
