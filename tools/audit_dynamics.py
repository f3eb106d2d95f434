"""A self-audit of the labels of a stored run's dynamic rows, re-judged independently.

    python -m tools.audit_dynamics RUN_DIR --rows 200 --seed 39 [--markdown OUT.md]

Samples the ``disagree`` rows of ``sphere_scene`` and ``sphere_toi`` in ``RUN_DIR/results.csv``,
stratified by (engine, category): ``--rows`` shared in proportion to the strata's sizes, at
least one each, drawn with ``random.Random(--seed)``.  Each sampled row is re-judged from
``cases.jsonl`` and the engines' declared conventions in ``run.json`` by small computations of
its own (nothing from ``crosscheck.truth`` or ``reference_impl``): the reason's words and cited
numbers, a toi's separation against the exact first contact, a drop's apexes bounce by
bounce, a two-body scene's step-sampled outcome.  Verdicts: ``true`` (label and reason hold),
``misleading`` (the reason's numbers or words do not support it), ``wrong`` (another category
is right), ``unchecked`` (no check could decide; the note says why).  Prints a summary; with
``--markdown`` also writes a table of every sampled row.  Bad input: one line, exit 2.

Over 400 lines: the table of the phrases by which reasons cite their numbers and the four
recomputations (cited numbers, toi, bounces, two-body step sampling) are one audit sharing
the row, case and convention plumbing.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import random
import re
import sys
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

Row = dict[str, str]
Json = dict[str, Any]
Key = tuple[str, str]
DYNAMIC = ("sphere_scene", "sphere_toi")
VERDICTS = ("true", "misleading", "wrong", "unchecked")
RANK = {"wrong": 3, "misleading": 2, "true": 1, "unchecked": 0}
PASSING = ("timestep", "tolerance", "convention")
RELATIVE = ("apex", "velocities", "energy", "momentum", "divergence")
"""Quantities whose error is a fraction of a scale: an allowance above 1 allows everything."""
REL = 1e-9
N = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?|[-+]?inf|nan)"
FAILS = re.compile(r"beyond (?!float)|not explained|no finite answer|no run's|no step lag adds"
                   r"|reported no contact|explains it\b|, an error\b"
                   r"|not a unit vector|zero vector|before any impact")
"""Phrases by which a reason says a value fails (``beyond float64's`` is a passing aside)."""
LAG = r"loses # of the \S+ m it fell from \([^;]*; one step's lag allows a loss of #: v dt \+ "
OFF = r"off by # [^,;:]*, within "
Pick = Callable[[list[float]], tuple[float, float]] | None
CITED: list[tuple[str, str, Pick]] = [(mode, pattern.replace("#", N), pick) for mode, pattern,
                                      pick in [  # pick None: (first number, last number)
    ("within", r"it is off by #, within #", None),
    ("within", OFF + r"the engine's declared precision: [^=]*= #", None),
    ("within", OFF + r"the # that the settle offsets", None),
    ("within", OFF + r"one step of gravity on every body \(\|g\| dt = #", None),
    ("within", r"jitter # m/s at rest, within one step of gravity \|g\| dt = #", None),
    ("within", r"jitter # m/s at rest, within what .*?, # m/s at dt", None),
    ("within", LAG + r"\|g\| dt\^2 = \S+ m\)(?!: beyond)", None),
    ("within", r"s, # s from the \S+ s its fall gives \(one step late at either end and the "
               r"recording stride allow # s\)", None),
    ("within", r"off by # mean radii, within one step's travel at the top speed \(v dt = #", None),
    ("within", r"the spheres overlap at most # \(t = \S+\): within #", None),
    ("within", r"overlap at most # \(t = \S+\), never the engine's declared target overlap # "
               r"\(less its toi_tolerance and precision, #\)", lambda v: (v[0], v[1] - v[2])),
    ("within", r"engine normal of length \S+ \(off 1 by #: within the #", None),
    ("within", r"\(# m\) of the exact one [^:]*: within the engine's declared precision there "
               r"\(# m", None),
    ("within", r"stays within # m of the exact one, inside one step's travel at the top speed "
               r"# m", None),
    ("within", r"surfaces are # apart, within # \(declared toi_tolerance [^)]*\) of "
               r"(?:touching \(separation |the declared target separation )#",
     lambda v: (v[0] - v[2], v[1])),
    ("within", r"surfaces are # apart, already within # \(declared toi_tolerance [^)]*\) of the "
               r"declared target separation # or closer", lambda v: (max(v[0] - v[2], 0.0), v[1])),
    ("within", r"come within # at t = \S+ \(no exact contact\), inside the declared target "
               r"separation # plus toi_tolerance and precision #", lambda v: (v[0], v[1] + v[2])),
    ("within", r"settle off by # m \((gaps to the ground [^)]*) m\), within [^(]*\(declared rest "
               r"band # \.\. # m per contact, soft sink \S+ s\^2 x \|g\| = # m per body carried, "
               r"step \S+ \|g\| dt\^2 = # m per contact, precision # m\)",
     lambda v: (v[0], v[1] * (max(abs(v[2]), abs(v[3])) + v[4] + v[5]) + v[6])),
    ("beyond", LAG + r"\|g\| dt\^2 = \S+ m\): beyond", None),
    ("beyond", r"gains \S+ of the \S+ m it fell from \(apex # m against # m; only the "
               r"precision's # m", lambda v: (v[0] - v[1], v[2])),
    ("beyond", r"jitter # m/s at rest, beyond one step of gravity #", None),
    ("beyond", r"off by # of the energy scale per s: beyond the precision #", None),
    ("beyond", r"not a unit vector: length \S+, off 1 by #, beyond the #", None)]]
"""What reasons cite: ``within`` claims ``|x| <= y``, ``beyond`` claims ``x > y``.  The
settle pattern's group of gaps reads as the number of bodies (:func:`cited_pairs`)."""


@dataclass(frozen=True)
class Finding:
    verdict: str
    note: str


@dataclass
class Run:
    rows: list[Row]
    cases: dict[str, Json]
    conventions: dict[str, Json]
    by_key: dict[tuple[str, str, str], Row]


def load_run(folder: Path) -> Run:
    """The rows, cases and declared conventions of a run folder (missing json files: none)."""
    with (folder / "results.csv").open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    cases_file, info_file = folder / "cases.jsonl", folder / "run.json"
    lines = cases_file.read_text("utf-8").splitlines() if cases_file.exists() else []
    info = json.loads(info_file.read_text("utf-8")) if info_file.exists() else {}
    return Run(rows, {c["id"]: c for c in map(json.loads, filter(None, lines))},
               {e["name"]: e.get("conventions") or {} for e in info.get("engines", [])},
               {(r["case_id"], r["engine"], r["quantity"]): r for r in rows})


def allocate(sizes: dict[Key, int], total: int) -> dict[Key, int]:
    """Rows per stratum: proportional (largest remainder), at least 1, at most the stratum.

    >>> allocate({("a", "x"): 90, ("b", "x"): 9, ("c", "x"): 1}, 10)
    {('a', 'x'): 8, ('b', 'x'): 1, ('c', 'x'): 1}
    """
    n = sum(sizes.values())
    if total >= n:
        return dict(sizes)
    quota = {k: Fraction(total * s, n) for k, s in sizes.items()}
    out = {k: math.floor(q) for k, q in quota.items()}
    for k in sorted(sizes, key=lambda k: (out[k] - quota[k], k))[:total - sum(out.values())]:
        out[k] += 1
    out = {k: max(1, v) for k, v in out.items()}
    while sum(out.values()) > total and max(out.values()) > 1:
        out[max(out, key=lambda k: (out[k], k))] -= 1
    return out


def sample(rows: list[Row], total: int, seed: int) -> tuple[list[Row], dict[Key, tuple[int, int]]]:
    """The sampled disagreeing dynamic rows, and per (engine, category) its size and draw."""
    strata: dict[Key, list[Row]] = {}
    for row in rows:
        if row["status"] == "disagree" and row["kind"] in DYNAMIC:
            strata.setdefault((row["engine"], row["category"]), []).append(row)
    counts = allocate({k: len(v) for k, v in strata.items()}, total)
    rng, chosen = random.Random(seed), []
    for key in sorted(strata):
        chosen += [strata[key][i] for i in sorted(rng.sample(range(len(strata[key])), counts[key]))]
    return chosen, {k: (len(strata[k]), counts[k]) for k in sorted(strata)}


def parse_value(text: str) -> Any:
    """A value cell: None (empty, null), a bool, a float or a (nested) list of floats.

    >>> parse_value("[[1.0, -2], [nan, -inf]]"), parse_value("null"), parse_value("false")
    ([[1.0, -2.0], [nan, -inf]], None, False)
    """
    text = text.strip()
    if text in ("", "null", "None", "true", "false"):
        return None if text not in ("true", "false") else text == "true"
    try:
        return json.loads(re.sub(r"\binf\b", "Infinity", re.sub(r"\bnan\b", "NaN", text)),
                          parse_int=float)
    except ValueError:
        return None


def floats(value: Any) -> list[float]:
    """Every number of a parsed value, flattened."""
    if isinstance(value, list):
        return [x for item in value for x in floats(item)]
    return [] if value is None or isinstance(value, bool) else [float(value)]


def finite(value: Any) -> bool:
    """Whether a parsed value is there and finite throughout (an empty list is finite)."""
    return value is not None and all(math.isfinite(x) for x in floats(value))


def half_ulp(text: str) -> float:
    """What printing may have rounded off a cited number: half a unit in its last digit,
    at most 5e-3 of it (printed with 3 significant digits, trailing zeros dropped; 0 is 0).

    >>> half_ulp("0.00273"), half_ulp("167"), half_ulp("1"), half_ulp("0")
    (5e-06, 0.5, 0.005, 0.0)
    """
    m = re.fullmatch(r"[-+]?\d*\.?(\d*)(?:e([-+]?\d+))?", text)
    return 0.0 if m is None else min(0.5 * 10.0 ** (int(m.group(2) or 0) - len(m.group(1))),
                                     5e-3 * abs(float(text)))


def norm(v: Sequence[float]) -> float:
    return math.sqrt(math.fsum(x * x for x in v))


def dot(u: Sequence[float], v: Sequence[float]) -> float:
    return math.fsum(x * y for x, y in zip(u, v, strict=True))


def sub(u: Sequence[float], v: Sequence[float]) -> list[float]:
    return [float(x) - float(y) for x, y in zip(u, v, strict=True)]


def first_contact(dp: Sequence[float], dv: Sequence[float], reach: float) -> float | None:
    """The first t >= 0 with ``|dp + dv t| = reach`` (0 if within reach at once; None: never):
    the smaller root of a t^2 + b t + c in fractions but for one square root, in the stable
    form ``c / q``, ``q = (-b + sqrt(b^2 - 4ac)) / 2``.

    >>> first_contact([2.0, 0.0], [-1.0, 0.0], 1.0)
    1.0
    """
    a = sum(Fraction(x) ** 2 for x in dv)
    b = 2 * sum(Fraction(p) * Fraction(v) for p, v in zip(dp, dv, strict=True))
    c = sum(Fraction(p) ** 2 for p in dp) - Fraction(reach) ** 2
    if c <= 0:
        return 0.0
    disc = b * b - 4 * a * c
    if a == 0 or b >= 0 or disc < 0:
        return None
    return float(c / ((-b + Fraction(math.sqrt(disc))) / 2))


def separation(case: Json, t: float) -> float:
    """The surfaces' distance of a toi case's spheres at time t (centres in fractions)."""
    a, b = case["a"], case["b"]
    d = [float(Fraction(q) - Fraction(p) + (Fraction(y) - Fraction(x)) * Fraction(t))
         for p, q, x, y in zip(a["center"], b["center"], a["velocity"], b["velocity"],
                               strict=True)]
    return norm(d) - float(a["radius"] + b["radius"])


def check_reason(row: Row) -> Finding | None:
    """Every row: a reason is given, a ``tolerance`` value is finite, the words agree with
    the category (an error says how it fails; a passing category says no failure)."""
    reason, category = row["reason"].strip(), row["category"]
    if not reason:
        return Finding("misleading", "the reason is empty")
    if category == "tolerance" and not finite(parse_value(row["value"])):
        return Finding("wrong", f"tolerance on a missing or non-finite value "
                                f"({row['value'] or 'empty'}): no precision explains it")
    fail = FAILS.search(reason)
    if category == "error" and not fail:
        return Finding("misleading", "an error whose reason names no failure"
                       + (" and says 'within'" if "within" in reason else ""))
    if category in PASSING and fail:
        return Finding("misleading", f"a {category} reason saying '{fail.group(0).strip()}'")
    return None


def cited_pairs(reason: str) -> list[tuple[str, float, float, float]]:
    """``(mode, x, y, rounding)`` for every :data:`CITED` claim of a reason; ``rounding`` is
    what the printed digits may hide (half a last digit of each number, times the bodies)."""
    out = []
    for mode, pattern, pick in CITED:
        for groups in re.findall(pattern, reason):
            texts = list(groups) if isinstance(groups, tuple) else [groups]
            numeric = [re.fullmatch(N, t) is not None for t in texts]
            values = [float(t) if ok else t.count(",") + 1.0 for t, ok in zip(texts, numeric,
                                                                            strict=True)]
            bodies = max([v for v, ok in zip(values, numeric, strict=True) if not ok] or [1.0])
            x, y = pick(values) if pick else (values[0], values[-1])
            out.append((mode, x, y, bodies * sum(map(half_ulp, texts))))
    return out


def check_cited(row: Row) -> Finding | None:
    """The numbers a reason cites support its category: a passing category's error within
    its allowance (under ``timestep``, for a relative quantity, an allowance below the whole
    scale), an error's "beyond" truly beyond; a precision said to reach the bodies' radius
    does; "no finite answer" and "the zero vector" are what the value column holds."""
    category, reason, value = row["category"], row["reason"], parse_value(row["value"])
    notes, bad = [], []
    declared_loss = ("keeps any part of a bounce" in reason
                     or "plus the declared damping" in reason)
    absolute = re.search(r"off by \S+ (m|m/s|kg m/s|J)\b", reason) is not None
    for mode, x, y, rounding in cited_pairs(reason):
        if category == "error" and mode == "within":
            continue  # an aside of an error's reason (the engine's own verdict, a time)
        if category == "convention" and declared_loss and mode == "within" and x > y:
            notes.append(f"loss {x:.3g} beyond one step's {y:.3g}, which the reason's "
                         "declared soft, predictive contact or damping takes")
            continue
        text = f"cited {x:.3g} {'<=' if mode == 'within' else '>'} {y:.3g}"
        if not (abs(x) - rounding <= y * (1 + REL) if mode == "within" else x + rounding > y):
            bad.append(f"{text} does not hold")
        elif category in PASSING and mode == "beyond":
            bad.append(f"{text}: a failure cited for {category}")
        elif category == "timestep" and row["quantity"] in RELATIVE and y > 1 and not absolute:
            bad.append(f"{text}, but an allowance of {y:.3g} exceeds the whole scale of "
                       f"{row['quantity']} it explains")
        else:
            notes.append(text)
    for rtol, size, said, radius in re.findall(
            rf"2 x rtol {N} x {N} = {N} m, reaches the bodies' mean radius {N} m", reason):
        precision = 2 * float(rtol) * float(size)
        ok = precision >= float(radius) and abs(precision - float(said)) <= 0.01 * precision
        (notes if ok else bad).append(f"precision 2 x {rtol} x {size} = {precision:.3g} m "
                                      f"(cited {said}) against radius {radius} m")
    for claim, holds in (("no finite answer", not finite(value)),
                         ("normal is the zero vector", not any(floats(value)))):
        if claim in reason:
            (notes if holds else bad).append(f"'{claim}': the value is {row['value']}")
    if bad:
        return Finding("misleading", "; ".join(bad))
    return Finding("true", "; ".join(notes)) if notes else None


def check_toi(row: Row, case: Json, conv: Json) -> Finding | None:
    """``sphere_toi``: a ``timestep``/``tolerance`` ``toi`` leaves the spheres at the declared
    target separation within the declared ``toi_tolerance`` plus ``16 rtol`` of the case's
    magnitudes (under ``timestep`` also: within a declared sample or time tolerance of the
    exact first contact, recomputed); 1000 times beyond: ``wrong``.  Else a separation or
    overlap the reason cites (at the engine's time, at the closest approach) is recomputed."""
    if case.get("kind") != "sphere_toi":
        return None
    a, b, duration = case["a"], case["b"], float(case["duration"])
    magnitude = (max(norm(a["center"]), norm(b["center"])) + a["radius"] + b["radius"]
                 + (norm(a["velocity"]) + norm(b["velocity"])) * duration)
    allow = (conv.get("toi_tolerance") or 0.0) \
        + 16 * max(2.0**-52, conv.get("rtol") or 0.0) * magnitude
    target, value = conv.get("toi_target") or 0.0, parse_value(row["value"])
    dp, dv = sub(b["center"], a["center"]), sub(b["velocity"], a["velocity"])
    exact = first_contact(dp, dv, a["radius"] + b["radius"])
    if row["quantity"] == "toi" and row["category"] in ("timestep", "tolerance") \
            and isinstance(value, float) and math.isfinite(value):
        off = abs(separation(case, value) - target)
        window = max(conv.get("toi_time_tolerance") or 0.0,
                     duration / conv["toi_samples"] if conv.get("toi_samples") else 0.0)
        near = row["category"] == "timestep" and exact is not None \
            and abs(value - exact) <= window * (1 + REL)
        note = (f"toi {value:.9g} (exact first contact {exact if exact is not None else 'none'}"
                f"): surfaces {off:.3g} from the target {target:g}, allowance {allow:.3g}")
        travel = (conv.get("toi_time_tolerance") or 0.0) * duration * norm(dv)
        if off <= (allow + travel) * (1 + REL) or near:
            return Finding("true", note)
        return Finding("wrong" if off > 1e3 * allow else "misleading", note + ": beyond")
    closest = min(max(-dot(dp, dv) / (dot(dv, dv) or 1.0), 0.0), duration)
    for pattern, sign, at_engine in (
            (rf"at the engine's time {N} the surfaces are {N} apart", 1, True),
            (rf"overlap at most {N} \(t = {N}\)", -1, False),
            (rf"come within {N} at t = {N}", 1, False)):
        if cited := re.search(pattern, row["reason"]):
            said, t = (cited.group(2), float(cited.group(1))) if at_engine else \
                (cited.group(1), closest)
            sep = sign * separation(case, t) + 0.0
            ok = abs(sep - float(said)) <= 5e-3 * abs(float(said)) + half_ulp(said) + allow
            return Finding("true" if ok else "misleading", f"{'overlap' if sign < 0 else 'gap'} "
                           f"{sep:.3g} at t = {t:.9g} recomputed (cited {said})")
    return None


def ground(case: Json) -> Json | None:
    """The wall a drop scene's one body falls on (facing gravity), or None."""
    if len(case.get("bodies") or []) != 1:
        return None
    return next((w for w in case.get("walls") or []
                 if dot(w["normal"], case.get("gravity") or [0.0] * len(w["normal"])) < 0), None)


def speed_cap(conv: Json, dt: float) -> float:
    """The declared speed cap at this time step (a cap per step scales as ``1 / dt``)."""
    cap = conv.get("max_speed") or math.inf
    return float(cap * (conv.get("time_step") or dt) / dt if conv.get("max_speed_at") == "step"
                 else cap)


def bounces(case: Json, conv: Json, apexes: Sequence[float], count: int, recorded: int = 0
            ) -> list[tuple[int, float, float, float, bool, bool]]:
    """Each apex ``(k, fell from, expected, engine, gain, loss)`` judged from the engine's
    previous apex (the first: the drop height): the body lands at ``v = sqrt(2|g|H)`` (under
    a declared speed cap), rises to ``(e v)^2 / 2|g|`` (e = 0 under a declared restitution
    threshold); a gain is beyond ``1e-6 H`` plus the declared precisions, a loss beyond one
    step's lag ``v dt + |g| dt^2 + |g| (s dt)^2 / 2`` (s: the recording stride).  A bounce
    the exact run has and the engine lacks is apex 0, while its flight lasts four steps."""
    wall, body, g_vec = ground(case), case["bodies"][0], case["gravity"]
    assert wall is not None
    g, dt = norm(g_vec), case.get("dt") or 1 / 240
    gap = dot(wall["normal"], body["center"]) - wall["offset"] - body["radius"]
    up, cap = max(0.0, dot(wall["normal"], body["velocity"])), speed_cap(conv, dt)
    stride = max(1, math.ceil(round(case["duration"] / dt) / 20_000))
    r, coords = conv.get("response_rtol") or 0.0, 2 * (conv.get("rtol") or 0.0) * (
        norm(body["center"]) + gap)
    out, previous = [], gap + up * up / (2 * g)
    for k in range(1, count + 1):
        speed = min(math.sqrt(2 * g * max(previous, 0.0)), cap)
        e = 0.0 if speed < (conv.get("restitution_threshold") or 0.0) else case["restitution"]
        expected, missing = (e * speed) ** 2 / (2 * g), k > len(apexes)
        if missing and 2 * e * speed / g < 4 * dt:
            break
        if missing and k <= recorded:  # the engine bounced; its apex falls after the end
            break
        apex = 0.0 if missing else apexes[k - 1]
        slack = 1e-6 * max(previous, 0.0) + coords + (2 * r + r * r) * expected
        lag = speed * dt + g * dt * dt + g * (stride * dt) ** 2 / 2
        out.append((k, previous, expected, apex, apex > expected + slack,
                    apex < expected - lag - slack))
        if missing:
            break
        previous = apex
    return out


def check_drop(row: Row, case: Json, conv: Json, run: Run) -> Finding | None:
    """Drop scenes, rows whose reason judges the bounces ("fell from"): each apex recomputed
    (:func:`bounces`); a gain or a loss beyond one step's lag refutes ``timestep`` and
    ``convention``, their absence refutes ``error``."""
    if ground(case) is None or "fell from" not in row["reason"]:
        return None
    apex_row = run.by_key.get((row["case_id"], row["engine"], "apex"), {})
    values, exact = (parse_value(apex_row.get(c, "")) for c in ("value", "truth"))
    if not isinstance(values, list) or not finite(values):
        return Finding("unchecked", "no finite apex list for this case and engine")
    count = len(exact) if isinstance(exact, list) else len(values)
    times = parse_value(run.by_key.get((row["case_id"], row["engine"], "bounce_time"),
                                       {}).get("value", ""))
    events = bounces(case, conv, floats(values)[:count], count,
                     len(times) if isinstance(times, list) else 0)
    bad = [e for e in events if e[4] or e[5]]
    if not events:  # the first expected flight lasts under four steps (or no exact bounce)
        return Finding("true" if count and row["category"] != "error" else "unchecked",
                       f"no bounce to expect (restitution threshold, or a flight under four "
                       f"steps): {len(values)} recorded, {count} exact")
    k, fell, expected, apex, gain, _ = (bad or sorted(events, key=lambda e: e[3] - e[2]))[0]
    text = (f"bounce {k}: apex {apex:.4g} m against {expected:.4g} m from {fell:.4g} m "
            f"({(apex - expected) / fell if fell > 0 else 0.0:+.3g} of it, "
            + ("a gain" if gain else "a loss beyond one step's lag" if bad else "within")
            + f"; {len(events)} bounces judged)")
    model = conv.get("restitution_model") or ""
    if row["category"] == "convention" and bad and not any(e[4] for e in bad):
        if model in ("soft", "predictive"):  # such a contact keeps any part of a bounce
            return Finding("true", f"{text}; a loss the declared {model} contact allows")
        if (conv.get("damping") or 0.0) > 0:
            return Finding("unchecked", f"{text}; the declared damping is not modelled here")
    return Finding(("true" if bad else "wrong") if row["category"] == "error" else
                   ("wrong" if bad else "true"), text)


def outcomes(case: Json, conv: Json) -> list[tuple[list[list[float]] | None, str]]:
    """Final velocities of two free spheres: the exact run's, and step-sampled runs', whose
    contact is the first step start ``k dt`` finding them within 0 (or the declared margin)
    of touching while approaching (none: they fly on), with and without the declared speed
    cap on the start.  An impact is resolved with e (0 under the declared threshold) along
    the line of centres; coincident centres have none (outcome None)."""
    (a, b), dt = case["bodies"], case.get("dt") or 1 / 240
    cap, reach = speed_cap(conv, dt), float(a["radius"] + b["radius"])

    def hit(va: list[float], vb: list[float], dp: list[float]) -> list[list[float]]:
        n, dv = [p / norm(dp) for p in dp], sub(vb, va)
        e = 0.0 if -dot(dv, n) < (conv.get("restitution_threshold") or 0.0) else \
            case["restitution"]
        j = -(1 + e) * dot(dv, n) / (1 / a["mass"] + 1 / b["mass"])
        return [[x - j * m / a["mass"] for x, m in zip(va, n, strict=True)],
                [y + j * m / b["mass"] for y, m in zip(vb, n, strict=True)]]

    def clamp(v: list[float]) -> list[float]:
        if conv.get("max_speed_at") == "per coordinate":
            return [max(-cap, min(cap, x)) for x in v]
        return v if norm(v) <= cap else [x * cap / norm(v) for x in v]

    va0, vb0 = [float(x) for x in a["velocity"]], [float(x) for x in b["velocity"]]
    dp0 = sub(b["center"], a["center"])
    t = first_contact(dp0, sub(vb0, va0), reach)
    out: list[tuple[list[list[float]] | None, str]] = [(
        hit(va0, vb0, [p + (y - x) * t for p, x, y in zip(dp0, va0, vb0, strict=True)])
        if t is not None and 0 < t <= case["duration"] else [va0, vb0], "the exact run")]
    for capped in (False, True):
        va, vb = (clamp(va0), clamp(vb0)) if capped else (va0, vb0)
        label = f" (start capped at {cap:.4g} m/s)" if capped else ""
        for m in sorted({0.0, (conv.get("verdict_margins") or {}).get("sphere") or 0.0}):
            for k in range(max(1, round(case["duration"] / dt))):
                dp = [p + (y - x) * k * dt for p, x, y in zip(dp0, va, vb, strict=True)]
                if norm(dp) - reach <= m and (norm(dp) == 0 or dot(dp, sub(vb, va)) < 0):
                    out.append((hit(va, vb, dp), f"step-sampled: contact at step {k}{label}")
                               if norm(dp) > 0 else (None, f"centres coincide at step {k}"))
                    break
            else:
                out.append(([va, vb], f"step-sampled: no step start finds contact{label}"))
    if t is not None and 0 < t <= case["duration"]:
        out += _ahead(case, conv, va0, vb0, dp0, t, hit)
    return out


def _ahead(case: Json, conv: Json, va: list[float], vb: list[float], dp0: list[float],
           t: float, hit: Callable[[list[float], list[float], list[float]],
                                   list[list[float]]]
           ) -> list[tuple[list[list[float]] | None, str]]:
    """The runs of engines that meet an impact before it or inside the bodies, as they
    declare: speculative contacts at the start of the step holding the touch at ``t``; a
    swept engine's time of impact at its declared overlap (``toi_target`` < 0), to its
    ``toi_tolerance``, the band scanned at 2001 points."""
    dt, reach = case.get("dt") or 1 / 240, float(case["bodies"][0]["radius"]
                                               + case["bodies"][1]["radius"])
    dv = sub(vb, va)
    out: list[tuple[list[list[float]] | None, str]] = []
    if conv.get("speculative_contacts"):
        k = math.floor(t / dt) - (1 if math.floor(t / dt) * dt >= t and t >= dt else 0)
        dp = [p + v * k * dt for p, v in zip(dp0, dv, strict=True)]
        out.append((hit(va, vb, dp), f"speculative: contact at the start of step {k}"))
    target, band = conv.get("toi_target") or 0.0, conv.get("toi_tolerance") or 0.0
    if target < 0 and not conv.get("sampled_contacts"):
        for i in range(2001):
            depth = -target - band + 2 * band * i / 2000
            later = first_contact(dp0, dv, reach - depth)
            if later is not None:
                dp = [p + v * later for p, v in zip(dp0, dv, strict=True)]
                out.append((hit(va, vb, dp), f"swept: impact {depth:.4g} m deep"))
    return out


def check_two_body(row: Row, case: Json, conv: Json, run: Run) -> Finding | None:
    """Two bodies, no walls, no gravity: the engine's final velocities (its velocities row)
    against :func:`outcomes`.  Within ``1e-5`` of the top initial speed they refute an
    ``error`` on velocities, energy or momentum or one citing a pass-through; a ``timestep``
    needs them within that plus the declared precisions (``2 rtol``, ``response_rtol``)."""
    if len(case.get("bodies") or []) != 2 or case.get("walls") or any(case.get("gravity") or []):
        return None
    if row["category"] == "error" and "passed through" not in row["reason"] and \
            row["quantity"] not in ("velocities", "energy", "momentum"):
        return None
    engine = parse_value(run.by_key.get((row["case_id"], row["engine"], "velocities"),
                                        {}).get("value", ""))
    if not isinstance(engine, list) or len(engine) != 2 or not finite(engine):
        return Finding("unchecked", "no finite final velocities for this case and engine")
    found, top = outcomes(case, conv), max(norm(body["velocity"]) for body in case["bodies"])
    if not conv.get("sampled_contacts"):  # a pass-through explains only a declared sampler
        found = [(out, how) for out, how in found if "no step start" not in how]
    undefined = next((f"; {how}: no line of centres" for out, how in found if out is None), "")
    off, how = min((max(abs(x - y) for u, w in zip(engine, out, strict=True)
                        for x, y in zip(u, w, strict=True)) / top, how)
                   for out, how in found if out is not None)
    # the precision: 2 rtol of a velocity, a declared response precision, and the tilt a
    # line of centres held to 2 rtol of the coordinates gives the impulse
    extent = max(abs(x) for body in case["bodies"] for x in body["center"]) + 1.0
    reach = float(case["bodies"][0]["radius"] + case["bodies"][1]["radius"])
    declared = (1e-5 + 2 * (conv.get("rtol") or 0.0) + (conv.get("response_rtol") or 0.0)
                + 4 * (conv.get("rtol") or 0.0) * extent / reach)
    text = f"velocities {off:.4g} of the top speed from {how}"
    if row["category"] == "error":
        return Finding("wrong", f"{text} (within 1e-05; the declared precision allows "
                                f"{declared - 1e-5:.4g})") if off <= 1e-5 else \
            Finding("unchecked" if undefined else "true", text + undefined)
    unmodelled = [f"{name} {conv.get(name)}" for name in ("damping", "friction")
                  if (conv.get(name) or 0.0) > 0] + [
        f"restitution_model {conv['restitution_model']}" for _ in [0]
        if conv.get("restitution_model")]
    if off > declared and unmodelled:
        return Finding("unchecked", f"{text}; declared {', '.join(unmodelled)}: not modelled "
                                    "by this audit")
    if row["category"] == "timestep" and off > declared:
        return Finding("unchecked" if undefined else "wrong",
                       f"{text}, beyond {declared:.3g}{undefined}")
    return Finding("true", f"{text} (within {declared:.3g})") if off <= declared else None


def audit(row: Row, run: Run) -> Finding:
    """The row's verdict: the worst finding of the checks that apply (``true`` needs one)."""
    case, conv = run.cases.get(row["case_id"]), run.conventions.get(row["engine"], {})
    found = [check_reason(row), check_cited(row)]
    if case is not None:
        found += [check_toi(row, case, conv), check_drop(row, case, conv, run),
                  check_two_body(row, case, conv, run)]
    real = [f for f in found if f is not None]
    if not real:
        return Finding("unchecked", "no case in cases.jsonl" if case is None else
                       f"no cited numbers parsed and no recomputation of {row['quantity']} here")
    worst = max(real, key=lambda f: RANK[f.verdict]).verdict
    return Finding(worst, "; ".join(f.note for f in real if f.verdict == worst))


def summary(strata: dict[Key, tuple[int, int]], verdicts: Counter[str]) -> str:
    """Rows sampled per stratum, the verdict counts and the wrong share of checked rows."""
    lines = ["engine / category: rows sampled of the stratum"]
    lines += [f"  {e} / {c}: {taken} of {size}" for (e, c), (size, taken) in strata.items()]
    checked = sum(verdicts[v] for v in ("true", "misleading", "wrong"))
    lines.append("verdicts: " + ", ".join(f"{v} {verdicts[v]}" for v in VERDICTS))
    share = f"{100 * verdicts['wrong'] / checked:.1f}%" if checked else "n/a"
    return "\n".join([*lines, f"wrong: {share} of {checked} checked rows"]) + "\n"


def markdown(audited: list[tuple[Row, Finding]]) -> str:
    """Every sampled row and its audit as a Markdown table."""
    def cell(text: str) -> str:
        return text.replace("|", "\\|").replace("\n", " ")
    lines = ["| case | engine | quantity | category | audit | audit reason |",
             "| --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {cell(r['case_id'])} | {r['engine']} | {r['quantity']} | {r['category']} "
              f"| {f.verdict} | {cell(f.note)} |" for r, f in audited]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Audit a run folder (see the module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, metavar="RUN_DIR", help="the run folder")
    parser.add_argument("--rows", type=int, default=200, help="rows to sample (default 200)")
    parser.add_argument("--seed", type=int, default=39, help="seed of the sample (default 39)")
    parser.add_argument("--markdown", type=Path, metavar="OUT.md", help="also write the table")
    args = parser.parse_args(argv)
    error = (f"--rows must be at least 1, not {args.rows}" if args.rows < 1 else
             f"run folder not found: {args.run}" if not args.run.is_dir() else
             f"no results.csv in {args.run}" if not (args.run / "results.csv").is_file() else "")
    if error:
        print(f"audit_dynamics: error: {error}", file=sys.stderr)
        return 2
    run = load_run(args.run)
    rows, strata = sample(run.rows, args.rows, args.seed)
    audited = [(row, audit(row, run)) for row in rows]
    sys.stdout.write(summary(strata, Counter(f.verdict for _, f in audited)))
    if args.markdown:
        args.markdown.write_text(markdown(audited), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
