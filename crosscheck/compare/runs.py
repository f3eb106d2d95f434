"""Compare two stored runs: first what differs between them, then verdicts and timings.

Typical use: the same suite before and after an engine upgrade.  Up front,
before judging anything, the comparison says how the runs differ: cases only
in A (``removed``) or only in B (``added``), engines in one run only, options,
engine versions and machines.  Verdicts and timings are then compared on the
overlap only (the cases and engines both runs have): a verdict is a row's
status and category.  Cost comes next: where both runs counted instructions
(``--timer instructions``), a pair's cost change is judged on its counts
(:mod:`crosscheck.compare.cost`), deterministic, with no statistics; a
count is never compared with a wall time.  The wall-clock change of each case x
engine is judged on its stored samples (:mod:`crosscheck.compare.timing`)
and recorded beside.  Added and removed cases are counted apart, never as
verdict changes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path

import pandas as pd

from crosscheck.compare import cost as compare_cost
from crosscheck.compare.timing import (
    ALPHA,
    MIN_EFFECT,
    VERDICTS,
    engine_summary,
    normalisation,
    run_timings,
    timing_changes,
)
from crosscheck.report.style import templates
from crosscheck.results.run import Run, read_run
from crosscheck.results.runinfo import RunInfo
from crosscheck.results.timings import MIN_SAMPLES

KEY = ["case_id", "engine", "quantity"]


def verdict_changes(a: pd.DataFrame, b: pd.DataFrame) -> pd.DataFrame:
    """Rows present in both runs whose status or category differ.

    Pass the overlap of the two runs (:func:`shared_rows`): rows in one run only
    are not verdict changes.
    """
    cols = [*KEY, "status", "category", "value", "error"]
    both = a[cols].merge(b[cols], on=KEY, how="inner", suffixes=("_a", "_b"))
    same = (both["status_a"] == both["status_b"]) & (
        both["category_a"].fillna("") == both["category_b"].fillna(""))
    return both[~same].reset_index(drop=True)


def case_ids(run: Run) -> set[str]:
    """The cases of a run: its stored cases and any case its results name."""
    return set(run.cases) | set(run.results["case_id"])


def engine_names(run: Run) -> list[str]:
    """The engines of a run, in run order (and any engine its results name)."""
    return list(dict.fromkeys([*run.info.engine_names, *run.results["engine"]]))


def shared_rows(frame: pd.DataFrame, cases: set[str], engines: set[str]) -> pd.DataFrame:
    """The rows of ``frame`` among ``cases`` x ``engines``."""
    return frame[frame["case_id"].isin(cases) & frame["engine"].isin(engines)]


def option_differences(a: RunInfo, b: RunInfo) -> list[str]:
    """The run options that differ, one ``name: A vs B`` line each.

    >>> from crosscheck.core.options import RunOptions
    >>> run = RunInfo("r", "c", RunOptions(), {}, (), "t")
    >>> option_differences(run, RunInfo("s", "c", RunOptions(samples=5), {}, (), "t"))
    ['samples: 10 vs 5']
    """
    return [f"{f.name}: {getattr(a.options, f.name)!r} vs {getattr(b.options, f.name)!r}"
            for f in fields(a.options)
            if getattr(a.options, f.name) != getattr(b.options, f.name)]


def _versions(info: RunInfo) -> dict[str, str]:
    return {str(e["name"]): str(e["version"]) for e in info.engines}


def version_table(a: RunInfo, b: RunInfo) -> list[dict[str, str]]:
    """Every engine of either run with its version in A and in B ('-': not in that run)."""
    va, vb = _versions(a), _versions(b)
    return [{"engine": name, "a": va.get(name, "-"), "b": vb.get(name, "-")}
            for name in dict.fromkeys([*va, *vb])]


def version_differences(a: RunInfo, b: RunInfo) -> list[str]:
    """Engines run in both whose versions differ, one ``engine: A vs B`` line each."""
    return [f"{v['engine']}: {v['a']} vs {v['b']}" for v in version_table(a, b)
            if "-" not in (v["a"], v["b"]) and v["a"] != v["b"]]


MACHINE_KEYS = ("cpu", "cores", "python", "implementation", "platform", "packages")
"""What must match for two runs' timings to be comparable (pyperf's compare checks the same)."""


def machine_differences(a: RunInfo, b: RunInfo) -> list[str]:
    """How the two runs' machines differ, one line per key (empty: the same machine).

    >>> from crosscheck.core.options import RunOptions
    >>> run = RunInfo("r", "c", RunOptions(), {"cpu": "x", "cores": 2}, (), "t")
    >>> machine_differences(run, run)
    []
    >>> machine_differences(run, RunInfo("s", "c", RunOptions(), {"cpu": "y", "cores": 2}, (), "t"))
    ["cpu: 'x' vs 'y'"]
    """
    return [f"{key}: {a.machine.get(key)!r} vs {b.machine.get(key)!r}" for key in MACHINE_KEYS
            if a.machine.get(key) != b.machine.get(key)]


@dataclass(frozen=True)
class Comparison:
    """What :func:`compare` found and wrote: the differences up front, then the judgements."""

    added_cases: list[str]
    """Cases only in B, sorted."""
    removed_cases: list[str]
    """Cases only in A, sorted."""
    shared_cases: int
    added_engines: list[str]
    removed_engines: list[str]
    option_differences: list[str]
    version_differences: list[str]
    machine_differences: list[str]
    unmatched_rows: int
    """Rows of shared cases x engines present in one run only (a run cut short): not compared."""
    shared_rows: int
    """Rows (case x engine x quantity) present in both runs: what verdicts are compared on."""
    verdict_changes: int
    timing_counts: dict[str, int]
    """Timed pairs of the overlap per verdict: slower, faster, same, unknown."""
    normalised: bool
    """Whether timings were set against the machine yardstick: per round (both runs timed in
    rounds), or B's divided by the runs' yardstick ratio (both runs have a steady one)."""
    normalisation: str
    yardstick_doubts: list[str]
    """Per run whose yardstick is unsteady: ``"A: why"`` (the normalisation is as uncertain)."""
    samples_missing: list[str]
    """Per run without stored samples: ``"A: why"``."""
    out: Path
    timers: tuple[str, str] = ("wall", "wall")
    """The timer each run used (``--timer``): ``wall`` or ``instructions``."""
    cost_counts: dict[str, int] | None = None
    """Counted pairs of the overlap per cost verdict (more, less, same, unknown); None when
    either run counted nothing (then only wall-clock timing is compared)."""

    @property
    def cost_threshold(self) -> float:
        """The share of instructions per query beyond which a counted pair has changed."""
        return compare_cost.THRESHOLD

    @property
    def cost_changes(self) -> int:
        """Pairs whose counted instructions moved beyond the threshold (0 if not counted)."""
        counts = self.cost_counts or {}
        return counts.get("more", 0) + counts.get("less", 0)

    @property
    def cost_pairs(self) -> int:
        return sum((self.cost_counts or {}).values())

    @property
    def timing_changes(self) -> int:
        """Pairs judged slower or faster."""
        return self.timing_counts["slower"] + self.timing_counts["faster"]

    @property
    def timing_pairs(self) -> int:
        return sum(self.timing_counts.values())

    @property
    def differences(self) -> list[str]:
        """How the runs differ, one sentence each, to read before any verdict or timing."""
        lines = []
        if self.added_cases or self.removed_cases:
            lines.append(f"case sets differ: {len(self.removed_cases)} only in A (removed), "
                         f"{len(self.added_cases)} only in B (added); verdicts and timings "
                         f"compare the {self.shared_cases} shared cases only")
        for name, engines in (("A", self.removed_engines), ("B", self.added_engines)):
            if engines:
                lines.append(f"engines only in {name} (not compared): {', '.join(engines)}")
        lines += [f"options differ: {d}" for d in self.option_differences]
        lines += [f"engine versions differ: {d}" for d in self.version_differences]
        lines += [f"the runs come from different machines: {d}; timing changes below may be "
                  "the machines', not the engines'" for d in self.machine_differences]
        if self.unmatched_rows:
            lines.append(f"{self.unmatched_rows} rows of shared cases and engines are in one "
                         "run only (a run cut short?): not compared")
        if self.timers[0] != self.timers[1]:
            lines.append(f"timers differ: A {self.timers[0]}, B {self.timers[1]}: counted "
                         "instructions are not compared, only wall-clock timings")
        lines += [f"{m}: every timing pair is unknown" for m in self.samples_missing]
        if not self.normalised and not self.samples_missing:
            lines.append(self.normalisation)
        return lines


def _differences(run_a: Run, run_b: Run) -> dict[str, list[str]]:
    ca, cb = case_ids(run_a), case_ids(run_b)
    ea, eb = engine_names(run_a), engine_names(run_b)
    return {"added_cases": sorted(cb - ca), "removed_cases": sorted(ca - cb),
            "added_engines": [e for e in eb if e not in ea],
            "removed_engines": [e for e in ea if e not in eb],
            "option_differences": option_differences(run_a.info, run_b.info),
            "version_differences": version_differences(run_a.info, run_b.info),
            "machine_differences": machine_differences(run_a.info, run_b.info)}


def _unmatched(a: pd.DataFrame, b: pd.DataFrame) -> tuple[int, int]:
    """Rows of the overlap in one run only, and rows in both."""
    both = a[KEY].merge(b[KEY], on=KEY, how="outer", indicator=True)
    shared = int((both["_merge"] == "both").sum())
    return len(both) - shared, shared


def compare(dir_a: Path, dir_b: Path, out: Path) -> Comparison:
    """Compare two runs; write verdict_changes.csv, case_changes.csv, cost_changes.csv,
    cost_engines.csv, timing_changes.csv, timing_engines.csv and compare.html into ``out``."""
    run_a, run_b = read_run(dir_a), read_run(dir_b)
    differences = _differences(run_a, run_b)
    cases = case_ids(run_a) & case_ids(run_b)
    engines = set(engine_names(run_a)) & set(engine_names(run_b))
    rows_a = shared_rows(run_a.results, cases, engines)
    rows_b = shared_rows(run_b.results, cases, engines)
    verdicts = verdict_changes(rows_a, rows_b)
    unmatched, shared = _unmatched(rows_a, rows_b)
    ta, tb = run_timings(run_a), run_timings(run_b)
    method = normalisation(ta, tb)
    timings = timing_changes(ta, tb, cases, engines, method.scale)
    order = [e for e in engine_names(run_a) if e in engines]
    per_engine = engine_summary(timings, order)
    ca, cb = compare_cost.run_counts(run_a), compare_cost.run_counts(run_b)
    costs = compare_cost.cost_changes(ca, cb, cases, engines)
    counted = not (ca.missing or cb.missing)
    result = Comparison(
        **differences, shared_cases=len(cases), unmatched_rows=unmatched, shared_rows=shared,
        verdict_changes=len(verdicts),
        timing_counts={v: int((timings["verdict"] == v).sum()) for v in VERDICTS},
        normalised=method.normalised, normalisation=method.text,
        yardstick_doubts=[f"{name}: {run.doubt}" for name, run in (("A", ta), ("B", tb))
                          if run.doubt],
        samples_missing=[f"{name}: {run.missing}" for name, run in (("A", ta), ("B", tb))
                         if run.missing],
        out=out, timers=(run_a.info.options.timer, run_b.info.options.timer),
        cost_counts=({v: int((costs["verdict"] == v).sum()) for v in compare_cost.VERDICTS}
                     if counted else None))
    _write(result, run_a, run_b, verdicts, timings, per_engine,
           (costs, compare_cost.cost_summary(costs, order)))
    return result


def _write(result: Comparison, run_a: Run, run_b: Run, verdicts: pd.DataFrame,
           timings: pd.DataFrame, per_engine: pd.DataFrame,
           costs: tuple[pd.DataFrame, pd.DataFrame]) -> None:
    """The CSV tables and compare.html (cost: the pairs and the per-engine summary)."""
    out = result.out
    out.mkdir(parents=True, exist_ok=True)
    verdicts.to_csv(out / "verdict_changes.csv", index=False)
    pd.DataFrame([*({"case_id": c, "change": "added"} for c in result.added_cases),
                  *({"case_id": c, "change": "removed"} for c in result.removed_cases)],
                 columns=["case_id", "change"]).to_csv(out / "case_changes.csv", index=False)
    timings.to_csv(out / "timing_changes.csv", index=False)
    per_engine.to_csv(out / "timing_engines.csv", index=False)
    costs[0].to_csv(out / "cost_changes.csv", index=False)
    costs[1].to_csv(out / "cost_engines.csv", index=False)
    changed = timings[timings["verdict"].isin(["slower", "faster"])]
    html = templates().get_template("compare.html.j2").render(
        a=str(run_a.directory), b=str(run_b.directory), c=result,
        verdicts=verdicts.to_dict("records"), timings=changed.to_dict("records"),
        per_engine=per_engine.to_dict("records"),
        costs=costs[0][costs[0]["verdict"].isin(["more", "less"])].to_dict("records"),
        cost_engines=costs[1].to_dict("records"),
        versions=version_table(run_a.info, run_b.info), alpha=ALPHA, min_effect=MIN_EFFECT,
        min_samples=MIN_SAMPLES, isnan=math.isnan)
    (out / "compare.html").write_text(html, encoding="utf-8")
