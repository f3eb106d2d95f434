"""numpy-spheres: a Collision Crosscheck plug-in engine, spheres by numpy (calls in .calls).

Conventions (sources: the numpy page cited below): the distance is norm(b - a) - ra - rb in
float64, touching spheres do not collide, the normal points from A's centre to B's; a scene
is stepped by semi-implicit Euler with the textbook impulse at each overlap; no walls.
"""

from typing import ClassVar

import numpy as np

from adapters.stepping import SceneCallsAdapter, scene_inputs
from crosscheck.core.contract import Call, Capability, Conventions, all_capabilities
from crosscheck.core.model import Kind
from crosscheck.core.schema import AnyCase, SceneCase, SphereCase


class NumpySpheres(SceneCallsAdapter):
    """Spheres (discs in 2-D) by numpy: detection, and scenes without walls."""

    name: ClassVar[str] = "numpy-spheres"
    engine: ClassVar[str] = "numpy"
    calls: ClassVar[str] = "crosscheck_numpy_spheres.calls"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE,
                                                                     Kind.SPHERE_SCENE)
    conventions: ClassVar[Conventions] = Conventions(rtol=2.0**-50, sources=(
        "https://numpy.org/doc/stable/reference/generated/numpy.linalg.norm.html",))

    def version(self) -> str:
        return str(np.__version__)

    def unsupported(self, case: AnyCase) -> str | None:
        if isinstance(case, SceneCase) and case.walls:
            return "numpy-spheres has no walls"
        return super().unsupported(case)

    def pair_call(self, case: SphereCase) -> Call:
        return Call("pair", "detect", {"a_center": tuple(case.a.center), "a_radius":
                                       case.a.radius, "b_center": tuple(case.b.center),
                                       "b_radius": case.b.radius})

    def scene_call(self, case: SceneCase) -> Call:
        return Call("scene", "step_scene", scene_inputs(case))
