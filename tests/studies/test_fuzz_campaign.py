"""Fuzz campaigns: chunks generated alone, a SIGKILL then --resume, crashes and hangs per case,
findings grouped in bounded memory, and the command line checked before any work."""

from __future__ import annotations

import csv
import json
import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, ClassVar

import dask
import pytest
from distributed import LocalCluster

from crosscheck.core.model import Kind, Observation
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.studies.fuzz import campaign as fuzz
from crosscheck.studies.fuzz import findings as findings_module
from crosscheck.studies.fuzz import generator as fuzzgen
from crosscheck.studies.fuzz.findings import Groups
from crosscheck.testing.fakes import AlwaysRight, OffByOne
from tests.conftest import ROOT, wait_until
from tests.studies.test_fuzz import fuzz_cli


def index(case: AnyCase) -> int:
    return int(case.id.rsplit("-", 1)[1])


class AbortsSometimes(AlwaysRight):
    """Right, but kills its process (SIGABRT) on every case whose index is 5 mod 700."""

    name: ClassVar[str] = "fake-aborts-sometimes"

    def query(self, prepared: Any) -> Observation:
        if index(prepared) % 700 == 5:
            os.abort()
        return super().query(prepared)


class HangsOnce(AlwaysRight):
    """Right, but never answers case 2."""

    name: ClassVar[str] = "fake-hangs-once"

    def query(self, prepared: Any) -> Observation:
        while index(prepared) == 2:
            time.sleep(0.05)
        return super().query(prepared)


def test_a_chunk_is_generated_alone_and_equals_that_slice_of_the_whole() -> None:
    n = fuzzgen.CHUNK + 12
    whole = fuzzgen.generate(Kind.SPHERE, n, seed=9)
    alone = fuzzgen.generate_chunk(Kind.SPHERE, 9, 1, n)
    assert [g.case for g in alone] == [g.case for g in whole[fuzzgen.CHUNK:]]
    assert [g.index for g in alone] == list(range(fuzzgen.CHUNK, n))
    first = fuzzgen.generate_chunk(Kind.SPHERE, 9, 0, 12)
    assert [g.case.description for g in first] != [g.case.description for g in alone[:12]]


def outputs(directory: Path) -> dict[str, Any]:
    """Everything a campaign leaves that must not depend on how it ran."""
    info = json.loads((directory / "fuzz.json").read_text())
    files = {p.name: p.read_text() for p in directory.glob("*.toml")}
    return {"csv": (directory / "findings.csv").read_text(), "files": files,
            "counts": info["counts"], "findings": info["findings"], "groups": info["groups"]}


ENGINES = (AlwaysRight, OffByOne)
N = 3 * fuzzgen.CHUNK
SCRIPT = """
import sys
from pathlib import Path
from crosscheck.core.model import Kind
from crosscheck.core.options import RunOptions
from crosscheck.studies.fuzz.campaign import fuzz
from crosscheck.testing.fakes import AlwaysRight, OffByOne
fuzz(Kind.SPHERE, {n}, 4, Path(sys.argv[1]), [AlwaysRight(), OffByOne()],
     RunOptions(quick=True, jobs=1), per_group=3, command="cmd")
"""


def made(names: Any) -> list[Any]:
    by_name = {cls.name: cls for cls in ENGINES}
    return [by_name[name]() for name in names]


