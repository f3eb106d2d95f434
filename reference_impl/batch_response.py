"""Correctly rounded elastic sphere responses for N pairs, vectorised in double-double.

The values equal ``float(x)`` of each exact velocity of
:func:`reference_impl.exact.sphere_response` (round to nearest, ties to even; an exact
zero is ``+0.0``).  With ``d = pa - pb``, ``w = vb - va``, ``M = ma + mb`` and
``T = (1 + e) (d.w) / (M d.d)``, the velocities are ``v1' = va + mb T d`` and
``v2' = vb - ma T d``.

Stage 1 evaluates them in double-double (:mod:`reference_impl.ddouble`) for the pairs in
range, with ``B = |1+e| sum|d_i w_i| / |M d.d| >= |T|`` (an absolute value: ``M`` may be
negative):

* ``d``, ``w``, ``1 + e`` and ``M`` exactly (TwoSum); ``d.d`` within ``2**-73.9``
  relative (see :mod:`reference_impl.batch_values`); ``d.w`` within ``2**-72 sum|d_i w_i|``
  absolute (a product split as in :func:`~reference_impl.ddouble.mul` per axis, the
  float sum of the small parts; it may cancel, hence an absolute bound);
* ``T`` by :func:`~reference_impl.ddouble.mul` and :func:`~reference_impl.ddouble.div`
  (``2**-75``, ``2**-74`` each) within ``2**-71 B``; each kick ``mb T d_i`` within
  ``2**-70.5 |mb d_i| B``;
* ``v1'_i = va_i + kick`` by TwoSum, rounded by :func:`~reference_impl.ddouble.ziv` with
  ``err = max(2**-69 |mb d_i| B, 2**-50 |lo|)``: twice the bound, and large enough to
  cover the rounding of ``lo`` (the TwoSum error plus the kick's low part) and the
  test's own roundings.  A zero is certified only when ``err == 0``: then the kick is
  exactly zero and the value is ``va_i`` (``+ 0.0`` gives the oracle's ``+0.0``).

In range: finite inputs; every non-zero component of ``pa, pb, va, vb, d, w``, and
``ma, mb, e, 1 + e, M`` in ``[2**-120, 2**120]``; ``M != 0`` and ``d != 0``.  No product
of the at most seven factors then overflows, and its rounding errors stay far above the
underflow threshold.  Every other pair, and every value the test cannot certify, goes to
the pure oracle.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from . import exact
from .ddouble import div, mul, norm2, split, ziv
from .expansion import two_sum
from .types import Response

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.intp]

_LIMIT = 2.0**120


@dataclass
class ResponseValues:
    """Per pair: ``v1``, ``v2`` (shape ``(N, dim)``; NaN rows where undefined) and the stages.

    ``undefined`` rows have no value (non-finite input, coincident centres or zero total
    mass); ``exact_rows`` lists the pairs the pure oracle settled; ``stages`` counts the
    pairs settled by ``double_double`` and by ``exact``.
    """

    v1: FloatArray
    v2: FloatArray
    undefined: BoolArray
    exact_rows: IntArray
    stages: dict[str, int] = field(default_factory=dict)


def response_values(pa: npt.ArrayLike, ma: npt.ArrayLike, va: npt.ArrayLike,
                    pb: npt.ArrayLike, mb: npt.ArrayLike, vb: npt.ArrayLike,
                    e: npt.ArrayLike) -> ResponseValues:
    """Correctly rounded velocities after the textbook response, for N pairs.

    >>> r = response_values([[0.0, 0.0]], [1.0], [[1.0, 0.0]], [[1.0, 0.0]], [1.0],
    ...                     [[0.0, 0.0]], [1.0])
    >>> r.v1.tolist(), r.v2.tolist(), r.stages
    ([[0.0, 0.0]], [[1.0, 0.0]], {'double_double': 0, 'exact': 1})
    """
    x = [np.ascontiguousarray(v, dtype=np.float64) for v in (pa, ma, va, pb, mb, vb, e)]
    with np.errstate(all="ignore"):
        v1, v2, ok = _stage_one(*x)
    out = ResponseValues(v1.T.copy(), v2.T.copy(), np.zeros(len(ok), bool),
                         np.flatnonzero(~ok))
    _exact(x, out)
    out.stages = {"double_double": int(ok.sum()), "exact": len(out.exact_rows)}
    return out


def _rows(v: FloatArray) -> FloatArray:
    return np.ascontiguousarray(v.T)


def _in_range(*values: FloatArray) -> BoolArray:
    """Pairs whose every value is zero or in ``[2**-120, 2**120]`` in magnitude (NaN: no)."""
    ok = np.ones(values[0].shape[-1], dtype=bool)
    for v in values:
        m = np.abs(v)
        good = (m == 0) | ((m >= 1 / _LIMIT) & (m <= _LIMIT))
        ok &= good if good.ndim == 1 else good.all(axis=0)
    return ok


def _stage_one(pa: FloatArray, ma: FloatArray, va: FloatArray, pb: FloatArray,
               mb: FloatArray, vb: FloatArray,
               e: FloatArray) -> tuple[FloatArray, FloatArray, BoolArray]:
    """Both velocities (rows are axes) and which pairs are certain (module docstring)."""
    a, b, u1, u2 = _rows(pa), _rows(pb), _rows(va), _rows(vb)
    dh, dl = two_sum(a, -b)
    wh, wl = two_sum(u2, -u1)
    eh, el = two_sum(np.ones_like(e), e)
    mh, ml = two_sum(ma, mb)
    ok = (_in_range(a, b, u1, u2, dh, wh, ma, mb, e, eh, mh) & (mh != 0)
          & dh.any(axis=0))
    dot, dot_mag = _dot(dh, dl, wh, wl)
    den = mul(mh, ml, *norm2(dh, dl))
    t = div(*mul(*dot, eh, el), *den)
    bound = np.abs(eh) * dot_mag / np.abs(den[0])
    v1, ok1 = _kick(u1, mb, t, dh, dl, bound)
    v2, ok2 = _kick(u2, -ma, t, dh, dl, bound)
    return v1, v2, ok & ok1 & ok2


def _dot(dh: FloatArray, dl: FloatArray, wh: FloatArray,
         wl: FloatArray) -> tuple[tuple[FloatArray, FloatArray], FloatArray]:
    """``d.w`` renormalised (within ``2**-72 sum|d_i w_i|``) and ``sum|d_i w_i|``."""
    hi = np.zeros(dh.shape[1])
    lo = np.zeros(dh.shape[1])
    mag = np.zeros(dh.shape[1])
    for j in range(dh.shape[0]):
        p = dh[j] * wh[j]
        xh, xl = split(dh[j])
        yh, yl = split(wh[j])
        small = xh * yh - p
        small += xh * yl
        small += xl * wh[j]
        small += dh[j] * wl[j] + dl[j] * wh[j]
        hi, err = two_sum(hi, p)
        lo += small + err
        mag += np.abs(p)
    return two_sum(hi, lo), mag


def _kick(v: FloatArray, m: FloatArray, t: tuple[FloatArray, FloatArray], dh: FloatArray,
          dl: FloatArray, bound: FloatArray) -> tuple[FloatArray, BoolArray]:
    """``v + m T d`` per axis, rounded, and whether every axis is certain."""
    mt = mul(*t, m, np.zeros_like(m))
    out = np.empty_like(v)
    ok = np.ones(v.shape[1], dtype=bool)
    for j in range(v.shape[0]):
        kh, kl = mul(*mt, dh[j], dl[j])
        hi, lo = two_sum(v[j], kh)
        lo += kl
        err = np.maximum(2.0**-69 * np.abs(m * dh[j]) * bound, 2.0**-50 * np.abs(lo))
        value, sure = ziv(hi, lo, err)
        out[j] = value + 0.0
        ok &= sure & ((value != 0) | (err == 0)) & np.isfinite(value)
    return out, ok


def _exact(x: list[FloatArray], out: ResponseValues) -> None:
    """The pure oracle for the pairs stage 1 left."""
    pa, ma, va, pb, mb, vb, e = x
    for i in out.exact_rows.tolist():
        r = exact.sphere_response(pa[i].tolist(), float(ma[i]), va[i].tolist(), pb[i].tolist(),
                                  float(mb[i]), vb[i].tolist(), float(e[i]))
        if isinstance(r, Response):
            out.v1[i] = [float(c) for c in r.v1]
            out.v2[i] = [float(c) for c in r.v2]
        else:
            out.v1[i] = out.v2[i] = np.nan
            out.undefined[i] = True
