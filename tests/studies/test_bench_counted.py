"""The counted harness-overhead figures of ``crosscheck bench``: their arithmetic on dumps the
test writes, what they say when nothing can be counted, and one small real count under
callgrind that checks their shape.  Nothing here measures time: the counts are
instructions, and no count of a real engine is written down as expected."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import pytest

from crosscheck.run import callgrind
from crosscheck.studies.bench import Figure, counted
from crosscheck.studies.bench.streams import overhead_streams

NO_VALGRIND = callgrind.missing()
needs_valgrind = pytest.mark.skipif(NO_VALGRIND is not None, reason=str(NO_VALGRIND))
NAMES = [f"harness overhead {e} {k}, counted instructions" for e, k in (
    ("fcl", "sphere"), ("fcl", "aabb"), ("pymunk", "sphere"), ("pymunk", "aabb"))]
PID = 4242


def dump(out: Path, number: int, total: int, engine_object: str = "", inside: int = 0) -> None:
    """Dump ``number`` of process :data:`PID`: ``total`` instructions, ``inside`` of them in
    one call from the interpreter into ``engine_object``."""
    call = (f"cob={engine_object}\ncfn=entry\ncalls=1 0\n1 {inside}\n" if engine_object else "")
    text = (f"events: Ir\nob=/usr/lib/libpython3.11.so\nfn=loop\n1 {total - inside}\n{call}"
            f"totals: {total}\n")
    (out / f"cg.{PID}.{number}-{callgrind.QUERY_THREAD:02d}").write_text(text, encoding="utf-8")


def test_counted_figures_are_harness_over_raw_per_case_net_of_the_empty_loop(
        tmp_path: Path) -> None:
    fcl, chipmunk = "/venv/fcl.cpython-311-x86_64-linux-gnu.so", "/venv/_chipmunk.abi3.so"
    dump(tmp_path, 1, 1_000)  # the empty counting loop
    # fcl sphere, 100 cases: raw 2,000, engine path 2,500, harness 3,000 a case: +50%, met
    dump(tmp_path, 2, 201_000, fcl, 150_000)
    dump(tmp_path, 3, 251_000, fcl, 150_000)
    dump(tmp_path, 4, 301_000, fcl, 150_000)
    # pymunk aabb: raw 1,000, engine path 1,500, harness 4,000 a case: +300%, not met
    dump(tmp_path, 5, 101_000, chipmunk, 60_000)
    dump(tmp_path, 6, 151_000, chipmunk, 60_000)
    dump(tmp_path, 7, 401_000, chipmunk, 60_000)
    report = {"pid": PID, "cases": 100, "empty": 1, "streams": [
        {"engine": "fcl", "kind": "sphere", "objects": ["fcl.cpython-*.so"],
         "dumps": {"raw": 2, "engine path": 3, "harness": 4}},
        {"engine": "pymunk", "kind": "aabb", "objects": ["_chipmunk*.so"],
         "dumps": {"raw": 5, "engine path": 6, "harness": 7}}]}
    met, unmet = counted.figures_from(tmp_path, report, "valgrind-9.9")
    assert (met.name, unmet.name) == (NAMES[0], NAMES[3])
    assert (met.value, met.unit, met.target, met.ok, met.gating) == (50.0, "%", "<= 50%", True,
                                                                      True)
    assert (unmet.value, unmet.ok) == (300.0, False)
    d = met.detail
    assert (d["raw_instructions"], d["engine_path_instructions"], d["harness_instructions"]) == (
        2_000.0, 2_500.0, 3_000.0)
    assert d["engine_path_overhead_pct"] == 25.0
    assert (d["raw_engine_instructions"], d["harness_engine_instructions"]) == (1_500.0, 1_500.0)
    assert (d["cases"], d["empty_loop_instructions"], d["valgrind"]) == (100, 1_000, "valgrind-9.9")
    assert unmet.detail["engine_path_overhead_pct"] == 50.0
    assert unmet.detail["raw_engine_instructions"] == 600.0
    assert "raw 2,000, engine path 2,500 (+25%), harness 3,000" in met.note
    assert list(tmp_path.iterdir()) == []  # every dump deleted once read


def test_without_valgrind_every_counted_figure_is_nan_and_says_why(
        monkeypatch: pytest.MonkeyPatch) -> None:
    why = "valgrind is not installed: install Debian's valgrind to count instructions"
    monkeypatch.setattr(callgrind, "missing", lambda: why)
    figures = counted.counted_figures(3)
    assert [f.name for f in figures] == NAMES
    for f in figures:
        assert math.isnan(f.value) and not f.ok and f.gating
        assert f.note == f"not counted: {why}" and f.target == "<= 50%"


def test_a_failed_counting_process_gives_nan_figures_with_its_message(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # no valgrind needed: the "counting" command runs the interpreter directly
    monkeypatch.setattr(callgrind, "missing", lambda: None)
    monkeypatch.setattr(callgrind, "command", lambda python, out: list(python))
    monkeypatch.setattr(counted, "WORKER", "crosscheck.no_such_worker")
    figures = counted.counted_figures(3)
    assert [f.name for f in figures] == NAMES
    for f in figures:
        assert math.isnan(f.value) and not f.ok
        assert "the counting process failed (exit code 1)" in f.note
        assert "No module named crosscheck.no_such_worker" in f.note


def test_the_counted_streams_are_the_wall_clock_figures_streams() -> None:
    names = [f"harness overhead {s.engine} {s.kind}" for s in overhead_streams(0)]
    assert [f"{n}, counted instructions" for n in names] == NAMES
    assert counted.name("fcl", "sphere") == NAMES[0]


def the_paths(figures: Sequence[Figure]) -> list[tuple[float, float, float]]:
    return [(f.detail["raw_instructions"], f.detail["engine_path_instructions"],
             f.detail["harness_instructions"]) for f in figures]


@needs_valgrind
@pytest.mark.engine
def test_a_real_count_under_callgrind_gives_every_figure_with_counts() -> None:
    figures = counted.counted_figures(2)
    assert [f.name for f in figures] == NAMES
    for f, (raw, path, harness) in zip(figures, the_paths(figures), strict=True):
        assert math.isfinite(f.value), f.note
        assert raw > 0 and path > 0 and harness >= path, f.name
        assert f.detail["raw_engine_instructions"] > 0, f.name  # the engine's objects matched
        assert f.detail["cases"] == 2 and f.ok == (f.value <= 50.0)
        assert f.detail["valgrind"] == callgrind.version()
