"""The report as a user sees it: rendered by headless Chromium (:mod:`tests.report.browser`),
with no console errors, its charts, its verdict block and its advise form."""

from __future__ import annotations

import shlex
import shutil
from pathlib import Path

import pytest

from crosscheck.cli import main
from crosscheck.report.render import render
from crosscheck.results.store import repro_name
from tests.conftest import ROOT
from tests.report import counted as run
from tests.report.advise_form import REAL_PROFILES, errors, form_and_cli
from tests.report.browser import needs_chromium, opened
from tests.report.counted import counted_run

pytestmark = pytest.mark.browser

EVIL = "<script>window.__pwned = true</script>"

@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    needs_chromium()
    work = tmp_path_factory.mktemp("browser")
    cases = work / "cases.toml"
    text = (ROOT / "cases" / "sphere.toml").read_text()
    cases.write_text(text.replace('description = "', f'description = "{EVIL} ', 1))
    out = work / "run"
    assert main(["run", str(cases), "--engine", "reference", "--engine", "pymunk",
                 "--min-sample", "0.001", "--out", str(out)]) == 0
    return out


@pytest.mark.engine
def test_report_renders_without_console_errors(run_dir: Path) -> None:
    messages: list[str] = []
    with opened(run_dir / "report.html", messages) as page:
        page.wait_for_load_state("load")
        page.evaluate("crosscheck.drawAllCharts()")  # charts draw lazily (near view, or idle)
        page.screenshot(path=str(run_dir / "report.png"), full_page=True)
        tables = page.locator("table").count()
        charts = page.locator(".js-plotly-plot").count()
        rows = page.locator("#summary tbody tr").count()
        pwned = page.evaluate("window.__pwned === true")
        requests = page.evaluate("performance.getEntriesByType('resource').map(e => e.name)")
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []
    assert (run_dir / "report.png").stat().st_size > 10_000
    assert tables >= 4 and rows == 2  # reference and pymunk, one kind
    assert charts >= 1
    assert not pwned, "a case description ran as script"
    assert [r for r in requests if r.startswith("http")] == []


