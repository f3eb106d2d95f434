"""numpy-spheres: a Collision Crosscheck plug-in engine, sphere detection by numpy.

Conventions (sources: the numpy page cited below): the distance is norm(b - a) - ra - rb
in float64; touching spheres do not collide; the normal points from A's centre to B's.
"""

from typing import Any, ClassVar

import numpy as np

from crosscheck.core.contract import Adapter, Capability, Conventions, all_capabilities
from crosscheck.core.model import Kind, Observation, Undefined
from crosscheck.core.schema import AnyCase, SphereCase


class NumpySpheres(Adapter):
    """Spheres (discs in 2-D) by numpy: verdict, signed distance and normal."""

    name: ClassVar[str] = "numpy-spheres"
    engine: ClassVar[str] = "numpy"
    capabilities: ClassVar[frozenset[Capability]] = all_capabilities(Kind.SPHERE)
    conventions: ClassVar[Conventions] = Conventions(rtol=2.0**-50, sources=(
        "https://numpy.org/doc/stable/reference/generated/numpy.linalg.norm.html",))

    def version(self) -> str:
        return str(np.__version__)

    def prepare(self, case: AnyCase) -> Any:
        assert isinstance(case, SphereCase)
        return np.array(case.b.center) - np.array(case.a.center), case.a.radius + case.b.radius

    def query(self, prepared: Any) -> Observation:
        offset, radii = prepared
        length = float(np.linalg.norm(offset))
        normal = tuple(float(x) for x in offset / length) if length else Undefined("coincident")
        return Observation(hit=length < radii, distance=length - radii, normal=normal)
