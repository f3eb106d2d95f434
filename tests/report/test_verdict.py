"""The verdict block: agreeing shares per kind, speed ranks, ranking and grouped failure modes.

Every frame is built by hand here; each expectation is counted from the rows of the test.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from crosscheck.core.model import Status
from crosscheck.report import verdict
from crosscheck.report.style import templates
from crosscheck.results.store import repro_name, written_repros

NAN = math.nan
EVIL = "<script>alert('pwned')</script>"
TOO_FAR = ("error 1.2e-06 beyond the agree bound 3.5e-15 (size 1)",
           "error 4e-07 beyond the agree bound 2e-15 (size 4)")


def row(case_id: str, kind: str, engine: str, quantity: str, status: str = "agree",
        category: str = "", reason: str = "", query_s: float = NAN) -> dict[str, Any]:
    return {"case_id": case_id, "kind": kind, "engine": engine, "quantity": quantity,
            "status": status, "category": category, "reason": reason, "query_s": query_s}


def frame() -> pd.DataFrame:
    """Three engines: ``good`` agrees everywhere, ``bad`` disagrees on distances and crashes
    on boxes, ``boxonly`` does boxes only (skips spheres and responses)."""
    rows = []
    for case_id in ("s1", "s2"):
        rows += [row(case_id, "sphere", "good", q, query_s=1e-6) for q in ("hit", "distance")]
    rows += [row("b1", "aabb", "good", q, query_s=2e-6) for q in ("hit", "distance")]
    rows += [row("r1", "sphere_response", "good", "v1", query_s=3e-6),
             row("r1", "sphere_response", "good", "v2", "undefined", query_s=3e-6)]
    for case_id, reason in zip(("s1", "s2"), TOO_FAR, strict=True):
        rows += [row(case_id, "sphere", "bad", "hit", query_s=1e-5),
                 row(case_id, "sphere", "bad", "distance", "disagree", "error", reason, 1e-5)]
    rows += [row("b1", "aabb", "bad", q, "crash", reason="worker killed by SIGSEGV")
             for q in ("hit", "distance", "normal")]
    rows += [row("r1", "sphere_response", "bad", q, "skip") for q in ("v1", "v2")]
    rows += [row(c, "sphere", "boxonly", q, "skip")
             for c in ("s1", "s2") for q in ("hit", "distance")]
    rows += [row("b1", "aabb", "boxonly", "hit", query_s=1e-7),
             row("b1", "aabb", "boxonly", "distance", "disagree", "tolerance",
                 "|gap| 1e-17 within the engine's declared tolerance 2e-15", 1e-7)]
    rows += [row("r1", "sphere_response", "boxonly", q, "skip") for q in ("v1", "v2")]
    return pd.DataFrame(rows)


def by_engine(rows: list[verdict.EngineVerdict]) -> dict[str, verdict.EngineVerdict]:
    return {r.engine: r for r in rows}


def test_kinds_follow_the_fixed_order() -> None:
    assert verdict.kinds_of(frame()) == ["aabb", "sphere", "sphere_response"]


def test_shares_per_kind_leave_out_skip_and_undefined_rows() -> None:
    rows = by_engine(verdict.verdicts(frame()))
    kinds = verdict.kinds_of(frame())
    share = {(e, k): c.share for e, r in rows.items() for k, c in zip(kinds, r.cells, strict=True)}
    assert share["good", "aabb"] == 1.0 and share["good", "sphere"] == 1.0
    assert share["good", "sphere_response"] == 1.0  # v1 agrees, v2 undefined counts neither way
    assert share["bad", "sphere"] == 2 / 4 and share["bad", "aabb"] == 0 / 3
    assert share["boxonly", "aabb"] == 1 / 2
    assert rows["good"].overall.share == 7 / 7
    assert rows["bad"].overall.share == 2 / 7
    assert rows["boxonly"].overall.share == 1 / 2


def test_an_unsupported_kind_shows_a_dash() -> None:
    rows = by_engine(verdict.verdicts(frame()))
    kinds = verdict.kinds_of(frame())
    box = dict(zip(kinds, rows["boxonly"].cells, strict=True))
    assert box["sphere"].share is None and box["sphere"].text == "\u2013"
    assert box["sphere_response"].text == "\u2013"
    assert box["sphere"].colour == "#e4e4e4"  # the matrix's grey for nothing judged
    assert dict(zip(kinds, rows["bad"].cells, strict=True))["sphere_response"].text == "\u2013"
    assert box["aabb"].text == "50.0%"


def test_engines_are_ranked_by_overall_agreeing_share() -> None:
    assert [r.engine for r in verdict.verdicts(frame())] == ["good", "boxonly", "bad"]


def test_speed_rank_per_kind_among_timed_engines() -> None:
    rows = by_engine(verdict.verdicts(frame()))
    aabb = {e: r.cells[0] for e, r in rows.items()}
    sphere = {e: r.cells[1] for e, r in rows.items()}
    assert (sphere["good"].rank, sphere["bad"].rank, sphere["boxonly"].rank) == (1, 2, None)
    assert sphere["good"].speed == "1 of 2" and sphere["boxonly"].speed == "\u2013"
    # boxonly (1e-7 s) is fastest on boxes; bad crashed there, so it has no timing
    assert (aabb["boxonly"].rank, aabb["good"].rank, aabb["bad"].rank) == (1, 2, None)
    assert aabb["good"].median_s == 2e-6


def test_reasons_differing_only_in_numbers_form_one_mode() -> None:
    modes = verdict.failure_modes(frame())
    bad = [m for m in modes if m.engine == "bad"]
    assert [(m.status, m.category, m.count) for m in bad] == [("crash", "", 3),
                                                              ("disagree", "error", 2)]
    assert bad[1].pattern == "error # beyond the agree bound # (size #)"
    assert bad[0].pattern == "worker killed by SIGSEGV" and bad[0].label == "crash"
    assert bad[1].label == "disagree / error"
    assert (bad[0].example, bad[1].example) == ("b1", "s1")  # the first row of each mode
    assert [m.count for m in modes] == sorted((m.count for m in modes), reverse=True)
    assert sum(m.count for m in modes) == frame()["status"].isin(Status.members("breaking")).sum()


def test_the_good_engine_has_no_failure_modes() -> None:
    assert by_engine(verdict.verdicts(frame()))["good"].modes == []


def test_a_repro_link_only_when_its_script_is_in_the_run_folder(tmp_path: Path) -> None:
    context = verdict.verdict(frame(), written_repros(tmp_path))
    assert all(m.repro == "" for m in context["modes"])
    (tmp_path / "repro").mkdir()
    script = f"{repro_name('s2', 'bad')}.py"
    (tmp_path / "repro" / script).write_text("# fake repro\n")
    modes = {(m.engine, m.status): m
             for m in verdict.verdict(frame(), written_repros(tmp_path))["modes"]}
    assert modes["bad", "disagree"].repro == f"repro/{script}"
    assert modes["bad", "disagree"].example == "s2"  # the example with a script is preferred
    assert modes["bad", "crash"].repro == "" and modes["bad", "crash"].example == "b1"


def test_every_failure_mode_shows_its_repro_command_and_links_only_a_written_script(
        tmp_path: Path) -> None:
    """A run writes no script: each mode's example gives the command that prints it (the run
    folder quoted for a shell); where the folder holds the script, it is linked too."""
    run = tmp_path / "a run"
    (run / "repro").mkdir(parents=True)
    script = f"{repro_name('s2', 'bad')}.py"
    (run / "repro" / script).write_text("# fake repro\n")
    html = templates().get_template("_verdict.html.j2").render(
        **verdict.verdict(frame(), written_repros(run)), run_dir=str(run))
    commands = {f"crosscheck repro &#39;{run}&#39; {case} --engine {engine}"
                for case, engine in (("s2", "bad"), ("b1", "bad"), ("b1", "boxonly"))}
    for command in commands:  # every mode's example, in each list that shows it
        assert f"<code>{command}</code>" in html
    assert html.count("<code>crosscheck repro ") == 2 * 3  # the top modes, then all of them
    assert html.count('class="repro" href=') == 2  # s2 on bad: in the top list and in all
    assert f'href="repro/{script}"' in html
    assert "command</summary><code>crosscheck repro &#39;" in html  # beside the link


def test_the_block_shows_the_top_modes_and_lists_them_all() -> None:
    reasons = ["first 1", "second 2", "third 3", "fourth 4"]
    rows = [row(f"c{i}.{n}", "sphere", "e", "distance", "disagree", "error", f"{reason} {n}")
            for i, reason in enumerate(reasons) for n in range(len(reasons) - i)]
    [only] = verdict.verdicts(pd.DataFrame(rows))
    assert [m.count for m in only.modes] == [4, 3, 2, 1]
    assert [m.pattern for m in only.top] == ["first # #", "second # #", "third # #"]
    assert only.breaking == 10 and only.overall.share == 0.0


def test_the_template_escapes_text_and_shows_counts(tmp_path: Path) -> None:
    data = frame()
    data.loc[data["status"] == "crash", "reason"] = EVIL
    html = templates().get_template("_verdict.html.j2").render(**verdict.verdict(data))
    assert EVIL not in html and "&lt;script&gt;" in html
    assert html.index(">good<") < html.index(">boxonly<") < html.index(">bad<")
    assert '<b class="count">3</b>' in html and '<b class="count">2</b>' in html
    assert "\u2013" in html and "speed 1 of 2" in html
    assert "All failure modes (3)" in html
