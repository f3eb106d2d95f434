"""Tests of the exact time of impact of two moving spheres (reference_impl.toi).

Hand-computed closed forms, the edge cases of the contact definition, ties to
even, and properties against a slow, independent brute force: the closest
approach over ``[0, t_end]`` decides the hit, exact signs of ``|d(t)|**2 - R**2``
at the midpoints between doubles prove the rounding of ``toi``, and a Fraction
bisection of the root to 300 bits encloses each component of the normal.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from fractions import Fraction

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from reference_impl.toi import Impact, time_of_impact

F = Fraction
Vec = tuple[float, ...]


def gap2(ca: Vec, va: Vec, ra: float, cb: Vec, vb: Vec, rb: float, t: Fraction) -> Fraction:
    """``|cb(t) - ca(t)|**2 - (ra + rb)**2`` evaluated directly from the positions at ``t``."""
    d = [F(b) + F(v) * t - F(a) - F(u) * t for a, u, b, v in zip(ca, va, cb, vb, strict=True)]
    return sum((x * x for x in d), F(0)) - (F(ra) + F(rb)) ** 2


def closest(ca: Vec, va: Vec, cb: Vec, vb: Vec, t_end: float) -> Fraction:
    """The time in ``[0, t_end]`` of closest approach (0 without relative motion)."""
    dp = [F(b) - F(a) for a, b in zip(ca, cb, strict=True)]
    dv = [F(v) - F(u) for u, v in zip(va, vb, strict=True)]
    speed2 = sum((x * x for x in dv), F(0))
    if speed2 == 0:
        return F(0)
    free = -sum((x * y for x, y in zip(dp, dv, strict=True)), F(0)) / speed2
    return min(max(free, F(0)), F(t_end))


def brute_force_problems(
    ca: Vec, va: Vec, ra: float, cb: Vec, vb: Vec, rb: float, t_end: float, got: Impact
) -> list[str]:
    """What is wrong with ``got`` according to the brute force (empty: nothing)."""
    g = lambda t: gap2(ca, va, ra, cb, vb, rb, t)  # noqa: E731
    t_near = closest(ca, va, cb, vb, t_end)
    if g(t_near) > 0:
        return [] if got == Impact(False, None, None) else [f"no contact, got {got}"]
    if not got.hit or got.toi is None:
        return [f"contact by t = {float(t_near)}, got {got}"]
    if g(F(0)) <= 0:
        problems = [] if got.toi == 0.0 else [f"contact at 0, got toi {got.toi}"]
        return problems + start_normal_problems(ca, cb, got)
    # g > 0 at 0, <= 0 at t_near, decreasing between: one root, toi must be its nearest double.
    toi = F(got.toi)
    below = (toi + F(math.nextafter(got.toi, -math.inf))) / 2
    above = (toi + F(math.nextafter(got.toi, math.inf))) / 2
    problems = []
    if below > 0 and (below > t_near or g(below) < 0):
        problems.append(f"root below the half-way point under toi {got.toi}")
    if above < t_near and g(above) > 0:
        problems.append(f"root above the half-way point over toi {got.toi}")
    # the bracket must be narrow against the radius too (a 1e-115 sphere needs ~380 more bits)
    tiny = max(0, -math.frexp(ra + rb)[1]) if ra + rb > 0 else 0
    root = bisect(g, F(0), t_near, 300 + tiny)
    return problems + normal_problems(ca, va, ra, cb, vb, rb, root, got)


def bisect(
    g: Callable[[Fraction], Fraction], lo: Fraction, hi: Fraction, bits: int = 300
) -> tuple[Fraction, Fraction]:
    """Shrink ``[lo, hi]`` (``g(lo) > 0 >= g(hi)``) around the root ``bits`` times."""
    for _ in range(bits):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if g(mid) > 0 else (lo, mid)
    return lo, hi


def normal_problems(
    ca: Vec, va: Vec, ra: float, cb: Vec, vb: Vec, rb: float,
    root: tuple[Fraction, Fraction], got: Impact,
) -> list[str]:
    """The normal at the bracketed root: each component one of its bracket's roundings."""
    radius = F(ra) + F(rb)
    if radius == 0:
        return [] if got.normal is None else [f"points have no normal, got {got.normal}"]
    if got.normal is None:
        return ["normal missing"]
    problems = []
    for k, n in enumerate(got.normal):
        ends = [(F(cb[k]) + F(vb[k]) * t - F(ca[k]) - F(va[k]) * t) / radius for t in root]
        if n not in {float(e) for e in ends}:
            problems.append(f"normal[{k}] = {n!r}, bracket {[float(e) for e in ends]}")
    if abs(sum(F(n) ** 2 for n in got.normal) - 1) > F(2) ** -51:
        problems.append(f"normal {got.normal} is not unit to rounding")
    return problems


