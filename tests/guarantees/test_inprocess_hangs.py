"""``--no-isolation``: a declared known hang is never run in-process (its quantities are
``skip`` rows naming the declaration), and Ctrl-C stops an in-process run between cases.

Nothing can stop an engine stuck in this process, so every check that would hang if the
guarantee broke runs where it can be given up on: a daemon thread, or a subprocess.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

import pandas as pd
import pytest

import adapters
from crosscheck.cases.load import load_paths
from crosscheck.core.contract import Adapter
from crosscheck.core.options import RunOptions
from crosscheck.results.run import read_results
from crosscheck.results.store import ResultsStore
from crosscheck.run.lanes import LocalLanes
from crosscheck.run.runner import run
from tests import fakes
from tests.conftest import ROOT, ctrl_c_delivered, lines_in, sphere, wait_until

CASES = [sphere(0.0, 2.0, id="before"), sphere(0.0, 1.5, id="boom"), sphere(0.0, 3.0, id="after")]
SKIPPED = "declared known hang, not run in-process (--no-isolation has no time limit to stop it): "


def run_in_process(tmp_path: Path, engine: Adapter) -> pd.DataFrame:
    """``run`` with ``isolate`` False, in a daemon thread: a hang fails the test, not the suite."""
    store = ResultsStore(tmp_path / "run")
    options = RunOptions(quick=True, isolate=False, jobs=1)
    thread = threading.Thread(target=run, args=(CASES, [engine], store, options), daemon=True)
    thread.start()
    thread.join(timeout=60)
    assert not thread.is_alive(), "a declared known hang was run in-process and never returned"
    store.close()
    return read_results(tmp_path / "run")


def rows(frame: pd.DataFrame, case_id: str) -> dict[str, tuple[str, str]]:
    part = frame[frame["case_id"] == case_id]
    return {str(q): (str(s), str(r))
            for q, s, r in zip(part["quantity"], part["status"], part["reason"], strict=True)}


def test_a_declared_hang_is_skipped_in_process_naming_the_declaration(tmp_path: Path) -> None:
    frame = run_in_process(tmp_path, fakes.DeclaresHangs())
    skipped = ("skip", SKIPPED + "stuck in a loop")
    for case_id in ("boom", "after"):  # 'after' is declared too: in-process it is not tried
        assert rows(frame, case_id) == dict.fromkeys(("hit", "distance", "normal"), skipped)
    assert set(rows(frame, "before").values()) == {("agree", "")}


def test_only_the_declared_hanging_quantities_are_skipped(tmp_path: Path) -> None:
    frame = run_in_process(tmp_path, fakes.HangsOnDistance())
    assert rows(frame, "boom") == {"hit": ("agree", ""), "normal": ("agree", ""),
                                   "distance": ("skip", SKIPPED + "distance loops")}


FCL_IN_PROCESS = """
import json, sys
from pathlib import Path
import adapters
from crosscheck.core.options import RunOptions
from crosscheck.results.store import ResultsStore
from crosscheck.results.run import read_results
from crosscheck.run.runner import run
from tests.conftest import sphere
store = ResultsStore(Path(sys.argv[1]))
run([sphere(0.0, 0.0, ra=1.0, rb=0.5, id="coincident")], [adapters.get("fcl")], store,
    RunOptions(quick=True, isolate=False))
