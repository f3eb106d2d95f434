"""The columnar path (crosscheck.truth.columnar, and the runner's columnar writing) gives every
row of the per-record path, field by field, on the whole suite."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Adapter
from crosscheck.core.model import PAIR_KINDS, Observation, Status, Undefined
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase, PairCase, SceneCase, SphereBody
from crosscheck.results.store import ResultsStore
from crosscheck.run import runner, scoring
from crosscheck.run.execute import Outcome, execute
from crosscheck.run.timing import Timing
from crosscheck.truth import oracle
from crosscheck.truth.columnar import judge_batch
from crosscheck.truth.score import Verdict, judge
from tests import fakes
from tests.conftest import ROOT, aabb, response, sphere

OPTIONS = RunOptions(quick=True, isolate=False)


@cache
def suite() -> tuple[list[PairCase], list[Observation]]:
    """Every pair case of cases/ and its exact truth."""
    loaded = load_paths(sorted((ROOT / "cases").glob("*.toml"))).cases
    cases = [_pair(c) for c in loaded if c.kind in PAIR_KINDS]
    return cases, [oracle.truth(c) for c in cases]


def _pair(case: AnyCase) -> PairCase:
    assert not isinstance(case, SceneCase)
    return case


def _same(a: float, b: float) -> bool:
    """Bit for bit, or both NaN."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return a == b and math.copysign(1, a) == math.copysign(1, b)


def _verdicts(adapter: Adapter, cases: Sequence[PairCase], observations: Sequence[Observation],
              truths: Sequence[Observation]) -> tuple[list[Verdict], list[Verdict]]:
    """The per-record verdicts and the columnar ones, row for row."""
    columns = judge_batch(cases, adapter.conventions, observations, truths)
    rows = zip(columns.case, columns.quantity, strict=True)
    per_record = [judge(cases[i], adapter.conventions, q, observations[i].get(q), truths[i],
                        observations[i]) for i, q in rows]
    return per_record, [columns.verdict(row) for row in range(len(per_record))]


def assert_same_verdicts(expected: list[Verdict], got: list[Verdict]) -> None:
    assert len(expected) == len(got)
    for row, (e, g) in enumerate(zip(expected, got, strict=True)):
        where = f"row {row}: {e} != {g}"
        assert (e.status, e.category, e.reason) == (g.status, g.category, g.reason), where
        for field in ("error", "tolerance", "error_at_contact"):
            assert _same(getattr(e, field), getattr(g, field)), f"{field} of {where}"


ENGINES = ["reference", "reference-f32", "fcl", "pymunk", "pymunk-default"]


@pytest.mark.parametrize("engine", [
    pytest.param(e, marks=() if e.startswith("reference") else pytest.mark.engine)
    for e in ENGINES])
def test_columnar_verdicts_equal_per_record_on_the_suite(engine: str) -> None:
    adapter = adapters.get(engine)
    if adapter.available() is not None:
        pytest.skip(f"{engine}: {adapter.available()}")
    cases, truths = suite()
    picked = [(c, t) for c, t in zip(cases, truths, strict=True)  # in-process: no faults
              if not adapter.unsupported(c) and adapter.known_hang(c) is None
              and (engine.startswith("reference")  # engines crash on bad input and on some
                   or ("bad_input" not in c.source and "cover" not in c.tags))]  # cover cases
    outcomes = [execute(adapter, c, OPTIONS) for c, _ in picked]
    kept = [(c, t, o.observation) for (c, t), o in zip(picked, outcomes, strict=True)
            if o.observation is not None]
    expected, got = _verdicts(adapter, [c for c, _, _ in kept], [o for _, _, o in kept],
                              [t for _, t, _ in kept])
    assert_same_verdicts(expected, got)
    assert len(kept) > 100


def _wrong(truth: Observation, how: str) -> Observation:
    """An answer wrong in a known way."""
    bumps: dict[str, Callable[[float], float]] = {
        "nudge": lambda x: x * (1 + 1e-9) + 1e-12, "flip": lambda x: -x,
        "nan": lambda x: math.nan, "inf": lambda x: math.inf}
    bump = bumps[how]

    def vec(v: Any) -> Any:
        return tuple(bump(x) for x in v) if isinstance(v, tuple) else v
    def num(x: Any) -> Any:
        return bump(x) if isinstance(x, float) else x
    return replace(truth, hit=(not truth.hit) if how == "flip" and isinstance(truth.hit, bool)
                   else truth.hit, distance=num(truth.distance), normal=vec(truth.normal),
                   v1=vec(truth.v1), v2=vec(truth.v2))


