"""The pytest plugin's suite: its options checked, one run into a folder, the run judged.

:class:`Suite` is registered as a plugin by :mod:`crosscheck.pytest_plugin` when
``--crosscheck-engine`` is given.  :meth:`Suite.from_config` checks every option before any
work (an unknown, refused or unavailable engine, a missing or bad case file, a bad baseline,
an output folder that already holds results: each a :class:`pytest.UsageError` naming the
option and the reason, so pytest exits with code 4).  At collection the session gets one
collector per engine (:mod:`crosscheck.pytest_plugin.items`); the first to collect runs the
suite once, for every engine, through :func:`crosscheck.run.launch.launch` with the engines
isolated in worker processes (a crash costs one row, never the session) and no timing
phase, then judges the rows with :func:`crosscheck.results.baseline.judge`, as
``crosscheck check`` does.  The run folder is kept and named in the terminal summary, so that
``crosscheck report DIR`` renders it.
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Generator
from pathlib import Path

import pytest

import adapters
import crosscheck
from crosscheck.cases.load import load_paths
from crosscheck.core.model import Kind, quantities_of
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import AnyCase
from crosscheck.pytest_plugin.engines import Engine, Ran
from crosscheck.pytest_plugin.items import EngineCollector
from crosscheck.results.baseline import Baseline, BaselineError, judge, read_baseline
from crosscheck.results.store import ResultsStore, StoreError
from crosscheck.run.launch import launch, new_info
from crosscheck.studies.repro import scripted

DEFAULT_CASES = Path(crosscheck.__file__).resolve().parent.parent / "cases"
"""The suite of the crosscheck checkout the package is installed from (if it is)."""


def _usage(option: str, reason: str) -> pytest.UsageError:
    return pytest.UsageError(f"{option}: {reason}")


def engine(name: str) -> Engine:
    """The engine called ``name``, made and available here; a UsageError saying why not."""
    option = f"--crosscheck-engine {name}"
    try:
        entry = adapters.find(name)
        cls = entry.load()
    except adapters.UnknownEngine as exc:  # RefusedEngine too: the reason is in its text
        raise _usage(option, str(exc)) from None
    try:
        adapter = cls()
        reason = adapter.available()
    except Exception as exc:  # a plug-in's fault is a reason, not a traceback
        reason = f"it fails: {type(exc).__name__}: {exc}"
    if reason:
        raise _usage(option, f"{entry.describe()} {entry.verdict}: {reason}")
    return Engine(name, adapter, entry.builtin)


def case_paths(given: list[str], here: Path) -> list[Path]:
    """The case files and folders to run: those given (relative to ``here``), else the
    checkout's ``cases/``; a UsageError if one is missing or there is none."""
    if not given:
        if DEFAULT_CASES.is_dir():
            return [DEFAULT_CASES]
        raise _usage("--crosscheck-cases", f"no case files: crosscheck's own cases/ folder is "
                     f"not beside the installed package ({DEFAULT_CASES}); pass "
                     f"--crosscheck-cases PATH (a case file or a folder of them)")
    paths = [here / p for p in given]
    missing = [str(p) for p in paths if not p.exists()]
    if missing:
        raise _usage("--crosscheck-cases", f"no such case file or folder: {', '.join(missing)}")
    return paths


def cases(paths: list[Path]) -> tuple[list[AnyCase], list[Path]]:
    """The cases under ``paths`` and their files; a UsageError listing the loader's messages
    (file, case, field, reason) if any file has an error, or if there is no case."""
    loaded = load_paths(paths)
    if loaded.errors:
        lines = "\n".join(f"  {error.message}" for error in loaded.errors)
        raise _usage("--crosscheck-cases", f"{len(loaded.errors)} error(s) in the case "
                     f"files; nothing was run:\n{lines}")
    if not loaded.cases:
        where = ", ".join(str(p) for p in paths)
        raise _usage("--crosscheck-cases", f"no case in {where}")
    return loaded.cases, loaded.files