def at_least(num: Fraction, q: Fraction, m: Fraction) -> bool:
    """Whether ``num / sqrt(q) >= m`` (``q > 0``), decided by exact squares."""
    if num >= 0:
        return m <= 0 or num * num >= m * m * q
    return m <= 0 and num * num <= m * m * q


def start_normal_problems(ca: Vec, cb: Vec, got: Impact) -> list[str]:
    """The normal at 0 must be ``dp / |dp|`` rounded to nearest, componentwise."""
    dp = [F(b) - F(a) for a, b in zip(ca, cb, strict=True)]
    q = sum((x * x for x in dp), F(0))
    if q == 0 or got.normal is None:
        return [] if (q == 0) == (got.normal is None) else [f"normal {got.normal} at q = {q}"]
    problems = []
    for k, (n, x) in enumerate(zip(got.normal, dp, strict=True)):
        below = (F(n) + F(math.nextafter(n, -math.inf))) / 2
        above = (F(n) + F(math.nextafter(n, math.inf))) / 2
        if not at_least(x, q, below) or (at_least(x, q, above) and not at_least(-x, q, -above)):
            problems.append(f"normal[{k}] = {n!r} is not the nearest double")
    return problems


def check(ca: Vec, va: Vec, ra: float, cb: Vec, vb: Vec, rb: float, t_end: float) -> Impact:
    got = time_of_impact(ca, va, ra, cb, vb, rb, t_end)
    assert brute_force_problems(ca, va, ra, cb, vb, rb, t_end, got) == []
    return got


def test_the_issues_head_on_crossing_is_the_exact_gap_over_the_closing_speed() -> None:
    x, r, v = 1.0123456789, 0.05, 0.3
    got = check((-x, 0.0, 0.0), (v, 0.0, 0.0), r, (x, 0.0, 0.0), (-v, 0.0, 0.0), r, 10.0)
    assert got.toi == float((2 * F(x) - 2 * F(r)) / (2 * F(v)))
    assert got.normal == (1.0, 0.0, 0.0)


def test_an_oblique_rational_contact_has_the_exact_normal() -> None:
    # B (radius 2) at (-8 + 2t, 3) touches A (radius 3) when |(-8 + 2t, 3)| = 5: at x = -4,
    # t = 2 (the 3-4-5 triangle), with the normal (-4, 3) / 5.
    got = check((0.0, 0.0), (0.0, 0.0), 3.0, (-8.0, 3.0), (2.0, 0.0), 2.0, 5.0)
    assert got == Impact(True, 2.0, (-0.8, 0.6))


def test_the_checker_rejects_a_toi_one_ulp_off_and_a_wrong_normal() -> None:
    args = ((-1.0123456789, 0.0), (0.3, 0.0), 0.05, (1.0123456789, 0.0), (-0.3, 0.0), 0.05, 10.0)
    good = time_of_impact(*args)
    assert good.toi is not None
    off = Impact(True, math.nextafter(good.toi, 0.0), good.normal)
    assert brute_force_problems(*args, off) != []
    assert brute_force_problems(*args, Impact(True, good.toi, (1.0, 1e-16))) != []
    assert brute_force_problems(*args, Impact(False, None, None)) != []