@pytest.mark.parametrize("how", ["nudge", "flip", "nan", "inf", "undefined", "absent", "long"])
def test_columnar_verdicts_equal_per_record_on_wrong_answers(how: str) -> None:
    """Fakes that disagree in known ways: every row goes through the same categories."""
    cases, truths = suite()
    if how == "undefined":
        answers = [Observation.undefined(("hit", "distance", "normal", "v1", "v2"), "tie")
                   for _ in cases]
    elif how == "absent":
        answers = [Observation(hit=t.hit) for t in truths]
    elif how == "long":  # vectors of the wrong length, and a normal that is not unit
        answers = [replace(t, normal=(2.0, 0.0), v1=(1.0, 2.0, 3.0, 4.0)) for t in truths]
    else:
        answers = [_wrong(t, how) for t in truths]
    for adapter in (fakes.AlwaysRight(), fakes.TouchingIsContact(), adapters.get("pymunk")):
        assert_same_verdicts(*_verdicts(adapter, cases, answers, truths))


def test_columnar_agrees_on_the_truth_itself_and_categorises_the_rest() -> None:
    """Not only the same as judge: the truth agrees everywhere it is defined."""
    cases, truths = suite()
    columns = judge_batch(cases, fakes.AlwaysRight().conventions, truths, truths)
    for i, q, status in zip(columns.case, columns.quantity, columns.status, strict=True):
        want = truths[i].get(q)
        assert status is (Status.UNDEFINED if isinstance(want, Undefined) else Status.AGREE)


def test_own_tolerances_and_odd_boxes_take_the_per_record_bound() -> None:
    """Cases with their own tolerance, near-tied box overlaps and huge or tiny numbers."""
    cases = [_pair(c) for c in (
        sphere(0.0, 1.0 + 2**-52), sphere(1e15, 1e15 + 1.0), sphere(0.0, 1e-300, 1e-300, 1e-300),
        aabb([0.0, 0.0], [1.0, 1.0], [1.5, 1.5], [1.0, 1.0]),
        aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.5, 1.5 + 1e-15, 0.0], [1.0, 1.0, 1.0]),
        aabb([0.0, 0.0], [1.0, 1.0], [2.0, 3.0 + 1e-16], [1.0, 1.0]),
        aabb([1e300, 0.0], [1e300, 1.0], [-1e300, 0.5], [1e300, 1.0]),
        response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1e300, 0.0]),
        sphere(0.0, 2.0, tolerance={"distance": 0.5, "normal": 0.1}),
        response([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [-1.0, 0.0], tolerance={"velocity": 1e-3}),
    )]
    truths = [oracle.truth(c) for c in cases]
    for answers in (truths, [_wrong(t, "nudge") for t in truths]):
        assert_same_verdicts(*_verdicts(fakes.AlwaysRight(), cases, answers, truths))


# --- the runner: rows written from columns ----------------------------------------------------


def _rows(folder: Path) -> list[dict[str, Any]]:
    rows = [json.loads(line) for line in (folder / "results.jsonl").read_text().splitlines()]
    for row in rows:
        row.pop("setup_s")  # timing: measured, differs between runs
    return sorted(rows, key=lambda r: (r["case_id"], r["engine"], r["quantity"]))


def _run(folder: Path, cases: Sequence[AnyCase], engines: Sequence[Adapter],
         columnar: bool) -> list[dict[str, Any]]:
    store = ResultsStore(folder)
    try:
        runner.run(cases, engines, store, OPTIONS, columnar=columnar)
    finally:
        store.close()
    return _rows(folder)


def test_runner_writes_the_same_lines_both_ways(tmp_path: Path) -> None:
    """Whole suite (scenes excluded: they are scored per record either way), reference
    engines and fakes, including error and skip outcomes: identical rows."""
    cases, _ = suite()
    engines = [adapters.get("reference"), adapters.get("reference-f32"), fakes.OffByOne(),
               fakes.TouchingIsContact(), fakes.HitOnly(), fakes.Raises(), fakes.Unavailable()]
    per_record = _run(tmp_path / "records", cases, engines, columnar=False)
    columnar = _run(tmp_path / "columns", cases, engines, columnar=True)
    assert len(per_record) == len(columnar) > 1000
    for a, b in zip(per_record, columnar, strict=True):
        assert a == b or json.dumps(a) == json.dumps(b), (a, b)


