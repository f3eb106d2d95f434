"""The instruction timer: what a callgrind dump counts, the counts it stores, and a cost
``compare`` that flags exactly the pairs whose work changed.  Nothing here measures time:
the counts are instructions, the same run after run."""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from crosscheck.compare.cost import cost_changes, judged, run_counts
from crosscheck.compare.runs import compare
from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.results.counts import FILE, CountRecord, read_counts, with_counts
from crosscheck.results.run import Run, read_run
from crosscheck.results.store import ResultsStore
from crosscheck.run import callgrind, cost
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import sphere

NO_VALGRIND = callgrind.missing()
needs_valgrind = pytest.mark.skipif(NO_VALGRIND is not None, reason=str(NO_VALGRIND))

ENGINE = "/venv/site-packages/pybullet.cpython-311-x86_64-linux-gnu.so"
DUMP = f"""events: Ir
ob=/usr/lib/libpython3.11.so
fn=_PyEval_EvalFrameDefault
1 500
cob={ENGINE}
cfn=pybullet_getClosestPointData
calls=10 0
1 40000
cob={ENGINE}
cfn=pybullet_getNumBodies
calls=10 0
1 2000
cfn=PyFloat_FromDouble
calls=30 0
1 900
ob={ENGINE}
fn=pybullet_getClosestPointData
1 30000
cfn=btGjkPairDetector
calls=10 0
1 9000
cob=/usr/lib/libpython3.11.so
cfn=PyFloat_FromDouble
calls=10 0
1 1000
totals: 43400
"""


def test_a_dump_counts_as_the_engine_only_the_calls_that_enter_its_objects() -> None:
    counts = callgrind.parse_dump(DUMP, ("pybullet*.so",))
    # 40,000 + 2,000 entered from libpython; the GJK call inside the engine is already in
    # them, and the interpreter's own float call is not the engine's
    assert counts == callgrind.Counts(total=43_400, engine=42_000)


def test_a_dump_with_compressed_names_counts_the_same() -> None:
    names: dict[str, str] = {}
    lines = []
    for line in DUMP.splitlines():  # callgrind's compression: "(id) name", then "(id)"
        key, sep, value = line.partition("=")
        if sep and key in ("ob", "cob"):
            first = value not in names
            names.setdefault(value, str(len(names) + 1))
            value = f"({names[value]}) {value}" if first else f"({names[value]})"
        lines.append(f"{key}{sep}{value}")
    compressed = "\n".join(lines)
    assert compressed.count(ENGINE) == 1 and "cob=(2)\n" in compressed
    assert callgrind.parse_dump(compressed, ("pybullet*.so",)) == callgrind.Counts(43_400, 42_000)


def test_a_dump_matches_objects_by_file_name_or_whole_path() -> None:
    by_path = callgrind.parse_dump(DUMP, ("/venv/site-packages/*",))
    assert by_path.engine == 42_000
    assert callgrind.parse_dump(DUMP, ("fcl*.so",)).engine == 0
    assert callgrind.parse_dump(DUMP, ()).engine == 0


def test_counts_are_read_per_query_net_of_the_empty_loop(tmp_path: Path) -> None:
    records = [CountRecord("a", "e", "sphere", "call", 10, 1_000_100, 100, 600_000),
               CountRecord("b", "e", "sphere", "call", 10, 500_100, 100)]
    text = "".join(r.to_json() + "\n" for r in records) + '{"case_id": "c", "eng'
    (tmp_path / FILE).write_text(text, encoding="utf-8")
    frame = read_counts(tmp_path).set_index("case_id")
    assert list(frame.index) == ["a", "b"]  # the half-written last line is skipped
    assert frame.loc["a", "query_instructions"] == 100_000.0
    assert frame.loc["a", "engine_instructions"] == 60_000.0
    assert frame["engine_instructions"].isna().tolist() == [False, True]  # b names no binding


