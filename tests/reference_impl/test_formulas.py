"""Unit tests of the faithful float formulas (reference_impl.formulas), f64 and f32."""

from __future__ import annotations

import doctest
import math
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import reference_impl
from reference_impl import exact, formulas, rounding, types
from reference_impl.types import Contact, Response, Undefined

PRECISIONS = ["f64", "f32"]

# Known float-vs-exact disagreements (see the module docstrings).
BOXES = ((0.0, 0.0, 0.0), (0.8, 1.0, 1.0), (1.2000000000000002, 0.0, 0.0), (0.4, 1.0, 1.0))
SPHERES = ((0.75, 0.0), 0.6, (2.05, 0.0), 0.7)


def bits(values: Sequence[float]) -> list[str]:
    return [float(v).hex() for v in values]


# ---------------------------------------------------------------- doctests


@pytest.mark.parametrize("module", [reference_impl, types, rounding, exact, formulas])
def test_doctests(module: Any) -> None:
    result = doctest.testmod(module)
    assert result.failed == 0


def test_doctests_exist() -> None:
    for module in (rounding, exact, formulas):
        assert doctest.testmod(module).attempted > 0


# ---------------------------------------------------------------- known examples


def test_boxes_float64_hit_but_exactly_apart() -> None:
    assert abs(0.0 - 1.2000000000000002) == 0.8 + 0.4  # the float sum rounds up to it
    assert formulas.aabb_contact(*BOXES).hit is True
    oracle = exact.aabb_contact(*BOXES)
    assert isinstance(oracle, Contact)
    assert oracle.hit is False and oracle.distance > 0


def test_spheres_float64_miss_but_exactly_overlap() -> None:
    assert abs(0.75 - 2.05) == 0.6 + 0.7  # both round to 1.2999999999999998
    assert formulas.sphere_contact(*SPHERES).hit is False
    oracle = exact.sphere_contact(*SPHERES)
    assert isinstance(oracle, Contact)
    assert oracle.hit is True and oracle.distance < 0


# ---------------------------------------------------------------- touching rules


@pytest.mark.parametrize("precision", PRECISIONS)
def test_touching_boxes_hit(precision: formulas.Precision) -> None:
    c = formulas.aabb_contact((0, 0, 0), (1, 1, 1), (2, 0.5, 0), (1, 1, 1), precision=precision)
    assert c == Contact(True, 0.0, (1.0, 0.0, 0.0))
    assert math.copysign(1.0, c.distance) == 1.0
    apart = formulas.aabb_contact((0, 0), (1, 1), (1.5, -2.5), (1, 1), precision=precision)
    assert apart == Contact(False, 0.5, (0.0, -1.0))


@pytest.mark.parametrize("precision", PRECISIONS)
def test_touching_spheres_do_not_collide(precision: formulas.Precision) -> None:
    c = formulas.sphere_contact((0, 0), 1.0, (0, 2), 1.0, precision=precision)
    assert c == Contact(False, 0.0, (0.0, 1.0))
    inside = formulas.sphere_contact((0, 0, 0), 1.0, (0, 0, -1.5), 1.0, precision=precision)
    assert inside == Contact(True, -0.5, (0.0, 0.0, -1.0))


def test_oracle_touching_rules() -> None:
    assert exact.aabb_contact((0, 0), (1, 1), (2, 0), (1, 1)) == Contact(True, 0.0, (1.0, 0.0))
    assert exact.sphere_contact((0, 0), 1, (2, 0), 1) == Contact(False, 0.0, (1.0, 0.0))


# ---------------------------------------------------------------- undefined outcomes


@pytest.mark.parametrize("precision", PRECISIONS)
def test_undefined_outcomes(precision: formulas.Precision) -> None:
    coincident = Undefined("coincident centres")
    s = formulas.sphere_contact((1, 2, 3), 1, (1, 2, 3), 1, precision=precision)
    assert s == Contact(True, -2.0, coincident)
    r = formulas.sphere_response((1, 2), 1, (1, 0), (1, 2), 1, (0, 0), precision=precision)
    assert r == coincident
    for ma, mb in [(1.0, -1.0), (0.0, 0.0), (-0.0, 0.0)]:
        r = formulas.sphere_response((0, 0), ma, (1, 0), (1, 0), mb, (0, 0), precision=precision)
        assert r == Undefined("zero total mass")
    tie = formulas.aabb_contact((0, 0), (1, 1), (1, -1), (1, 1), precision=precision)
    assert tie.normal == Undefined("tie between axes x and y")
    tie3 = formulas.aabb_contact((0, 0, 0), (1, 1, 1), (1, 1, 1), (1, 1, 1), precision=precision)
    assert tie3.normal == Undefined("tie between axes x, y and z")
    on_axis = formulas.aabb_contact((0, 0), (1, 1), (0, 0.5), (1, 2), precision=precision)
    assert on_axis == Contact(True, -2.0, Undefined("coincident centres on axis x"))