def test_scored_outcomes_equal_records() -> None:
    """score_lines (columns to JSON lines) against score_case's records, as the store writes."""
    cases, truths = suite()
    adapter = fakes.OffByOne()
    outcomes = [execute(adapter, c, OPTIONS) for c in cases]  # errors on undefined truths
    timings = [Timing((1e-6, 2e-6, 4e-6), 10, 0.0), Timing((3e-6,), 1, 0.0)]
    outcomes = [replace(o, timing=timings[k % 3]) if k % 3 < 2 else o
                for k, o in enumerate(outcomes)]
    outcomes[0] = Outcome(None, Status.CRASH, "worker died \u2013 \"quoted\"")
    assert any(o.status is Status.ERROR for o in outcomes)
    lines = runner.score_lines(cases, adapter, outcomes, truths)
    records = [r for c, o, t in zip(cases, outcomes, truths, strict=True)
               for r in scoring.score_case(c, adapter, o, t)]
    assert lines == "".join(json.dumps(r.row()) + "\n" for r in records)
    kept = runner.score_records(cases, adapter, outcomes, truths)
    assert lines == "".join(json.dumps(r.row()) + "\n" for r in kept)


def _random_pairs(n: int, seed: int) -> list[PairCase]:
    """Random spheres, boxes and responses in 2-D and 3-D, about half touching or
    overlapping, sizes and offsets over many scales (as fuzzing and the bench draw them)."""
    rng = np.random.default_rng(seed)
    cases: list[PairCase] = []
    for k in range(n):
        dim, scale = int(rng.integers(2, 4)), 10.0 ** rng.uniform(-6, 6)
        a = rng.uniform(-10, 10, dim) * scale + rng.choice([0.0, 1e6, 1e12]) * scale
        b = a + rng.uniform(-3, 3, dim) * scale
        sizes = rng.uniform(0.2, 1.5, (2, dim)) * scale
        kind = k % 3
        if kind == 0:
            cases.append(_pair(aabb(a.tolist(), sizes[0].tolist(), b.tolist(), sizes[1].tolist())))
        elif kind == 1:
            cases.append(_pair(sphere(0.0, 0.0, float(sizes[0, 0]), float(sizes[1, 0]),
                                      dim=dim).model_copy(update={
                "a": SphereBody(center=tuple(a.tolist()), radius=float(sizes[0, 0])),
                "b": SphereBody(center=tuple(b.tolist()), radius=float(sizes[1, 0]))})))
        else:
            v = rng.normal(0, 1, (2, dim)) * 10.0 ** rng.uniform(-3, 3)
            cases.append(_pair(response(a.tolist(), v[0].tolist(), b.tolist(), v[1].tolist(),
                                        float(rng.uniform(0.1, 10)), float(rng.uniform(0.1, 10)))))
    return cases


@pytest.mark.parametrize("engine", ["reference", "reference-f32"])
def test_columnar_verdicts_equal_per_record_on_random_pairs(engine: str) -> None:
    """Boxes whose deciding axes differ (the magnitudes that set the bound), at many scales."""
    cases = _random_pairs(3000, 7)
    truths = [oracle.truth(c) for c in cases]
    adapter = adapters.get(engine)
    answers = [_observed(execute(adapter, c, OPTIONS)) for c in cases]
    expected, got = _verdicts(adapter, cases, answers, truths)
    assert_same_verdicts(expected, got)
    agreeing = sum(v.status is Status.AGREE for v in got)
    assert agreeing > (len(got) // 2 if engine == "reference" else 0)


def _observed(outcome: Outcome) -> Observation:
    assert outcome.observation is not None, outcome.reason
    return outcome.observation


def test_an_interrupted_columnar_run_writes_every_case_it_received(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Chunks wait to be written; Ctrl-C (here raised by the progress callback after the
    fifth lane item) still writes the cases already received, and only those."""
    monkeypatch.setattr(runner, "FLUSH_S", 1e9)  # nothing written before the end
    cases, _ = suite()
    engines = [fakes.AlwaysRight(), fakes.OffByOne()]
    received, items = 0, 0

    def progress(pairs: int) -> None:
        nonlocal received, items
        received += pairs // len(engines)
        items += 1
        if items == 5:
            raise KeyboardInterrupt

    store = ResultsStore(tmp_path / "run")
    with pytest.raises(KeyboardInterrupt):
        runner.run(cases[:100], engines, store, replace(OPTIONS, jobs=1), progress)
    store.close()
    rows = _rows(tmp_path / "run")
    assert 5 <= received < 100
    assert len({r["case_id"] for r in rows}) == received
    assert {r["engine"] for r in rows} == {"fake-right", "fake-off"}
    assert len({(r["case_id"], r["engine"], r["quantity"]) for r in rows}) == len(rows)