class Suite:
    """The crosscheck suite of one pytest session: what the options name, checked, and the
    run made of it (once, at collection)."""

    def __init__(self, config: pytest.Config, engines: list[Engine], suite: list[AnyCase],
                 files: list[Path], baseline: tuple[Path, Baseline] | None,
                 out: Path | None) -> None:
        self.config, self.engines, self.cases, self.files = config, engines, suite, files
        self.baseline_file: Path | None = baseline[0] if baseline else None
        self.baseline: Baseline | None = baseline[1] if baseline else None
        self.out = out
        self.quick: bool = config.getoption("crosscheck_quick")
        self.sources = {case.id: case.source for case in suite}
        """Each case's file, by id: the location of its items."""
        self.order = {case.id: (i, quantities_of(Kind(case.kind))) for i, case in enumerate(suite)}
        """Each case's place in the suite and its kind's quantities, in order, by id."""
        self._ran: Ran | BaseException | None = None
        self._by_id = {case.id: case for case in suite}

    @classmethod
    def from_config(cls, config: pytest.Config) -> Suite:
        """Every option checked, before any work; a UsageError names the first bad one."""
        here = config.invocation_params.dir
        names: list[str] = list(dict.fromkeys(config.getoption("crosscheck_engine")))
        engines = [engine(name) for name in names]
        suite, files = cases(case_paths(config.getoption("crosscheck_cases"), here))
        baseline = None
        given: str | None = config.getoption("crosscheck_baseline")
        if given is not None:
            try:
                baseline = Path(given), read_baseline(here / given)
            except (BaselineError, OSError) as exc:
                raise _usage("--crosscheck-baseline", str(exc)) from None
        out_option: str | None = config.getoption("crosscheck_out")
        out = here / out_option if out_option is not None else None
        if out is not None and (out / "results.jsonl").exists():
            raise _usage("--crosscheck-out", f"{out} already holds results: choose another "
                         "folder (or delete it)")
        return cls(config, engines, suite, files, baseline, out)

    # --- the run ----------------------------------------------------------------------------

    def scripted(self, engine: Engine, case: str) -> bool:
        """Whether ``crosscheck repro`` writes a script of ``case`` on ``engine`` (its calls
        are a module and it makes this case as calls)."""
        known = self._by_id.get(case)
        return known is not None and scripted(engine.adapter, known)

    def ran(self) -> Ran:
        """The run and its findings: made the first time it is asked for, for every engine."""
        if self._ran is None:
            try:
                self._ran = self._run()
            except BaseException as exc:  # every collector reports the same failure
                self._ran = exc
                raise
        if isinstance(self._ran, BaseException):
            raise self._ran
        return self._ran

    def _folder(self) -> Path:
        if self.out is not None:
            return self.out
        factory = getattr(self.config, "_tmp_path_factory", None)  # the session's tmp_path
        if isinstance(factory, pytest.TempPathFactory):
            return factory.mktemp("crosscheck-run")
        raise pytest.UsageError("--crosscheck-out: pytest's temporary directory is not "
                                "available (-p no:tmpdir?); pass --crosscheck-out DIR")

    def _run(self) -> Ran:
        directory = self._folder()
        adapters_ = [e.adapter for e in self.engines]
        options = RunOptions(quick=self.quick, timing_cases=0, isolate=True,
                             jobs=os.cpu_count() or 1)
        command = shlex.join(["pytest", *self.config.invocation_params.args])
        self.say(f"crosscheck: running {len(self.cases)} cases x {len(self.engines)} "
                 f"engine(s) ({', '.join(e.name for e in self.engines)}) into {directory}")
        try:
            store = ResultsStore(directory)
            run = launch(store, self.cases, adapters_, options,
                         new_info(directory, command, options, adapters_, self.cases,
                                  self.files))
        except StoreError as exc:
            raise EngineCollector.CollectError(f"the crosscheck run failed: {exc}") from None
        names = [e.name for e in self.engines]
        found = judge(run.results, self.baseline, engines=names)
        return Ran(directory, {name: [f for f in found if f.engine == name] for name in names})

    def say(self, line: str) -> None:
        """A line on the terminal now, even while pytest captures the collection's output."""
        reporter = self.config.pluginmanager.get_plugin("terminalreporter")
        capture = self.config.pluginmanager.get_plugin("capturemanager")
        if reporter is None or self.config.get_verbosity() < 0:
            return
        if capture is None:
            reporter.write_line(line)
            return
        with capture.global_and_fixture_disabled():
            if reporter.isatty or self.config.get_verbosity() > 0:
                reporter.write("\n")  # after "collecting ... "
            reporter.write_line(line)

    # --- hooks ------------------------------------------------------------------------------

    @pytest.hookimpl(wrapper=True)
    def pytest_make_collect_report(
            self, collector: pytest.Collector
    ) -> Generator[None, pytest.CollectReport, pytest.CollectReport]:
        """The session's collection gets one collector per engine, after the files'."""
        report = yield
        if isinstance(collector, pytest.Session) and report.passed:
            report.result.extend(
                EngineCollector.from_parent(collector, suite=self, engine=e,
                                            name=f"crosscheck/{e.name}",
                                            nodeid=f"crosscheck/{e.name}")
                for e in self.engines)
        return report

    def pytest_terminal_summary(self, terminalreporter: pytest.TerminalReporter) -> None:
        """Where the run is, how to render it, and the findings by verdict."""
        if not isinstance(self._ran, Ran):
            return
        directory = self._ran.directory
        terminalreporter.write_sep("=", "crosscheck")
        terminalreporter.write_line(f"run folder: {directory}")
        terminalreporter.write_line(f"render its report with: crosscheck report {directory}")
        for name, findings in self._ran.findings.items():
            counts: dict[str, int] = {}
            for finding in findings:
                counts[str(finding.verdict)] = counts.get(str(finding.verdict), 0) + 1
            tally = ", ".join(f"{n} {verdict}" for verdict, n in counts.items()) or "none"
            terminalreporter.write_line(f"{name}: {len(findings)} findings: {tally}")