def test_oracle_undefined_outcomes() -> None:
    assert exact.sphere_response((0, 0), 1, (1, 0), (0, 0), 1, (0, 0)) == Undefined(
        "coincident centres"
    )
    assert exact.sphere_response((0, 0), 2, (1, 0), (1, 0), -2, (0, 0)) == Undefined(
        "zero total mass"
    )
    tie = exact.aabb_contact((0, 0), (1, 1), (1, -1), (1, 1))
    assert isinstance(tie, Contact) and tie.normal == Undefined("tie between axes x and y")
    assert exact.sphere_contact((0, math.nan), 1, (0, 0), 1) == Undefined("non-finite input: pa[1]")
    assert exact.sphere_response((0, 0), 1, (0, 0), (1, 0), 1, (0, 0), e=math.inf) == Undefined(
        "non-finite input: e"
    )
    assert exact.aabb_contact((0, 0), (1, 1), (0, 0), (1, -math.inf)) == Undefined(
        "non-finite input: hb[1]"
    )


def test_bad_arguments() -> None:
    with pytest.raises(ValueError):
        formulas.sphere_contact((0, 0), 1, (1, 0, 0), 1)
    with pytest.raises(ValueError):
        exact.aabb_contact((0,), (1,), (0,), (1,))
    with pytest.raises(ValueError):
        formulas.sphere_contact((0, 0), 1, (1, 0), 1, precision="f16")  # type: ignore[arg-type]


@pytest.mark.parametrize("precision", PRECISIONS)
def test_non_finite_inputs_give_ieee_results_without_warnings(
    precision: formulas.Precision,
) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = formulas.sphere_contact((math.nan, 0), 1, (1, 0), 1, precision=precision)
        assert s.hit is False and math.isnan(s.distance)
        b = formulas.aabb_contact((0, 0), (1, math.inf), (math.inf, 0), (1, 1), precision=precision)
        assert b.hit is False and b.distance == math.inf
        r = formulas.sphere_response(
            (0, 0), 1, (1, 0), (1e-30, 0), math.inf, (0, 0), precision=precision
        )
        assert isinstance(r, Response) and all(math.isnan(x) for x in r.v1)


# ---------------------------------------------------------------- the textbook, literally


def textbook_response(
    p1: Sequence[float], m1: float, v1: Sequence[float],
    p2: Sequence[float], m2: float, v2: Sequence[float],
    *, cast: Callable[[float], Any],
) -> tuple[list[float], list[float]]:  # fmt: skip
    """The blog post's response, line by line, in the arithmetic of ``cast``."""
    sqrt = math.sqrt if cast is float else np.sqrt
    P1, V1, P2, V2 = ([cast(c) for c in v] for v in (p1, v1, p2, v2))
    m1, m2 = cast(m1), cast(m2)

    def dot(a: list[Any], b: list[Any]) -> Any:
        r = a[0] * b[0] + a[1] * b[1]
        return r + a[2] * b[2] if len(a) == 3 else r

    x = [a - b for a, b in zip(P1, P2, strict=True)]  # x = s1.pos - s2.pos
    length = sqrt(dot(x, x))
    x = [c / length for c in x]  # x.normalize()
    x1 = dot(x, V1)
    v1x = [c * x1 for c in x]
    v1y = [a - b for a, b in zip(V1, v1x, strict=True)]
    x = [c * -1 for c in x]
    x2 = dot(x, V2)
    v2x = [c * x2 for c in x]
    v2y = [a - b for a, b in zip(V2, v2x, strict=True)]
    s1 = [
        a * ((m1 - m2) / (m1 + m2)) + b * ((2 * m2) / (m1 + m2)) + c
        for a, b, c in zip(v1x, v2x, v1y, strict=True)
    ]
    s2 = [
        a * ((2 * m1) / (m1 + m2)) + b * ((m2 - m1) / (m1 + m2)) + c
        for a, b, c in zip(v1x, v2x, v2y, strict=True)
    ]
    return [float(c) for c in s1], [float(c) for c in s2]


moderate = st.builds(math.ldexp, st.integers(-(2**53), 2**53), st.integers(-80, 0))
masses = st.builds(math.ldexp, st.integers(1, 2**53), st.integers(-60, 0))


@st.composite
def response_inputs(draw: st.DrawFn) -> tuple[Any, ...]:
    n = draw(st.sampled_from([2, 3]))
    vec = st.lists(moderate, min_size=n, max_size=n).map(tuple)
    p1, v1, p2, v2 = draw(vec), draw(vec), draw(vec), draw(vec)
    assume(p1 != p2)
    return p1, draw(masses), v1, p2, draw(masses), v2


