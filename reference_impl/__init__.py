"""Reference implementations of the textbook AABB and sphere collision formulas.

Two renderings of the same textbook (Freya.no, AABB vs AABB and sphere-sphere
detection and response):

* :mod:`reference_impl.formulas` -- the formulas as written, evaluated in
  float64 or float32, rounding and all;
* :mod:`reference_impl.exact` -- the exact oracle: verdicts and responses in
  rational arithmetic, distances and normals correctly rounded to float64.

Both return the value types of :mod:`reference_impl.types`.  This package
depends only on the standard library and numpy.  ``formulas`` (numpy) is imported
by name (``from reference_impl import formulas``), not here: the value types load
without numpy, so ``crosscheck --help`` never imports it.
"""

from . import exact
from .types import Contact, Response, Undefined, Vec

__all__ = ["Contact", "Response", "Undefined", "Vec", "exact"]