def test_results_gain_the_count_columns_empty_where_nothing_was_counted(
        tmp_path: Path) -> None:
    rows = pd.DataFrame({"case_id": ["a", "z"], "engine": ["e", "e"]})
    empty = with_counts(rows.copy(), tmp_path)
    assert empty[["query_instructions", "engine_instructions"]].isna().all().all()
    (tmp_path / FILE).write_text(
        CountRecord("a", "e", "sphere", "call", 4, 400, 0, 200).to_json() + "\n")
    filled = with_counts(rows.copy(), tmp_path).set_index("case_id")
    assert filled.loc["a", "query_instructions"] == 100.0
    assert filled.loc["a", "engine_instructions"] == 50.0
    assert filled["query_instructions"].isna().tolist() == [False, True]


def test_a_cost_verdict_needs_a_move_beyond_the_threshold_either_way() -> None:
    assert judged(1000.0, 1009.0)[0] == "same"
    assert judged(1000.0, 1011.0)[0] == "more"
    assert judged(1000.0, 989.0)[0] == "less"
    assert judged(0.0, 10.0)[0] == "unknown"
    assert "+5.00%" in judged(1000.0, 1050.0)[1]


def test_a_counted_run_and_a_wall_clock_run_compare_no_cost(tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    for folder in (a, b):
        verdicts_and_wall_times(folder, fakes.BusyLoop()).close()
    (a / FILE).write_text(CountRecord("s0", "fake-busy", "sphere", "call", 1, 10, 0).to_json()
                          + "\n")
    result = compare(a, b, tmp_path / "cmp")
    assert result.cost_counts is None and result.cost_changes == 0
    assert "Not compared" in (tmp_path / "cmp" / "compare.html").read_text()


def test_a_run_without_counts_is_never_compared_with_one_that_has_them(tmp_path: Path) -> None:
    a = tmp_path / "a"
    a.mkdir()
    (a / FILE).write_text(CountRecord("s0", "e", "sphere", "call", 1, 10, 0).to_json() + "\n")
    b = tmp_path / "b"
    b.mkdir()

    class Folder:
        def __init__(self, directory: Path) -> None:
            self.directory = directory

    ra, rb = run_counts(Folder(a)), run_counts(Folder(b))  # type: ignore[arg-type]
    changes = cost_changes(ra, rb, {"s0"}, {"e"})
    assert list(changes["verdict"]) == ["unknown"]
    assert "B: no instructions counted" in changes["reason"].iloc[0]


def test_the_counting_command_runs_python_under_callgrind_without_counting_start_up(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(callgrind, "valgrind", lambda: "/usr/bin/valgrind")
    command = callgrind.command(["python", "-m", "x"], tmp_path)
    assert command[:2] == ["/usr/bin/valgrind", "--tool=callgrind"]
    assert "--instr-atstart=no" in command and command[-3:] == ["python", "-m", "x"]


def test_without_valgrind_the_timer_says_so_and_counts_nothing(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(callgrind, "valgrind", lambda: None)
    assert "valgrind is not installed" in str(callgrind.missing())
    store, engines = ResultsStore(tmp_path / "run"), [fakes.BusyLoop()]
    info = new_info(store.directory, "test", OPTIONS, engines, CASES)
    try:
        section = cost.cost_phase(store, Run(store.directory, info, {c.id: c for c in CASES}),
                                  engines, OPTIONS)
    finally:
        store.close()
    assert section["none"].startswith("valgrind is not installed")
    assert not (tmp_path / "run" / FILE).exists()


CASES = [sphere(0.0, 2.0 + i / 10, id=f"s{i}") for i in range(6)]
OPTIONS = RunOptions(min_sample_s=0.0005, samples=10, timing_cases=4, isolate=False,
                     timer="instructions")
RUNS = {"a": fakes.BusyLoop(), "again": fakes.BusyLoop(), "more": fakes.BusyLoopFivePercent()}


def verdicts_and_wall_times(folder: Path, engine: Adapter) -> ResultsStore:
    """A run's verdict pass and wall-clock phase, in this process; its store left open."""
    options = replace(OPTIONS, timer="wall")
    launch(ResultsStore(folder), CASES, [engine], options,
           new_info(folder, "test", options, [engine], CASES))
    return ResultsStore(folder, resume=True)


@pytest.fixture(scope="module")
def counted(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Three runs counted side by side (counts do not depend on the load: each counting
    worker pays its Valgrind start-up at once), and a library whose first pair kills its
    counting worker."""
    if NO_VALGRIND:
        pytest.skip(NO_VALGRIND)
    root = tmp_path_factory.mktemp("counted")
    stores = {name: verdicts_and_wall_times(root / name, engine)
              for name, engine in RUNS.items()}
    dying, hanging = ResultsStore(root / "dying"), ResultsStore(root / "hanging")
    library = cost.LibraryCounter(dying, OPTIONS, threading.Lock(), None, threading.Event())
    stuck = cost.LibraryCounter(hanging, replace(OPTIONS, timeout_s=0.05), threading.Lock(),
                                None, threading.Event())  # 0.05 s x SLOWDOWN: 5 s
    boom = sphere(0.0, 2.0, id="boom")
    with ThreadPoolExecutor(max_workers=5) as pool:
        sections = {name: pool.submit(cost.cost_phase, store, read_run(store.directory),
                                      [RUNS[name]], OPTIONS)
                    for name, store in stores.items()}
        died = pool.submit(library.count, [(boom, fakes.CrashesOnSpheresAt()),
                                           (CASES[0], fakes.BusyLoop())])
        hung = pool.submit(stuck.count, [(CASES[1], fakes.SleepsForever()),
                                         (CASES[0], fakes.BusyLoop())])
        out = {name: future.result() for name, future in sections.items()}
        died.result()
        hung.result()
    for store in [*stores.values(), dying, hanging]:
        store.close()
    return {"root": root, "sections": out, "failed": library.failed, "hung": stuck.failed}


@needs_valgrind
def test_identical_cost_runs_flag_nothing_and_five_percent_more_work_is_flagged_everywhere(
        counted: dict[str, Any]) -> None:
    root = counted["root"]
    section = counted["sections"]["a"]
    assert section["counted"] == 4 and section["failed"] == 0
    results = read_run(root / "a").results.drop_duplicates("case_id")
    assert results["query_instructions"].notna().sum() == 4  # the sampled pairs, filled

    same = compare(root / "a", root / "again", root / "cmp-same")
    assert same.cost_counts == {"more": 0, "less": 0, "same": 4, "unknown": 0}
    more = compare(root / "a", root / "more", root / "cmp-more")
    assert more.cost_counts == {"more": 4, "less": 0, "same": 0, "unknown": 0}
    changed = pd.read_csv(root / "cmp-more" / "cost_changes.csv")
    assert set(changed["verdict"]) == {"more"} and "more work" in (
        root / "cmp-more" / "compare.html").read_text()
    ratios = list(changed["ratio"])
    assert all(1.03 < r < 1.06 for r in ratios), ratios  # 5% more loop, the rest fixed


@needs_valgrind
def test_a_counting_worker_that_dies_costs_one_pair_and_the_next_is_counted(
        counted: dict[str, Any]) -> None:
    assert list(counted["failed"]) == ["boom x fake-boom"]
    assert "died" in counted["failed"]["boom x fake-boom"]
    assert set(read_counts(counted["root"] / "dying")["case_id"]) == {"s0"}


@needs_valgrind
def test_a_counting_worker_that_does_not_answer_is_stopped_and_the_next_pair_is_counted(
        counted: dict[str, Any]) -> None:
    assert list(counted["hung"]) == ["s1 x fake-hangs"]
    assert counted["hung"]["s1 x fake-hangs"].startswith("no answer within 5 s under callgrind")
    assert set(read_counts(counted["root"] / "hanging")["case_id"]) == {"s0"}