@pytest.fixture(scope="module")
def timed_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A synthetic run folder with timings (timings.jsonl and run.json's timing), rendered."""
    needs_chromium()
    from crosscheck.report.render import render
    from tests.report.test_report import timed_run

    folder = timed_run(tmp_path_factory.mktemp("browser-timed") / "run")
    render(folder)
    return folder


def test_speed_points_show_their_timing_whiskers(timed_dir: Path) -> None:
    messages: list[str] = []
    with opened(timed_dir / "report.html", messages) as page:
        page.wait_for_load_state("load")
        page.evaluate("crosscheck.drawAllCharts()")  # charts draw lazily (near view, or idle)
        page.screenshot(path=str(timed_dir / "report.png"), full_page=True)
        bars = page.locator("#speed-sphere g.errorbar").count()
        across = page.locator("#speed-sphere g.errorbar path.xerror").count()
        upward = page.locator("#speed-sphere g.errorbar path.yerror").count()
        legend = page.locator("#speed-sphere .legendtext").all_text_contents()
        timing = page.locator("#timing").count()
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []
    assert bars >= 6  # fast, exact and noisy on both panels (distance, normal) of sphere
    assert across == 6 and upward == 6  # each point: its IQR across, its error whisker up
    assert "noisy (timing unstable)" in legend
    assert timing == 1


def test_verdict_block_comes_first_and_fits_the_page(timed_dir: Path) -> None:
    """The verdict block is the page's first section, lists each engine with its failure modes
    (their row counts add up to the engine's breaking rows) and fits a 1,400 px viewport."""
    import pandas as pd
    results = pd.read_csv(timed_dir / "results.csv", keep_default_na=False)
    breaking = results[results["status"].isin(["disagree", "error", "crash", "timeout"])]
    assert not breaking.empty  # the synthetic run has disagreements and crashes
    with opened(timed_dir / "report.html") as page:
        page.wait_for_load_state("load")
        first = page.evaluate("document.querySelector('h2').closest('#verdict') !== null")
        engines = page.locator("#verdict tr.verdict-engine td.engine").all_text_contents()
        counts = page.locator("#verdict li.mode b.count").all_text_contents()
        listed = page.evaluate("""Array.from(document.querySelectorAll(
            '#verdict table.verdict-modes tbody tr')).map(r => [r.cells[0].textContent,
            Number(r.cells[1].textContent)])""")
        widths = page.evaluate("""[document.documentElement.scrollWidth,
            document.getElementById('verdict').scrollWidth,
            document.getElementById('verdict').getBoundingClientRect().right]""")
    assert first, "the verdict block is not the first section"
    assert sorted(engines) == sorted(set(results["engine"]))
    assert counts and all(c.isdigit() and int(c) > 0 for c in counts)
    for engine in set(results["engine"]):
        expected = int((breaking["engine"] == engine).sum())
        assert sum(n for e, n in listed if e == engine) == expected, engine
    assert widths[0] <= 1400, f"the page overflows a 1,400 px viewport: {widths}"
    assert widths[1] <= 1400 and widths[2] <= 1400


REPORT_BUDGET = 3_000_000
"""Bytes: the report of the full suite (~770 cases x 7 engines, ~15k rows) stays under this."""


@pytest.fixture(scope="module")
def suite_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A synthetic run of the full suite's size (770 cases x 7 engines x 3 quantities), rendered."""
    needs_chromium()
    from dataclasses import replace

    from crosscheck.report.render import render
    from tests.report.test_report import detection, write_run

    rows = []
    for i in range(770):
        source = ("cases/near_touching.toml", "cases/float_traps.toml", "cases/sphere.toml")[i % 3]
        for j, engine in enumerate(("fast", "exact", "bullet", "fcl", "munk", "f32", "slow")):
            for r in detection(f"s{i}", engine, (i * j % 11) * 1e-6, 1e-6 * (1 + j), source):
                rows.append(replace(r, value=f"[{0.1 * i:.17g}, {1e-3 * j:.17g}, 0.0]",
                                    truth="[0.0, 0.0, 0.0]",
                                    reason=f"error {r.error:.3g} exceeds 8 u (1.8e-15) + 0"
                                    if r.error else ""))
    folder = write_run(tmp_path_factory.mktemp("browser-suite") / "run", rows)
    render(folder)
    return folder


def test_suite_sized_report_fits_its_budget_filters_by_column_and_opens_a_case(
        suite_dir: Path) -> None:
    page_file = suite_dir / "report.html"
    assert page_file.stat().st_size <= REPORT_BUDGET, page_file.stat().st_size
    messages: list[str] = []
    with opened(page_file, messages) as page:
        page.wait_for_selector("#results-table[data-ready]")
        page.evaluate("crosscheck.drawAllCharts()")
        charts = page.locator(".js-plotly-plot").count()
        info = page.locator("#results-table_wrapper .dt-info, .dt-info").first
        page.locator("#results-breaking").uncheck()
        everything = info.inner_text()
        page.locator("#results-table thead input").nth(1).fill("slow")  # the engine column
        page.wait_for_timeout(300)
        filtered = info.inner_text()
        sticky = page.evaluate("getComputedStyle(document.querySelector('#results-table thead'))"
                               ".position")
        link = page.locator("#results-table tbody a[href^='#case-']").first
        case = (link.get_attribute("href") or "")[len("#case-"):]
        link.click()
        page.wait_for_selector(f"#case-details details[id='case-{case}']")
        case_rows = page.locator(f"#case-details details[id='case-{case}'] tbody tr").count()
        in_view = page.evaluate(f"document.getElementById('case-{case}').getBoundingClientRect()"
                                ".top < innerHeight")
    assert [m for m in messages if m.startswith(("error", "pageerror"))] == []
    assert charts >= 1
    assert "of 5,390 rows" in everything  # 770 cases x 7 engines
    assert "of 770 rows (filtered from 5,390)" in filtered, filtered
    assert sticky == "sticky"
    assert case_rows == 7 * 3 and in_view  # every engine's hit, distance and normal


def test_the_advise_form_writes_the_command_and_the_page_answers_the_standard_profiles(
        fakes_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The form judges nothing: it writes the ``crosscheck advise`` command of its fields; the
    standard profiles are answered in Python, as the command answers them, a refused or empty
    one with the reason."""
    profiles = [({"tolerance": "0.5"}, ["--tolerance", "0.5"]),
                ({"rtol": "2", "strict": "on", "nof32": "on"},
                 ["--rtol", "2", "--strict-conventions", "--no-float32"]),
                *(p for p in REAL_PROFILES if p[0].get("kind", "sphere") == "sphere")]
    found, expected, console = form_and_cli(fakes_dir, profiles, capsys)
    messages: list[str] = []
    with opened(fakes_dir / "report.html", messages) as page:
        exact = page.locator("#advise-out details.advise-profile").first.inner_text()
        refused = page.locator("#advise-out .advise-message").all_text_contents()
    assert console == [] and errors(messages) == []
    assert found == expected
    assert [row[:3] for row in found[len(profiles)]] == [("fake-right", "pass", "4"),
                                                         ("fake-off", "fail", "4")]
    assert "Passing (none timed: in run order): fake-right" in exact  # a --quick run
    assert "4 cases" in exact
    assert "No answer from this run: --kind: the run holds no aabb cases" in " ".join(refused)


ROW_REPROS = """rows => rows.map(r => {
    const cell = r.cells[0], id = cell.querySelector('a.case-id'),
          code = cell.querySelector('details.repro-command code'),
          link = cell.querySelector('a.repro');
    return [id.title, r.cells[1].textContent, code ? code.textContent : null,
            link ? link.getAttribute('href') : null];
})"""
"""Each shown row of the results table: case id, engine, its repro command, its script link."""


def test_breaking_rows_fold_their_repro_command_and_a_written_script_is_linked(
        fakes_dir: Path, tmp_path: Path) -> None:
    """A run writes no script: each breaking row of the results table folds the command that
    prints it in a ``<code>`` (no link), and so does the advise form's worst answer; the
    page quotes a word as ``shlex`` does.  Once the folder holds a script (``crosscheck repro
    RUN --all``) and the report is rendered again, its row links it, the command beside."""
    import pandas as pd
    run = tmp_path / "run"
    shutil.copytree(fakes_dir, run)
    render(run)
    results = pd.read_csv(run / "results.csv", keep_default_na=False)
    breaking = {(str(c), str(e)) for c, e, s in zip(results["case_id"], results["engine"],
                                                   results["status"], strict=True)
                if s in ("disagree", "error", "crash", "timeout")}
    assert ("s0", "fake-off") in breaking
    tricky = [str(tmp_path / "a run"), "it's a case", "e"]
    messages: list[str] = []
    with opened(run / "report.html", messages) as page:
        page.wait_for_selector("#results-table[data-ready]")
        rows = page.eval_on_selector_all("#results-table tbody tr", ROW_REPROS)
        summary = page.locator("#results-table details.repro-command summary").first
        hidden = page.locator("#results-table details.repro-command code").first.is_visible()
        summary.click()
        shown = page.locator("#results-table details.repro-command code").first.is_visible()
        quoted = page.evaluate("words => crosscheck.reproCommand(...words)", tricky)
        worst = page.eval_on_selector("#advise-out tr[data-engine='fake-off'] code",
                                      "code => code.textContent")
    assert errors(messages) == []
    assert {(c, e) for c, e, _, _ in rows} == breaking  # the page shows the breaking rows
    assert all(command == shlex.join(["crosscheck", "repro", str(run), c, "--engine", e])
               and link is None for c, e, command, link in rows)
    assert not hidden and shown  # folded until asked
    assert quoted == shlex.join(["crosscheck", "repro", *tricky[:2], "--engine", tricky[2]])
    assert worst.startswith(f"crosscheck repro {run} ") and worst.endswith(" --engine fake-off")
    script = run / "repro" / f"{repro_name('s0', 'fake-off')}.py"
    script.parent.mkdir()
    script.write_text("# a repro script\n", encoding="utf-8")
    render(run)
    with opened(run / "report.html", messages) as page:
        page.wait_for_selector("#results-table[data-ready]")
        again = {(c, e): (command, link) for c, e, command, link in
                 page.eval_on_selector_all("#results-table tbody tr", ROW_REPROS)}
    assert again["s0", "fake-off"] == (
        shlex.join(["crosscheck", "repro", str(run), "s0", "--engine", "fake-off"]),
        f"repro/{script.name}")
    assert all(link is None for pair, (_, link) in again.items() if pair != ("s0", "fake-off"))


@pytest.fixture(scope="module")
def real_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A real run (textbook formula, pybullet, pymunk) of a real slice of the suite: spheres,
    responses and every bad-input case (NaN, infinities, negative sizes and masses), with a
    small timing phase (so that the form's times can be checked against the CLI's)."""
    needs_chromium()
    out = tmp_path_factory.mktemp("advise-real") / "run"
    paths = [str(ROOT / "cases" / f"{name}.toml") for name in ("sphere", "response", "bad_input")]
    assert main(["run", *paths, "--engine", "reference", "--engine", "pybullet", "--engine",
                 "pymunk", "--samples", "3", "--min-sample", "0.001", "--timing-cases", "40",
                 "--out", str(out)]) == 0
    return out


COUNTED_PROFILES = [({}, []), ({"tolerance": "2"}, ["--tolerance", "2"]),
                    ({"quantities": "hit"}, ["--quantities", "hit"])]
"""Profiles of the counted run: two passing engines then one failing, three passing, and
the hit verdicts alone."""


@pytest.mark.parametrize("counted", [run.INSTRUCTIONS, run.PARTLY], ids=["all", "partly"])
def test_the_advise_form_on_a_counted_run_ranks_as_the_cli_does(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], counted: dict[str, float]) -> None:
    # costs written by the test: fake-right the cheapest in instructions, fake-twin on the
    # wall clock; all counted, the form orders by instructions as the CLI does; fake-twin
    # not counted, both by the wall clock
    needs_chromium()
    directory = counted_run(tmp_path / "run", counted)
    found, expected, console = form_and_cli(directory, COUNTED_PROFILES, capsys)
    assert console == []
    assert found == expected
    cheapest = ["fake-right", "fake-twin"] if counted is run.INSTRUCTIONS else [
        "fake-twin", "fake-right"]
    exact = found[len(COUNTED_PROFILES)]  # the first standard profile: no options
    assert [row[0] for row in exact[:2]] == cheapest
    assert all(len(row) == 6 for row in exact)  # instructions and wall clock


@pytest.mark.engine
def test_the_advise_form_on_a_real_run_ranks_as_the_cli_does(
        real_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    found, expected, console = form_and_cli(real_dir, REAL_PROFILES, capsys)
    assert console == []
    assert found == expected
    answers = found[len(REAL_PROFILES):]  # the standard profiles; the second: 3-D spheres
    assert answers[1][0][0] == "pybullet" and "pymunk" not in [row[0] for row in answers[1]]
    assert any(row[4] != "-" for rows in answers for row in rows)  # the times are compared


@pytest.mark.engine
def test_results_table_keeps_case_ids_on_one_line_and_shows_only_the_pages_quantities(
        real_dir: Path) -> None:
    """At 1,024 px no case id wraps and the table fits its box or scrolls in a .wide one; a
    quantity's column shows only while a row on the page has it (unless asked for every one)."""
    import pandas as pd
    results = pd.read_csv(real_dir / "results.csv", keep_default_na=False)
    quantities = list(dict.fromkeys(results["quantity"]))
    responses = set(results.loc[results["kind"] == "sphere_response", "quantity"])
    assert responses and responses != set(quantities)  # the filter below hides columns
    messages: list[str] = []
    with opened(real_dir / "report.html", messages) as page:
        page.set_viewport_size({"width": 1024, "height": 1000})
        page.wait_for_selector("#results-table[data-ready]")
        page.locator("#results-breaking").uncheck()
        lines = page.evaluate("""Array.from(document.querySelectorAll('#results-table a.case-id'))
            .map(a => a.getClientRects().length === 1 && a.getBoundingClientRect().height <
                      1.5 * parseFloat(getComputedStyle(a).lineHeight))""")
        fits = page.evaluate("""(t => t.scrollWidth <= t.parentElement.clientWidth ||
            t.parentElement.classList.contains('wide'))(document.getElementById('results-table'))""")

        def shown() -> set[str]:
            page.wait_for_timeout(300)
            heads = page.locator("#results-table thead tr:first-child th").all_inner_texts()
            return {h.strip() for h in heads} & set(quantities)

        page.locator("#results-table thead input").nth(2).fill("sphere_response")  # the kind
        only_responses = shown()
        page.locator("#results-every-column").check()
        every = shown()
    assert errors(messages) == []
    assert lines and all(lines), "a case id wraps"
    assert fits
    assert only_responses == responses
    assert every == set(quantities)
