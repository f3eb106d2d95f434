"""Adapters for the textbook formula itself: ``reference`` (float64) and ``reference-f32``.

The calls (``reference_impl.formulas`` on plain inputs) are :mod:`adapters.reference.calls`.

They are scored against the exact oracle like any engine, so the report shows
where the textbook formula in floating point disagrees with exact truth: near
touching, at large offsets and, for float32 (the textbook's ``float``), almost
everywhere a size is not a power of two.

Conventions (sources: the two textbook blog posts of :data:`TEXTBOOK` and
:mod:`reference_impl.formulas`): half-widths; normal from A to B; AABB
touching overlaps, spheres touching do not collide; no margin; the relative
tolerance is the rounding of a handful of operations in the declared precision.
For a time of impact (``sphere_toi``) they are the discrete baseline: the textbook's
sphere test at the interval's start and end only, as a simulation stepping over the
interval sees the pair (``toi_samples`` 2; :func:`crosscheck.truth.oracle.sampled_impact`).
The formula has no time step or damping (``time_step`` None, ``damping`` 0), takes a
zero mass as the number 0 (``zero_mass`` "") and a negative radius or half-width as the
number it is (``negative_extents`` "": the textbook's literal reading, which is the
oracle's).  The textbook defines no normal for coincident centres or a tie of box axes
(and no response for coincident centres) [reference_impl.formulas]; each variant declares
that rule on its own float numbers (``no_value`` "float64-textbook" or
"float32-textbook"): where rounding makes centres coincide or axes tie that the exact case
keeps apart, the engine gives no value by its rule, a ``convention``.
"""

from __future__ import annotations

from dataclasses import replace
from typing import ClassVar

import crosscheck
from crosscheck.core.contract import (
    Call,
    CallsAdapter,
    Capability,
    Conventions,
    all_capabilities,
    pair_inputs,
)
from crosscheck.core.model import Kind
from crosscheck.core.schema import AabbCase, ResponseCase, SphereCase, ToiCase
from reference_impl.formulas import Precision

TEXTBOOK = (
    "http://wp.freya.no/3d-math-and-physics/simple-aabb-vs-aabb-collision-detection/",
    "http://wp.freya.no/3d-math-and-physics/"
    "simple-sphere-sphere-collision-detection-and-collision-response/",
)
"""The textbook: the blog posts that give the AABB and the sphere formulas, at their public
addresses (the sources of both reference variants' conventions)."""


class ReferenceF64(CallsAdapter):
    """The textbook formula in float64."""

    name: ClassVar[str] = "reference"
    light_import = True  # the engine is imported lazily (available(), prepare)
    engine: ClassVar[str] = "reference_impl"
    settings: ClassVar[str] = "textbook formula, float64"
    precision: ClassVar[Precision] = "f64"
    calls: ClassVar[str] = "adapters.reference.calls"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(
        Kind.AABB, Kind.SPHERE, Kind.SPHERE_RESPONSE, Kind.SPHERE_TOI)
    conventions: ClassVar[Conventions] = Conventions(
        rtol=2.0**-50,
        restitution="case value (textbook generalised with e)",
        time_step=None,
        damping=0.0,
        zero_mass="",
        negative_extents="",
        no_value=("float64-textbook",),
        toi_samples=2,
        notes="Faithful textbook code; float64 throughout; no normal (nor response) where the "
              "computed centres coincide or the box axes tie. A time of impact is the discrete "
              "test sampled at the interval's two ends (toi_samples 2).",
        sources=TEXTBOOK,
    )

    def version(self) -> str:
        return crosscheck.__version__

    def pair_call(self, case: AabbCase | SphereCase) -> Call:
        ask = "aabb" if isinstance(case, AabbCase) else "sphere"
        return Call("given", ask, {**pair_inputs(case), "precision": self.precision})

    def response_call(self, case: ResponseCase) -> Call:
        a, b = case.a, case.b
        return Call("given", "response", {
            "a_center": a.center, "a_mass": a.mass, "a_velocity": a.velocity,
            "b_center": b.center, "b_mass": b.mass, "b_velocity": b.velocity,
            "restitution": case.restitution, "precision": self.precision})

    def toi_call(self, case: ToiCase) -> Call:
        a, b = case.a, case.b
        return Call("given", "sampled_impact", {
            "a_center": a.center, "a_radius": a.radius, "a_velocity": a.velocity,
            "b_center": b.center, "b_radius": b.radius, "b_velocity": b.velocity,
            "duration": case.duration, "precision": self.precision})


class ReferenceF32(ReferenceF64):
    """The textbook formula in float32, as the textbook's ``float`` declares."""

    name: ClassVar[str] = "reference-f32"
    settings: ClassVar[str] = "textbook formula, float32 (inputs rounded to float32)"
    precision: ClassVar[Precision] = "f32"
    conventions: ClassVar[Conventions] = replace(
        ReferenceF64.conventions,
        rtol=2.0**-21,
        no_value=("float32-textbook",),
        notes="Inputs rounded to float32, every operation in float32; no normal (nor "
              "response) where the rounded centres coincide or the box axes tie. A time of "
              "impact is the discrete test sampled at the interval's two ends.",
    )