@settings(deadline=None)
@given(response_inputs())
def test_e1_is_the_textbook_bit_for_bit(args: tuple[Any, ...]) -> None:
    got = formulas.sphere_response(*args)
    assert isinstance(got, Response)
    s1, s2 = textbook_response(*args, cast=float)
    assert bits(got.v1) == bits(s1) and bits(got.v2) == bits(s2)
    with np.errstate(all="ignore"):
        s1, s2 = textbook_response(*args, cast=np.float32)
    got32 = formulas.sphere_response(*args, precision="f32")
    if not isinstance(got32, Undefined):  # distinct f64 centres may coincide in f32
        assert bits(got32.v1) == bits(s1) and bits(got32.v2) == bits(s2)


def assert_mirrored(ab: Contact, ba: Contact) -> None:
    assert ab.hit == ba.hit and bits([ab.distance]) == bits([ba.distance])
    if isinstance(ab.normal, Undefined):
        assert ab.normal == ba.normal
    else:
        assert isinstance(ba.normal, tuple) and ab.normal == tuple(-c for c in ba.normal)


@settings(deadline=None)
@given(response_inputs(), st.floats(0, 1), st.sampled_from(PRECISIONS))
def test_float_formulas_are_mirror_symmetric(
    args: tuple[Any, ...], e: float, precision: formulas.Precision
) -> None:
    p1, m1, v1, p2, m2, v2 = args
    fwd = formulas.sphere_response(p1, m1, v1, p2, m2, v2, e, precision=precision)
    back = formulas.sphere_response(p2, m2, v2, p1, m1, v1, e, precision=precision)
    if isinstance(fwd, Undefined):
        assert back == fwd
    else:
        assert isinstance(back, Response)
        assert bits(fwd.v1) == bits(back.v2) and bits(fwd.v2) == bits(back.v1)
    h1, h2 = tuple(abs(c) for c in v1), tuple(abs(c) for c in v2)
    ab = formulas.aabb_contact(p1, h1, p2, h2, precision=precision)
    assert_mirrored(ab, formulas.aabb_contact(p2, h2, p1, h1, precision=precision))
    ab = formulas.sphere_contact(p1, m1, p2, m2, precision=precision)
    assert_mirrored(ab, formulas.sphere_contact(p2, m2, p1, m1, precision=precision))


# ---------------------------------------------------------------- f32 versus f64


def test_f32_differs_from_f64_where_it_should() -> None:
    near = ((0.0, 0.0), 0.5, (1 - 1e-10, 0.0), 0.5)  # 1 - 1e-10 rounds to 1.0f
    assert formulas.sphere_contact(*near).hit is True
    assert formulas.sphere_contact(*near, precision="f32").hit is False
    boxes = ((0.0, 0.0), (0.5, 1.0), (1 + 1e-10, 0.0), (0.5, 1.0))
    assert formulas.aabb_contact(*boxes).hit is False
    assert formulas.aabb_contact(*boxes, precision="f32").hit is True
    args = ((0.0, 0.0), 1.0, (0.1, 0.2), (0.3, 0.7), 3.0, (-0.4, 0.9))
    r64, r32 = formulas.sphere_response(*args), formulas.sphere_response(*args, precision="f32")
    assert isinstance(r64, Response) and isinstance(r32, Response)
    assert r64 != r32
    assert all(float(np.float32(c)) == c for c in r32.v1 + r32.v2)
    assert r32.v1 == pytest.approx(r64.v1, rel=1e-6) and r32.v2 == pytest.approx(r64.v2, rel=1e-6)


@pytest.mark.parametrize("precision", PRECISIONS)
def test_results_are_plain_python_values(precision: formulas.Precision) -> None:
    c = formulas.sphere_contact((0.1, 0.2), 0.3, (0.7, -0.1), 0.2, precision=precision)
    assert type(c.hit) is bool and type(c.distance) is float
    assert isinstance(c.normal, tuple) and all(type(x) is float for x in c.normal)
    r = formulas.sphere_response(
        (0.1, 0.2), 1, (1, 0), (0.7, -0.1), 2, (0, 1), 0.5, precision=precision
    )
    assert isinstance(r, Response) and all(type(x) is float for x in r.v1 + r.v2)


def test_restitution_zero_gives_equal_normal_velocities() -> None:
    r = formulas.sphere_response((0, 0), 1, (2, 1), (1, 0), 1, (0, 0), e=0.0)
    assert r == Response((1.0, 1.0), (1.0, 0.0))