@pytest.mark.parametrize("velocity", [(0.0, 0.0), (3.0, -1.5)])
def test_without_relative_motion_only_the_start_decides(velocity: Vec) -> None:
    assert check((0.0, 0.0), velocity, 0.5, (1.0, 0.0), velocity, 0.5, 9.0) == Impact(
        True, 0.0, (1.0, 0.0)
    )  # touching
    assert check((0.0, 0.0), velocity, 0.5, (0.75, 0.0), velocity, 0.5, 9.0).toi == 0.0
    far = math.nextafter(1.0, 2.0)
    assert check((0.0, 0.0), velocity, 0.5, (far, 0.0), velocity, 0.5, 9.0).hit is False


def test_overlapping_while_moving_apart_is_a_hit_at_zero_along_the_centres() -> None:
    got = check((0.0, 0.0), (-1.0, 0.0), 0.5, (0.3, 0.4), (1.0, 1.0), 0.5, 1.0)
    assert got == Impact(True, 0.0, (0.6, 0.8))
    assert check((0.0, 0.0), (-1.0, 0.0), 0.5, (1.0, 0.0), (1.0, 0.0), 0.5, 1.0).toi == 0.0


def test_coincident_centres_at_the_start_have_no_normal() -> None:
    assert time_of_impact((2.0, 2.0, 2.0), (1.0, 0.0, 0.0), 0.5, (2.0, 2.0, 2.0), (0.0,) * 3,
                          0.0, 1.0) == Impact(True, 0.0, None)


def test_points_collide_only_when_they_pass_through_each_other() -> None:
    assert check((0.0, 0.0), (1.0, 1.0), 0.0, (2.0, 2.0), (-1.0, -1.0), 0.0, 5.0) == Impact(
        True, 1.0, None
    )
    off = math.nextafter(2.0, 3.0)
    assert check((0.0, 0.0), (1.0, 1.0), 0.0, (2.0, off), (-1.0, -1.0), 0.0, 5.0).hit is False
    assert check((0.0, 0.0), (0.0, 0.0), 0.0, (3.0, 0.0), (-1.0, 0.0), 1.0, 5.0) == Impact(
        True, 2.0, (1.0, 0.0)
    )  # a point and a sphere


def test_a_graze_at_exact_tangency_hits_and_one_ulp_further_misses() -> None:
    assert check((0.0, 0.0), (0.0, 0.0), 0.5, (-10.0, 1.0), (1.0, 0.0), 0.5, 20.0) == Impact(
        True, 10.0, (0.0, 1.0)
    )
    wide = math.nextafter(1.0, 2.0)
    assert check((0.0, 0.0), (0.0, 0.0), 0.5, (-10.0, wide), (1.0, 0.0), 0.5, 20.0).hit is False
    narrow = math.nextafter(1.0, 0.0)  # overlaps by an ulp: an irrational root just before 10
    got = check((0.0, 0.0), (0.0, 0.0), 0.5, (-10.0, narrow), (1.0, 0.0), 0.5, 20.0)
    assert got.toi is not None and 9.99 < got.toi < 10.0


def test_contact_exactly_at_t_end_hits_and_a_root_beyond_it_misses() -> None:
    args = ((0.0, 0.0), (0.0, 0.0), 0.5, (3.0, 0.0), (-1.0, 0.0), 0.5)
    assert check(*args, 2.0) == Impact(True, 2.0, (1.0, 0.0))
    assert check(*args, math.nextafter(2.0, 0.0)) == Impact(False, None, None)
    assert check(*args, 1.0) == Impact(False, None, None)


@pytest.mark.parametrize(("start", "expected"), [
    (-(2.0**-52), 1.0),  # root 1 + 2**-53: half-way, the even neighbour is 1
    (-3 * 2.0**-52, 1.0 + 2.0**-51),  # root 1 + 3 * 2**-53: half-way, even is 1 + 2**-51
])
def test_a_root_half_way_between_doubles_rounds_to_even(start: float, expected: float) -> None:
    got = check((start, 0.0), (1.0, 0.0), 0.5, (3.0, 0.0), (-1.0, 0.0), 0.5, 4.0)
    assert F(got.toi or 0) != (3 - 1 - F(start)) / 2
    assert got.toi == expected