@pytest.mark.slow
def test_a_campaign_killed_by_sigkill_resumes_to_the_outputs_of_an_uninterrupted_one(
        tmp_path: Path) -> None:
    killed = tmp_path / "killed"
    child = subprocess.Popen([sys.executable, "-c", SCRIPT.format(n=N), str(killed)], cwd=ROOT,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def chunk_written() -> bool:
        if (killed / "chunks").exists() and fuzz.finished_chunks(killed):
            return True
        assert child.poll() is None, "the campaign ended before it wrote a chunk"
        return False

    wait_until(chunk_written, "no chunk was written", timeout_s=120, poll_s=0.01)
    child.send_signal(signal.SIGKILL)
    child.wait()
    before = fuzz.finished_chunks(killed)
    assert 1 <= len(before) < 3 and not (killed / "fuzz.json").exists()  # killed mid-run
    with pytest.raises(fuzz.CampaignError, match="--resume"):
        fuzz.fuzz(Kind.SPHERE, N, 4, killed, made(["fake-right"]), RunOptions(quick=True))
    fuzz.resume(killed, made)
    info = json.loads((killed / "fuzz.json").read_text())
    assert info["chunks_before"] == len(before) and info["chunks_run"] == 3 - len(before)
    whole = tmp_path / "whole"
    fuzz.fuzz(Kind.SPHERE, N, 4, whole, [AlwaysRight(), OffByOne()],
              RunOptions(quick=True, jobs=2), per_group=3, command="cmd")
    assert outputs(killed) == outputs(whole)
    assert sum(info["counts"]["fake-off"].values()) == N * 3
    assert info["counts"]["fake-right"] == {"distance agree": N, "hit agree": N,
                                            "normal agree": N}


def read_csv(directory: Path) -> list[dict[str, str]]:
    with (directory / "findings.csv").open(encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def test_a_crash_or_a_hang_costs_its_own_case_only(tmp_path: Path) -> None:
    n = fuzzgen.CHUNK + 100
    fuzz.fuzz(Kind.SPHERE, n, 2, tmp_path / "out", [AbortsSometimes(), HangsOnce()],
              RunOptions(quick=True, jobs=2, timeout_s=1.0))
    info = json.loads((tmp_path / "out" / "fuzz.json").read_text())
    aborted = [i for i in range(n) if i % 700 == 5]
    assert info["counts"]["fake-aborts-sometimes"] == {
        f"{q} {s}": count for q in ("distance", "hit", "normal")
        for s, count in (("agree", n - len(aborted)), ("crash", len(aborted)))}
    assert info["counts"]["fake-hangs-once"] == {
        f"{q} {s}": count for q in ("distance", "hit", "normal")
        for s, count in (("agree", n - 1), ("timeout", 1))}
    rows = read_csv(tmp_path / "out")
    crashes = {(int(r["case_id"].rsplit("-", 1)[1]), r["reason"]) for r in rows
               if r["status"] == "crash"}
    assert crashes == {(i, "worker killed by SIGABRT") for i in aborted}
    assert {r["case_id"] for r in rows if r["status"] == "timeout"} == {"fuzz-sphere-s2-2"}
    assert len(rows) == 3 * (len(aborted) + 1)  # agreeing rows are counted, not stored


def test_streamed_groups_keep_the_largest_errors_and_count_every_finding(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(findings_module, "KEEP_GROUPS", 2)
    groups = Groups(per_group=3)  # keeps 6 candidates per group
    errors = [(i * 7919) % 101 / 10 for i in range(500)]
    for i, error in enumerate(errors):
        groups.add({"case_id": f"c-{i}", "engine": "e", "kind": "sphere", "quantity": "hit",
                    "status": "disagree", "category": "error", "family": "scaled",
                    "driver": "scale", "index": i, "error": error})
    [group] = groups.result()
    assert group.count == 500
    expected = sorted(range(500), key=lambda i: (-errors[i], i))[:6]
    assert [r["index"] for r in group.rows] == expected


@pytest.mark.parametrize(("argv", "message"), [
    (["--resume", "X", "--n", "5"], "--n would change it"),
    (["--kind", "sphere", "--n", "0", "--seed", "1"], "--n must be >= 1"),
    (["--kind", "sphere", "--n", "5", "--seed", "1", "--jobs", "0"], "--jobs must be >= 1"),
    (["--kind", "sphere", "--n", "5", "--seed", "1", "--timeout", "0"], "--timeout must be > 0"),
    (["--kind", "sphere", "--n", "5"], "--seed required"),
    (["--kind", "sphere", "--n", "5", "--seed", "1", "--shrink", "-1"], "--shrink must be >= 0"),
    (["--kind", "sphere", "--n", "5", "--seed", "1", "--shrink", "2", "--no-shrink"],
     "--shrink 2 and --no-shrink contradict"),
    (["--resume", "X", "--no-shrink"], "--no-shrink would change it"),
    (["--resume", "MISSING"], "is not a fuzz campaign"),
])
def test_bad_command_lines_are_refused_before_any_work(
        argv: list[str], message: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    argv = [str(tmp_path / a) if a in ("X", "MISSING") else a for a in argv]
    assert fuzz_cli(*argv) == 2
    assert message in " ".join(capsys.readouterr().err.split())
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_campaign_on_dask_gives_the_outputs_of_a_local_one(tmp_path: Path) -> None:
    n = 2 * fuzzgen.CHUNK + 50
    engines = [AbortsSometimes(), OffByOne()]
    local, remote = tmp_path / "local", tmp_path / "remote"
    fuzz.fuzz(Kind.SPHERE, n, 6, local, engines, RunOptions(quick=True, jobs=2), command="c")
    with (dask.config.set({"distributed.worker.daemon": False}),
          LocalCluster(n_workers=2, processes=True, threads_per_worker=1,  # type: ignore[no-untyped-call]
                       dashboard_address=None, silence_logs=logging.ERROR) as cluster):
        fuzz.fuzz(Kind.SPHERE, n, 6, remote, engines,
                  RunOptions(quick=True, jobs=2, scheduler=cluster.scheduler_address),
                  command="c")
    assert outputs(remote) == outputs(local)
    assert outputs(local)["counts"]["fake-aborts-sometimes"]["hit crash"] == 3  # 5, 705, 1405


def test_campaign_throughput_reports_every_engine_and_memory() -> None:
    readings = iter([100.0, 102.5])  # injected time: the 40 cases take 2.5 s
    figure = fuzz.campaign_throughput(40, [AlwaysRight(), OffByOne()], jobs=1,
                                      clock=lambda: next(readings))
    assert figure["n"] == 40 and figure["engines"] == ["fake-right", "fake-off"]
    assert set(figure["engine_cases_per_s"]) == {"fake-right", "fake-off"}
    assert (figure["wall_s"], figure["cases_per_s"]) == (2.5, 16.0)
    assert figure["peak_lanes_mb"] > 0
