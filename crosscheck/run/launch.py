"""One run into one folder, from start to finish: the one place that does it.

Every command that runs cases (``run``, ``run --resume``, ``stability``,
``fuzz``, ``bench``'s scale-out figure) goes through :func:`launch`: write
``cases.jsonl`` then ``run.json`` (so a folder with a run.json can always be
resumed), run every case x engine pair not yet done into the results
store, ask the disagreeing pairs again with ``repeat_check``
(:mod:`crosscheck.run.repeat`), time a sample, mark the run finished, close the store.
Rendering a report is a separate step (``crosscheck.report``), in the manner of asv's run
and publish.

:func:`launch` returns the folder as a :class:`~crosscheck.results.run.Run`, built once:
its rows are read after the verdict pass (``results.jsonl`` parsed once), and the same
object goes to the repeat check, the timing and cost phases and back to the caller (the
report, the summary, the baseline check), joined again to what each phase appended
(:meth:`~crosscheck.results.run.Run.refresh`).  It equals :func:`~crosscheck.results.run.read_run`
of the folder.

>>> import tempfile
>>> from pathlib import Path
>>> from crosscheck.core.schema import CASE_ADAPTER
>>> from crosscheck.results.run import read_run
>>> from crosscheck.results.store import ResultsStore
>>> from crosscheck.testing.fakes import AlwaysRight
>>> case = CASE_ADAPTER.validate_python({"id": "s", "description": "d", "kind": "sphere",
...     "dim": 2, "a": {"center": [0, 0], "radius": 0.5}, "b": {"center": [2, 0], "radius": 0.5}})
>>> folder = Path(tempfile.mkdtemp()) / "run"
>>> options = RunOptions(quick=True, isolate=False)
>>> run = launch(ResultsStore(folder), [case], [AlwaysRight()], options,
...              new_info(folder, "doctest", options, [AlwaysRight()], [case]))
>>> run.info.finished is not None, len(run.results), len(read_run(folder).results)
(True, 3, 3)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from crosscheck.core.contract import Adapter, engine_info
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.results.run import Run
from crosscheck.results.runinfo import RunInfo, now
from crosscheck.results.store import ResultsStore
from crosscheck.run import environment
from crosscheck.run.cost import cost_phase
from crosscheck.run.repeat import repeat_check
from crosscheck.run.runner import Progress, run_pending
from crosscheck.run.timing_phase import time_phase
from crosscheck.run.worker_process import preload


def new_info(directory: Path, command: str, options: RunOptions, engines: Sequence[Adapter],
             cases: Sequence[AnyCase], case_files: Sequence[Path | str] = (),
             case_errors: Sequence[str] = ()) -> RunInfo:
    """The run.json of a new run into ``directory``: started now, this machine, these engines."""
    return RunInfo(run_id=directory.name, command=command, options=options,
                   machine=environment.machine(),
                   engines=tuple(engine_info(a) for a in engines), started=now(),
                   case_files=tuple(str(p) for p in case_files), cases_run=len(cases),
                   case_errors=tuple(case_errors))


def pending(cases: Sequence[AnyCase], engines: Sequence[Adapter], store: ResultsStore) -> int:
    """How many case x engine pairs are still to run in ``store`` (all, unless resumed)."""
    return sum((c.id, a.name) not in store.done for c in cases for a in engines)


Phases = Callable[[str, int], Callable[[int], None]]
"""``phases(name, total)`` is called as a phase starts ("verdicts", "repeat check", "timing")
and returns
the function to call with the number of items each time some finish (a progress bar)."""


def launch(store: ResultsStore, cases: Sequence[AnyCase], engines: Sequence[Adapter],
           options: RunOptions, info: RunInfo, progress: Progress | None = None,
           phases: Phases | None = None) -> Run:
    """Write ``info`` as run.json, run what is left, time the sample, then mark it finished;
    the run folder as a :class:`~crosscheck.results.run.Run`.

    The verdict pass runs every case x engine pair not yet done (``progress``, or
    the ``"verdicts"`` phase, counts them); with ``options.repeat_check``, the repeat check
    then asks every disagreeing pair not yet asked again (the ``"repeat check"`` phase) and
    records its summary in run.json; unless the run is ``quick`` or its ``timing_cases``
    is 0, the timing phase then measures a sample in quiet
    (:mod:`crosscheck.run.timing_phase`) and, with ``options.timer == "instructions"``, the
    instruction timer counts the same sample (:mod:`crosscheck.run.cost`).  The store is
    closed in every case.  An
    interruption (Ctrl-C) propagates after the store is closed: every finished
    row and sample is on disk, run.json says the run did not finish, and
    ``crosscheck run --resume`` completes it.
    """
    preload(engines)
    run = Run(store.directory, info, {case.id: case for case in cases})
    try:
        store.add_cases(cases)  # before run.json: a folder with a run.json can be resumed
        store.write_run_info(info)
        if progress is None and phases is not None:
            progress = phases("verdicts", pending(cases, engines, store))
        run_pending(cases, engines, store, options, progress)
        if options.repeat_check:
            again = (lambda total: phases("repeat check", total)) if phases else None
            info = replace(info, repeat_check=repeat_check(store, run, engines, options,
                                                           again, info.repeat_check))
            store.write_run_info(info)  # kept if the timing phase is interrupted
            run.refresh()
        if not options.quick and options.timing_cases > 0:
            start = (lambda total: phases("timing", total)) if phases else None
            timing = time_phase(store, run, engines, options, start)
            info = replace(info, timing=timing)
            if options.timer == "instructions":
                store.write_run_info(info)  # the wall-clock samples are kept if interrupted
                run.refresh()  # the cost sample reads the timed scenes' medians
                count = (lambda total: phases("counting", total)) if phases else None
                timing = timing | {"cost": cost_phase(store, run, engines, options, count)}
                info = replace(info, timing=timing)
        info = info.finish()
        store.write_run_info(info)
    finally:
        store.close()
    run.refresh()
    return run
