"""Property tests of the exact oracle (reference_impl.exact), in 2-D and 3-D.

Floats are drawn over wide magnitudes (2**-120 .. 2**113) and configurations
are biased towards touching: B's centre is A's plus the radius / half-width
sum nudged by a few ulps.  The range keeps every non-zero exact distance far
above the subnormal range, so a correctly rounded distance keeps its sign.
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext
from fractions import Fraction
from typing import Any

from hypothesis import assume, given, settings
from hypothesis import strategies as st

from reference_impl import exact
from reference_impl.rounding import quotient, sqrt_minus, sqrt_rounded
from reference_impl.types import Contact, Response, Undefined

Vec = tuple[float, ...]
oracle = settings(deadline=None, max_examples=150)

wide = st.builds(math.ldexp, st.integers(-(2**53), 2**53), st.integers(-120, 60))
sizes = st.builds(math.ldexp, st.integers(1, 2**53), st.integers(-120, 60)) | st.sampled_from(
    [0.0, 0.5, 1.0]
)
restitution = st.floats(0, 1) | st.sampled_from([0.0, 0.5, 1.0])


def nudge(x: float, ulps: int) -> float:
    for _ in range(abs(ulps)):
        x = math.nextafter(x, math.inf if ulps > 0 else -math.inf)
    return x


@st.composite
def vectors(draw: st.DrawFn, n: int, elements: st.SearchStrategy[float] = wide) -> Vec:
    return tuple(draw(elements) for _ in range(n))


@st.composite
def sphere_pairs(draw: st.DrawFn) -> tuple[Vec, float, Vec, float]:
    """(pa, ra, pb, rb), half of them within a few ulps of touching."""
    n = draw(st.sampled_from([2, 3]))
    pa, ra, rb = draw(vectors(n)), draw(sizes), draw(sizes)
    if draw(st.booleans()):
        return pa, ra, draw(vectors(n)), rb
    reach = nudge(ra + rb, draw(st.integers(-3, 3)))
    axis, sign = draw(st.integers(0, n - 1)), draw(st.sampled_from([1, -1]))
    if draw(st.booleans()):  # along an axis
        offset = [0.0] * n
        offset[axis] = sign * reach
    else:  # a 3-4-5 direction
        offset = [0.0] * n
        offset[axis], offset[(axis + 1) % n] = sign * 0.6 * reach, 0.8 * reach
    return pa, ra, tuple(p + o for p, o in zip(pa, offset, strict=True)), rb


@st.composite
def box_pairs(draw: st.DrawFn) -> tuple[Vec, Vec, Vec, Vec]:
    """(ca, ha, cb, hb), with some axes within a few ulps of touching."""
    n = draw(st.sampled_from([2, 3]))
    ca, ha, hb = draw(vectors(n)), draw(vectors(n, sizes)), draw(vectors(n, sizes))
    cb = list(draw(vectors(n)))
    for i in range(n):
        if draw(st.booleans()):
            reach = nudge(ha[i] + hb[i], draw(st.integers(-3, 3)))
            cb[i] = ca[i] + draw(st.sampled_from([1, -1])) * reach
        elif draw(st.booleans()):
            cb[i] = ca[i] + draw(st.sampled_from([-1.0, 1.0])) * draw(sizes)
    return ca, ha, tuple(cb), hb


@st.composite
def bodies(draw: st.DrawFn) -> tuple[Any, ...]:
    """(pa, ma, va, pb, mb, vb) for sphere_response, positive masses."""
    n = draw(st.sampled_from([2, 3]))
    pa, pb = draw(vectors(n)), draw(vectors(n))
    assume(pa != pb)
    return (
        pa,
        draw(sizes.filter(bool)),
        draw(vectors(n)),
        pb,
        draw(sizes.filter(bool)),
        draw(vectors(n)),
    )


def q(v: Vec) -> tuple[Fraction, ...]:
    return tuple(Fraction(x) for x in v)


def dot(a: tuple[Fraction, ...], b: tuple[Fraction, ...]) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), Fraction(0))


def response(*args: Any) -> Response[Fraction]:
    r = exact.sphere_response(*args)
    assert isinstance(r, Response)
    return r


def contact(r: Contact | Undefined) -> Contact:
    assert isinstance(r, Contact)
    return r


def negated(n: Vec | Undefined) -> Vec | Undefined:
    return n if isinstance(n, Undefined) else tuple(-x for x in n)


def dec(x: Fraction) -> Decimal:
    return Decimal(x.numerator) / Decimal(x.denominator)


# ---------------------------------------------------------------- conservation laws


@oracle
@given(bodies(), restitution)
def test_momentum_is_conserved_exactly(args: tuple[Any, ...], e: float) -> None:
    _, ma, va, _, mb, vb = args
    r = response(*args, e)
    m1, m2 = Fraction(ma), Fraction(mb)
    before = [m1 * a + m2 * b for a, b in zip(q(va), q(vb), strict=True)]
    assert [m1 * a + m2 * b for a, b in zip(r.v1, r.v2, strict=True)] == before


@oracle
@given(bodies())
def test_kinetic_energy_is_conserved_exactly_when_elastic(args: tuple[Any, ...]) -> None:
    _, ma, va, _, mb, vb = args
    r = response(*args)
    m1, m2 = Fraction(ma), Fraction(mb)
    before = m1 * dot(q(va), q(va)) + m2 * dot(q(vb), q(vb))
    assert m1 * dot(r.v1, r.v1) + m2 * dot(r.v2, r.v2) == before


@oracle
@given(bodies(), restitution)
def test_response_is_the_generalised_textbook_formula(args: tuple[Any, ...], e: float) -> None:
    pa, ma, va, pb, mb, vb = args
    r = response(*args, e)
    m1, m2, ee, v1, v2 = Fraction(ma), Fraction(mb), Fraction(e), q(va), q(vb)
    x = tuple(a - b for a, b in zip(q(pa), q(pb), strict=True))  # unnormalised: proj only

    def proj(v: tuple[Fraction, ...]) -> tuple[Fraction, ...]:
        return tuple(c * dot(x, v) / dot(x, x) for c in x)

    v1x, v2x, m = proj(v1), proj(v2), m1 + m2
    v1y = tuple(a - b for a, b in zip(v1, v1x, strict=True))
    v2y = tuple(a - b for a, b in zip(v2, v2x, strict=True))
    new1 = [
        a * (m1 - ee * m2) / m + b * ((1 + ee) * m2) / m + c
        for a, b, c in zip(v1x, v2x, v1y, strict=True)
    ]
    new2 = [
        a * ((1 + ee) * m1) / m + b * (m2 - ee * m1) / m + c
        for a, b, c in zip(v1x, v2x, v2y, strict=True)
    ]
    assert list(r.v1) == new1 and list(r.v2) == new2


# ---------------------------------------------------------------- mirror symmetry


@oracle
@given(bodies(), restitution)
def test_swapping_bodies_swaps_the_response(args: tuple[Any, ...], e: float) -> None:
    pa, ma, va, pb, mb, vb = args
    r, s = response(*args, e), response(pb, mb, vb, pa, ma, va, e)
    assert (r.v1, r.v2) == (s.v2, s.v1)


@oracle
@given(sphere_pairs())
def test_swapping_spheres_mirrors_the_contact(args: tuple[Any, ...]) -> None:
    pa, ra, pb, rb = args
    ab, ba = (
        contact(exact.sphere_contact(pa, ra, pb, rb)),
        contact(exact.sphere_contact(pb, rb, pa, ra)),
    )
    assert (ab.hit, ab.distance, ab.normal) == (ba.hit, ba.distance, negated(ba.normal))


@oracle
@given(box_pairs())
def test_swapping_boxes_mirrors_the_contact(args: tuple[Any, ...]) -> None:
    ca, ha, cb, hb = args
    ab, ba = (
        contact(exact.aabb_contact(ca, ha, cb, hb)),
        contact(exact.aabb_contact(cb, hb, ca, ha)),
    )
    assert (ab.hit, ab.distance, ab.normal) == (ba.hit, ba.distance, negated(ba.normal))


# ---------------------------------------------------------------- verdict agrees with distance


@oracle
@given(box_pairs())
def test_box_verdict_agrees_with_signed_distance(args: tuple[Any, ...]) -> None:
    c = contact(exact.aabb_contact(*args))
    assert c.hit == (c.distance <= 0)


@oracle
@given(sphere_pairs())
def test_sphere_verdict_agrees_with_signed_distance(args: tuple[Any, ...]) -> None:
    pa, ra, pb, rb = args
    c = contact(exact.sphere_contact(*args))
    assert c.hit == (c.distance < 0)
    d = tuple(b - a for a, b in zip(q(pa), q(pb), strict=True))
    r = Fraction(ra) + Fraction(rb)
    assert (c.distance == 0) == (r >= 0 and dot(d, d) == r * r)


# ---------------------------------------------------------------- correct rounding


def assert_unit(n: Vec) -> None:
    assert abs(math.fsum(x * x for x in n) - 1) <= 4 * 2.0**-52


@oracle
@given(sphere_pairs())
def test_sphere_distance_and_normal_are_correctly_rounded(args: tuple[Any, ...]) -> None:
    pa, ra, pb, rb = args
    c = contact(exact.sphere_contact(*args))
    d = tuple(b - a for a, b in zip(q(pa), q(pb), strict=True))
    assume(any(d))
    with localcontext() as ctx:
        ctx.prec = 400  # near-touching cancels at most ~150 of these digits
        root = dec(dot(d, d)).sqrt()
        assert c.distance == float(root - dec(Fraction(ra) + Fraction(rb)))
        ctx.prec = 100
        assert c.normal == tuple(float(dec(x) / root) for x in d)
    assert isinstance(c.normal, tuple)
    assert_unit(c.normal)


@oracle
@given(box_pairs())
def test_box_distance_and_normal_are_correctly_rounded(args: tuple[Any, ...]) -> None:
    ca, ha, cb, hb = args
    c = contact(exact.aabb_contact(*args))
    dc = [b - a for a, b in zip(q(ca), q(cb), strict=True)]
    s = [Fraction(a) + Fraction(b) for a, b in zip(ha, hb, strict=True)]
    if c.hit:
        assert c.distance == float(-min(x - abs(y) for x, y in zip(s, dc, strict=True)))
        return
    gaps = [max(abs(y) - x, Fraction(0)) * (1 if y > 0 else -1) for x, y in zip(s, dc, strict=True)]
    with localcontext() as ctx:
        ctx.prec = 100
        root = dec(sum((g * g for g in gaps), Fraction(0))).sqrt()
        assert c.distance == float(root)
        assert c.normal == tuple(float(dec(g) / root) for g in gaps)
    assert isinstance(c.normal, tuple)
    assert_unit(c.normal)


positive = st.floats(min_value=0, allow_infinity=False, allow_subnormal=True)


@oracle
@given(positive)
def test_sqrt_rounded_matches_ieee_sqrt(x: float) -> None:
    assert sqrt_rounded(Fraction(x)) == math.sqrt(x)


@oracle
@given(st.floats(allow_nan=False, allow_infinity=False), positive.filter(lambda y: 0 < y < 1e154))
def test_quotient_matches_ieee_division(x: float, y: float) -> None:
    assume(math.isfinite(x / y))
    assert quotient(Fraction(x), Fraction(y) ** 2) == x / y


@oracle
@given(wide, wide)
def test_sqrt_minus_of_a_square_is_exact_subtraction(x: float, r: float) -> None:
    # sqrt(x*x) - r == |x| - r exactly, so the result is the correctly rounded |x| - r.
    assert sqrt_minus(Fraction(x) ** 2, Fraction(r)) == float(abs(Fraction(x)) - Fraction(r))


# ---------------------------------------------------------------- negative radii


def test_negative_radius_sum_never_collides() -> None:
    c = contact(exact.sphere_contact((0.0, 0.0), -1.0, (0.5, 0.0), 0.25))
    assert c == Contact(False, 1.25, (1.0, 0.0))
    same = contact(exact.sphere_contact((0.0, 0.0), -1.0, (0.0, 0.0), 0.25))
    assert same == Contact(False, 0.75, Undefined("coincident centres"))