@pytest.mark.parametrize(("shift", "radius", "speed"), [
    (1e8, 3e-7, 1e-3), (-1e8, 0.3, 7.0), (1e8, 1e7, 1e5), (1e150, 1e149, 1e140),
    (1e-290, 1e-300, 1e-290), (0.0, 1e-300, 1.0),
])
def test_huge_and_tiny_scales_and_far_offsets(shift: float, radius: float, speed: float) -> None:
    ca = (shift, shift * 0.5, 0.1 * shift)
    cb = (shift + 7 * radius, shift * 0.5 + radius, 0.1 * shift)
    va, vb = (speed / 3, 0.0, 0.0), (-speed, speed / 7, 0.0)
    got = check(ca, va, radius, cb, vb, radius * 0.75, 1e300)
    assert got.hit and got.toi is not None and got.toi > 0


def test_a_head_on_far_from_the_origin_is_the_exact_quotient() -> None:
    x, r, v = 1e8 + 0.1, 1e-8, 3e-3
    got = check((x, 0.0), (v, 0.0), r, (x + 1.0, 0.0), (-v, 0.0), 2 * r, 1e9)
    assert got.toi == float((F(x + 1.0) - F(x) - 3 * F(r)) / (2 * F(v)))


@pytest.mark.parametrize("bad", [
    dict(ra=-1.0), dict(t_end=0.0), dict(t_end=math.inf), dict(ca=(math.nan, 0.0)),
    dict(cb=(0.0, 0.0, 0.0)),
])
def test_invalid_inputs_raise(bad: dict[str, object]) -> None:
    args: dict[str, object] = dict(ca=(0.0, 0.0), va=(1.0, 0.0), ra=0.5, cb=(3.0, 0.0),
                                   vb=(0.0, 0.0), rb=0.5, t_end=1.0)
    with pytest.raises(ValueError):
        time_of_impact(**{**args, **bad})  # type: ignore[arg-type]


coord = st.floats(-10.0, 10.0, allow_subnormal=False)
speed = st.floats(-5.0, 5.0, allow_subnormal=False)
radius = st.floats(0.0, 3.0, allow_subnormal=False)


@st.composite
def scenes(draw: st.DrawFn) -> tuple[Vec, Vec, float, Vec, Vec, float, float]:
    dim = draw(st.sampled_from([2, 3]))
    vec = lambda s: tuple(draw(s) for _ in range(dim))  # noqa: E731
    shift = draw(st.sampled_from([0.0, 1e8, -3.5e8]))
    ca, cb = (tuple(x + shift for x in vec(coord)) for _ in "ab")
    va, ra, rb, t_end = vec(speed), draw(radius), draw(radius), draw(st.floats(1e-3, 10.0))
    vb = vec(speed)
    if draw(st.booleans()):  # aim B at A, give or take the radius sum: mostly hits and grazes
        aim = vec(st.floats(-1.0, 1.0))
        reach = draw(st.floats(0.1, 1.2)) * t_end
        parts = zip(va, ca, cb, aim, strict=True)
        vb = tuple(u + (a - b + (ra + rb) * e) / reach for u, a, b, e in parts)
    return ca, va, ra, cb, vb, rb, t_end


@settings(max_examples=300, deadline=None)
@given(scenes())
@example(((0.0, 0.0), (0.0, 0.0), 0.0, (0.0, 1.0), (0.0, -1.0), 3.0894053672346e-115, 1.0))
def test_matches_the_brute_force(scene: tuple[Vec, Vec, float, Vec, Vec, float, float]) -> None:
    check(*scene)


@settings(max_examples=150, deadline=None)
@given(st.sampled_from([2, 3]), st.floats(-1e3, 1e3), st.floats(0.1, 4.0), st.floats(0.5, 2.0))
def test_near_grazing_passes_match_the_brute_force(
    dim: int, x: float, r: float, miss: float
) -> None:
    # B passes A sideways at a distance near the radius sum: tangency up to rounding.
    pad = (0.0,) * (dim - 2)
    check((x, 0.0, *pad), (0.0, 0.0, *pad), r, (x - 5.0, 2 * r * miss, *pad),
          (1.0, 0.0, *pad), r, 10.0)


def test_vectors_of_other_lengths_raise() -> None:
    one: Sequence[float] = (0.0,)
    with pytest.raises(ValueError):
        time_of_impact(one, one, 1.0, one, one, 1.0, 1.0)