store.close()
frame = read_results(Path(sys.argv[1]))
print(json.dumps(dict(zip(frame["quantity"], zip(frame["status"], frame["reason"])))))
"""


@pytest.mark.engine
def test_fcl_in_process_skips_its_hanging_signed_distance_and_answers_the_rest(
        tmp_path: Path) -> None:
    pytest.importorskip("fcl")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    try:  # FCL's hang holds the GIL: only a subprocess can be given up on
        done = subprocess.run([sys.executable, "-c", FCL_IN_PROCESS, str(tmp_path / "run")],
                              capture_output=True, text=True, env=env, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail("fcl's signed distance of coincident spheres was run in-process: it hung")
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout)
    assert found["distance"][0] == "skip"
    assert found["distance"][1].startswith(SKIPPED + "fcl's signed distance loops")
    assert found["hit"] == ["agree", ""]


@pytest.mark.parametrize("jobs", [1, 2])
@pytest.mark.usefixtures("ctrl_c_raises")
def test_ctrl_c_stops_in_process_lanes_between_items(jobs: int) -> None:
    started: list[int] = []
    lock = threading.Lock()

    def slow(item: int, _: object) -> int:
        with lock:
            started.append(item)
        if item == 2:
            os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.3)  # a Ctrl-C raised here would lose an item already begun
        return item

    finished: list[int] = []
    with pytest.raises(KeyboardInterrupt), LocalLanes(RunOptions(isolate=False, jobs=jobs)) \
            as lanes:
        finished.extend(lanes.map(slow, range(20)))
    assert sorted(finished) == sorted(started)  # every item begun was finished and yielded
    assert 2 in finished and len(started) < 20  # and the rest never started
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def plugin(site: Path) -> dict[str, str]:
    """An environment where the slow fake is an installed engine (a bare .dist-info)."""
    info = site / "crosscheck_fake_slow-0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: crosscheck-fake-slow\n"
                                   "Version: 0\n", encoding="utf-8")
    (info / "entry_points.txt").write_text(
        f"[{adapters.ENTRY_POINT_GROUP}]\n"
        "fake-slow = crosscheck.testing.fakes:SlowWithDeclaredHang\n", encoding="utf-8")
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}


def case_file(path: Path, count: int, stuck_at: int) -> Path:
    blocks = []
    for i in range(count):
        case_id = "stuck" if i == stuck_at else f"c{i:03d}"
        blocks.append(f'[[case]]\nid = "{case_id}"\ndescription = "d"\nkind = "sphere"\n'
                      f"dim = 3\na = {{ center = [0.0, 0.0, 0.0], radius = 0.5 }}\n"
                      f"b = {{ center = [{1 + i / count}, 0.0, 0.0], radius = 0.5 }}\n")
    path.write_text("\n".join(blocks), encoding="utf-8")
    return path


def wait_for_lines(path: Path, lines: int) -> None:
    wait_until(lambda: lines_in(path) >= lines, f"{path} never reached {lines} lines",
               timeout_s=120)


def whole_cases(out: Path) -> Counter[str]:
    """Rows per case in results.jsonl, every line whole JSON (3 rows a case)."""
    text = (out / "results.jsonl").read_text(encoding="utf-8")
    assert text.endswith("\n")
    return Counter(json.loads(line)["case_id"] for line in text.splitlines())


@pytest.mark.slow
def test_ctrl_c_stops_an_in_process_run_with_a_declared_hang_and_resume_finishes_it(
        tmp_path: Path) -> None:
    env = plugin(tmp_path / "site")
    cases, out = case_file(tmp_path / "cases.toml", count=60, stuck_at=4), tmp_path / "run"
    cli = [sys.executable, "-m", "crosscheck.cli", "run"]
    process = subprocess.Popen([*cli, str(cases), "--engine", "fake-slow", "--no-isolation",
                                "--jobs", "2", "--quick", "--out", str(out)],
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True,
                               preexec_fn=ctrl_c_delivered, cwd=ROOT)
    try:
        wait_for_lines(out / "results.jsonl", 3 * 8)  # past the declared hang
        os.killpg(process.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole group
        _, stderr = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail("Ctrl-C did not stop the in-process run")
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert process.returncode == 130, stderr
    assert f"crosscheck run --resume {out}" in stderr.replace("\n", "")
    assert "stopping after the cases in flight (Ctrl-C again to stop at once)" in stderr
    kept = whole_cases(out)
    assert set(kept.values()) == {3} and 8 <= len(kept) < 120  # whole cases; it stopped
    stuck = read_results(out).query("case_id == 'stuck'")
    assert set(stuck["status"]) == {"skip"}
    assert set(stuck["reason"]) == {SKIPPED + "loops on 'stuck', deaf to Ctrl-C"}
    resumed = subprocess.run([*cli, "--resume", str(out)], env=env, capture_output=True,
                             text=True, timeout=300, cwd=ROOT)
    assert resumed.returncode == 0, resumed.stderr
    every = {c.id for c in load_paths([cases]).cases}  # with their swapped twins
    assert whole_cases(out) == Counter(dict.fromkeys(every, 3))
