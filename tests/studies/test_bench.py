"""``crosscheck bench`` at small sizes: every figure is produced and written; no measured
timing asserted (the figures' arithmetic is checked on injected times: ``best_of`` replaced,
or a fake ``clock``)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

import crosscheck.studies.bench as bench_package
from crosscheck.cli import main
from crosscheck.studies.bench import Figure
from crosscheck.studies.bench import comparison as bench_compare
from crosscheck.studies.bench import figures as bench
from crosscheck.studies.bench import suite as bench_suite
from crosscheck.studies.bench.kit import RECORDED
from crosscheck.studies.bench.oracle import values_benchmark
from tests.conftest import ROOT


def test_batch_figures_agree_with_the_pure_oracle() -> None:
    figures = bench.batch_figures(20_000)
    assert [f.name.split()[2].rstrip(":") for f in figures] == ["aabb", "sphere"]
    for f in figures:
        assert f.detail["agreement"] == 1.0
        assert f.detail["checked"] >= 200  # every near pair, plus a random sample
        assert f.detail["refined"] > 0 and f.detail["fallbacks"] == 0


def inject_best_of(monkeypatch: pytest.MonkeyPatch, seconds: list[float]) -> list[int]:
    """Replace the figures' ``best_of``: it runs the function once (the path still runs) and
    returns the next of ``seconds``; the list returned counts the calls."""
    given: Iterator[float] = iter(seconds)
    calls: list[int] = []

    def best_of(f: Callable[[], object], repeat: int = 3) -> float:
        f()
        calls.append(repeat)
        return next(given)

    monkeypatch.setattr(bench, "best_of", best_of)
    return calls


def fake_clock(*readings: float) -> Callable[[], float]:
    """A clock that gives ``readings`` in turn."""
    given = iter(readings)
    return lambda: next(given)


@pytest.mark.engine
def test_wall_clock_overhead_figures_measure_raw_engine_path_and_harness_and_never_gate(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # (raw, engine path, harness) seconds per figure: 50% or 100% over raw, recorded alike
    times = [(0.5, 0.625, 0.75), (0.5, 0.5, 1.0), (0.25, 0.375, 0.375), (1.0, 1.5, 2.0)]
    calls = inject_best_of(monkeypatch, [t for triple in times for t in triple])
    figures = bench.overhead_figures(60)
    assert len(calls) == 12
    assert [f.name for f in figures] == [
        "harness overhead fcl sphere", "harness overhead fcl aabb",
        "harness overhead pymunk sphere", "harness overhead pymunk aabb"]
    for f, (raw, path, harness) in zip(figures, times, strict=True):
        d = f.detail
        assert d["cases"] == 60
        assert (d["raw_us"], d["engine_path_us"], d["harness_us"]) == pytest.approx(
            (raw / 60 * 1e6, path / 60 * 1e6, harness / 60 * 1e6))
        assert f.value == pytest.approx((harness / raw - 1) * 100)
        assert d["engine_path_overhead_pct"] == pytest.approx((path / raw - 1) * 100)
    for f in figures:  # the counted figures judge the target; these are recorded only
        assert (f.ok, f.gating, f.target) == (True, False, "recorded, never gating")
        assert f.note.startswith("wall clock, never gating (the counted figure gates <= 50%)")


@pytest.mark.engine
def test_pybullet_stream_reports_memory_and_bodies(monkeypatch: pytest.MonkeyPatch) -> None:
    # raw loop 0.2 s (best of 3), harness on a tenth 0.05 s, the stream 3.0 -> 3.5 s
    calls = inject_best_of(monkeypatch, [0.2, 0.05])
    stream, memory = bench.pybullet_figures(400, clock=fake_clock(3.0, 3.5))
    assert calls == [3, 1]
    assert stream.detail["cases"] == 400 and stream.value == pytest.approx(0.5 / 0.2)
    assert stream.ok  # <= 3
    assert (stream.detail["raw_us"], stream.detail["engine_path_us"],
            stream.detail["harness_us"]) == pytest.approx((500.0, 1250.0, 1250.0))
    assert len(memory.detail["rss_mb"]) == 10
    # sphere detection builds no body: the client holds what it held before the stream
    # (other tests in this worker may have left idle pooled bodies in the shared client)
    assert memory.detail["bodies_left"] == memory.detail["bodies_before"]


def test_bench_json_round_trips(tmp_path: Path) -> None:
    figures = [Figure("x", 1.5, "x", ">= 1", True, {"n": 3}, note="n")]
    path = bench.write(figures, tmp_path, quick=True)
    data = json.loads(path.read_text())
    assert data["format_version"] == bench.FORMAT_VERSION
    assert data["quick"] is True and data["command"] == "crosscheck bench --quick"
    assert data["figures"] == [{"name": "x", "value": 1.5, "unit": "x", "target": ">= 1",
                                "ok": True, "detail": {"n": 3}, "note": "n", "gating": True}]
    assert "packages" in data["machine"]


def test_compare_refuses_an_unreadable_or_unknown_bench_before_measuring(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def measured(*args: object, **kwargs: object) -> None:
        pytest.fail("the bench started measuring before checking --compare")

    monkeypatch.setattr(bench, "measure", measured)
    future = tmp_path / "bench.json"
    future.write_text(json.dumps({"format_version": 99, "figures": []}))
    assert main(["bench", "--quick", "--compare", str(future)]) == 2
    assert main(["bench", "--quick", "--compare", str(tmp_path / "missing.json")]) == 2
    assert not (tmp_path / "reports").exists()


def test_compare_matches_figures_by_name_and_lists_machine_differences() -> None:
    old = {"format_version": 1, "machine": {"cpu": "a", "packages": {"numpy": "1"}},
           "figures": [{"name": "x", "value": 4.0, "unit": "s", "target": "", "ok": False}]}
    new = {"format_version": 2, "machine": {"cpu": "a", "packages": {"numpy": "2"}},
           "figures": [{"name": "x", "value": 2.0, "unit": "s", "target": "", "ok": True},
                       {"name": "y", "value": 1.0, "unit": "s", "target": "", "ok": True}]}
    result = bench_compare.compare(new, old)
    assert result.machine == ["numpy: 1 -> 2"]
    first = result.rows[0]
    assert (first.name, first.ratio, first.ok_old) == ("x", 0.5, False)
    assert math.isnan(result.rows[1].ratio) and result.rows[1].ok_old is None


def test_compare_reads_the_stored_older_bench_and_matches_the_wall_clock_figures_by_name(
        tmp_path: Path) -> None:
    # docs/bench.json as written at d918646, format 2 (before the counted figures), read as is
    stored = bench_compare.load(ROOT / "tests" / "data" / "bench-format2.json")
    assert stored["format_version"] == 2 < bench.FORMAT_VERSION
    figures = [Figure("harness overhead fcl sphere", 250.0, "%", "recorded, never gating",
                            True, gating=False),
               Figure("harness overhead fcl sphere, counted instructions", 260.0, "%",
                            "<= 50%", False)]
    new = json.loads(bench.write(figures, tmp_path, quick=True).read_text())
    wall, counted = bench_compare.compare(new, stored).rows
    old_wall = next(f for f in stored["figures"] if f["name"] == wall.name)
    assert (wall.old, wall.ok_old, wall.ok_new, wall.gating) == (
        old_wall["value"], old_wall["ok"], True, False)
    assert math.isnan(counted.old) and counted.ok_old is None and counted.gating
    assert bench_compare.load(tmp_path / "bench.json")["format_version"] == 3


@pytest.mark.engine
def test_spread_and_the_seven_variants_are_registered() -> None:
    s = bench_suite.spread([3.0, 1.0, 2.0, 4.0])
    assert (s["median"], s["min"], s["max"], s["n"]) == (2.5, 1.0, 4.0, 4.0)
    assert set(bench_suite.SEVEN) <= set(bench_suite.available())


def test_values_benchmark_checks_every_near_pair() -> None:
    r = values_benchmark(n=20_000, seed=1, sample=500)
    assert r["checked"] == r["near"] + 500 and r["identical"] == r["checked"]
    assert sum(r[k] for k in r if k.startswith("stage_")) == 20_000


def test_values_figure_checks_every_near_pair_bit_for_bit() -> None:
    figure = bench.values_figure(20_000)
    d = figure.detail
    assert d["near"] == 200 and d["checked"] == d["identical"] >= 200
    assert "near ones included" in figure.note and d["stage_exact"] >= 0


@pytest.mark.engine
def test_a_small_campaign_is_extrapolated_to_a_million_and_only_recorded() -> None:
    # injected: the 1,000 cases take 60 s, so a million take 1,000 minutes, over the 15
    figure = bench.campaign_figure(1_000, ["reference", "pymunk"], clock=fake_clock(5.0, 65.0))
    assert set(figure.detail["engine_cases_per_s"]) == {"reference", "pymunk"}
    assert figure.detail["n"] == 1_000 and figure.detail["peak_parent_mb"] > 0
    assert figure.detail["wall_s"] == 60.0
    assert figure.unit == "min" and figure.value == pytest.approx(1_000.0)
    assert "extrapolated" in figure.name and figure.target == RECORDED and figure.ok


@pytest.mark.engine
def test_the_target_campaign_is_judged_on_its_own_wall_time(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(bench, "MILLION", 1_000)  # this campaign stands for the million
    figure = bench.campaign_figure(1_000, ["reference"], clock=fake_clock(5.0, 65.0))
    assert "run to the end" in figure.name and figure.target == "<= 15 min"
    assert figure.value == pytest.approx(1.0) and figure.ok
    slow = bench.campaign_figure(1_000, ["reference"], clock=fake_clock(0.0, 960.0))
    assert slow.value == pytest.approx(16.0) and not slow.ok


def test_make_test_on_a_fresh_clone_is_read_from_its_measurement(tmp_path: Path) -> None:
    path = tmp_path / "setup.json"
    path.write_text(json.dumps({"make test": {
        "seconds": 250.0, "measured": "2026-12-05T00:00:00+00:00",
        "machine": {"git_commit": "abcdef1234567890"}}}))
    figure = bench_suite.fresh_clone_figure(path)
    assert figure.value == 250.0 and not figure.ok and "abcdef123456" in figure.note
    missing = bench_suite.fresh_clone_figure(tmp_path / "none.json")
    assert math.isnan(missing.value) and not missing.ok and "no measurement" in missing.note


def test_full_runs_and_campaign_size_reach_the_measurement_and_bad_ones_are_refused(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
        ) -> None:
    asked: list[dict[str, object]] = []

    def measured(quick: bool, **kwargs: object) -> list[Figure]:
        asked.append({"quick": quick, **kwargs})
        return []

    monkeypatch.setattr(bench_package, "measure", measured)  # what the command imports
    out = tmp_path / "b"
    assert main(["bench", "--full-runs", "1", "--campaign", "20000", "--out", str(out)]) == 0
    assert asked[0]["full_runs"] == 1 and asked[0]["campaign"] == 20_000
    assert not asked[0]["quick"] and (out / "bench.json").exists()
    for bad, named in ((["--full-runs", "0"], "--full-runs: 0 is under 1"),
                       (["--campaign", "999"], "--campaign: 999 is under 1,000"),
                       (["--campaign", "1e6"], "--campaign: '1e6' is not a whole number")):
        with pytest.raises(SystemExit) as stopped:
            main(["bench", *bad])
        assert stopped.value.code == 2 and named in capsys.readouterr().err
    assert len(asked) == 1
