"""A worker pool's batches (``WorkerPool.many``): every call answered in order, a crash or a
hang costing only the call it struck while the calls queued behind it go to a fresh worker,
variants sharing a worker warmed up between answers, a leaking worker recycled."""

from __future__ import annotations

from crosscheck.core.model import Status
from crosscheck.core.options import RunOptions
from crosscheck.run.execute import Call, Outcome, execute, run_calls
from crosscheck.run.worker import WorkerPool
from crosscheck.truth import oracle
from tests import fakes
from tests.conftest import sphere

OPTIONS = RunOptions(quick=True, timeout_s=20.0)


def batch(calls: list[Call], options: RunOptions = OPTIONS) -> tuple[list[Outcome], WorkerPool]:
    """The outcomes of ``calls`` on a fresh pool (closed after), and the pool, for its counts."""
    pool = WorkerPool(options)
    try:
        return run_calls(pool, calls), pool
    finally:
        pool.close()


def test_a_crash_in_a_batch_costs_its_call_and_the_rest_are_answered_by_a_fresh_worker(
) -> None:
    ids = ["c0", "c1", "boom", "c3", "c4"]
    cases = [sphere(0.0, 1.5 + k, id=name) for k, name in enumerate(ids)]
    outcomes, pool = batch([(fakes.CrashesOnSpheresAt(), case, OPTIONS, False, frozenset())
                            for case in cases])
    assert [o.status for o in outcomes] == [None, None, Status.CRASH, None, None]
    assert "SIGSEGV" in outcomes[2].reason
    for case, outcome in zip(cases, outcomes, strict=True):
        if case.id != "boom":
            assert outcome.observation == oracle.truth(case)
    assert pool.started == 2


def test_a_hang_in_a_batch_times_out_alone() -> None:
    options = RunOptions(quick=True, timeout_s=1.0)
    cases = [sphere(0.0, 2.0, id=f"c{k}") for k in range(3)]
    calls = [(fakes.AlwaysRight(), cases[0], options, False, frozenset()),
             (fakes.SleepsForever(), cases[1], options, False, frozenset()),
             (fakes.AlwaysRight(), cases[2], options, False, frozenset())]
    outcomes, _ = batch(calls, options)
    assert [o.status for o in outcomes] == [None, Status.TIMEOUT, None]
    assert outcomes[1].reason == "no answer within 1 s"
    assert outcomes[2].observation == oracle.truth(cases[2])


def test_variants_sharing_a_worker_answer_in_order_from_one_process() -> None:
    cases = [sphere(0.0, 1.0 + k, id=f"c{k}") for k in range(4)]
    calls = [(adapter, case, OPTIONS, False, frozenset())
             for case in cases for adapter in (fakes.AlwaysRight(), fakes.OffByOne())]
    outcomes, pool = batch(calls)
    right = [oracle.truth(case) for case in cases]
    assert [o.observation for o in outcomes[0::2]] == right
    off = [o.observation for o in outcomes[1::2]]
    assert all(o is not None and o.distance == t.distance + 1.0
               for o, t in zip(off, right, strict=True))
    assert pool.started == 1


def test_a_leaking_worker_is_recycled_within_a_batch_and_every_call_answers() -> None:
    options = RunOptions(quick=True, timeout_s=30.0, worker_memory_mb=400.0)
    cases = [sphere(0.0, 2.0, id=f"c{k}") for k in range(8)]  # 800 MB leaked in all
    outcomes, pool = batch([(fakes.Leaks(), case, options, False, frozenset())
                            for case in cases], options)
    assert [o.reason for o in outcomes] == [""] * 8
    assert all(o.observation is not None for o in outcomes)
    assert pool.recycled >= 1


def test_run_calls_in_process_answers_every_call_in_order() -> None:
    cases = [sphere(0.0, 1.0 + k, id=f"c{k}") for k in range(3)]
    outcomes = run_calls(execute, [(adapter, case, OPTIONS, False, frozenset())
                                   for case in cases
                                   for adapter in (fakes.AlwaysRight(), fakes.OffByOne())])
    assert [o.observation for o in outcomes[0::2]] == [oracle.truth(c) for c in cases]
    assert [o.observation.distance for o in outcomes[1::2] if o.observation] == [
        oracle.truth(c).distance + 1.0 for c in cases]
