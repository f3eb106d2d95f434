"""tools.audit_dynamics: the self-audit of a run's dynamic labels, on a hand-made run folder
whose every row's right verdict is known (a 5% apex gain called ``timestep``, a NaN toi called
``tolerance``, a pass-through whose velocities are the step-sampled run's called ``error``,
and honest rows of each kind), and its refusal of bad input."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest

from tools import audit_dynamics
from tools.audit_dynamics import audit, load_run, main, sample

HEADER = ["case_id", "source", "kind", "dim", "tags", "engine", "quantity", "value", "truth",
          "error", "tolerance", "status", "category", "reason", "setup_s", "query_s",
          "query_iqr_s", "loops", "unstable", "origin", "coords", "twin_of", "error_at_contact",
          "query_instructions", "engine_instructions", "nondeterministic", "repeat_value",
          "repeat_status"]
"""The columns of a real run's results.csv (format 7)."""
DT = 1 / 60
DROP = {"id": "drop", "kind": "sphere_scene", "dim": 2, "restitution": 1.0, "duration": 2.0,
        "dt": DT, "gravity": [0.0, -9.81], "walls": [{"normal": [0.0, 1.0], "offset": 0.0}],
        "bodies": [{"center": [0.0, 1.1], "radius": 0.1, "mass": 1.0, "velocity": [0.0, 0.0]}]}
FAST = {"id": "fast", "kind": "sphere_scene", "dim": 2, "restitution": 1.0, "duration": 0.1,
        "dt": DT, "gravity": None, "walls": [],
        "bodies": [{"center": [-0.6, 0.0], "radius": 0.05, "mass": 1.0, "velocity": [30.0, 0.0]},
                   {"center": [0.6, 0.0], "radius": 0.05, "mass": 1.0,
                    "velocity": [-30.0, 0.0]}]}
"""Relative travel 1 m a step: step starts 0.2 apart and then 0.8 past, never in contact."""
TOI = {"id": "toi", "kind": "sphere_toi", "dim": 3, "duration": 1.0,
       "a": {"center": [-1.0, 0.0, 0.0], "radius": 0.05, "velocity": [1.0, 0.0, 0.0]},
       "b": {"center": [1.0, 0.0, 0.0], "radius": 0.05, "velocity": [-1.0, 0.0, 0.0]}}
"""First contact at t = 0.95 exactly."""
WITHIN = ("apex off by 0.06 (relative) over 2 exact bounces: every bounce within one step's lag "
          "of the bounce its fall gives (worst: bounce {k} loses {loss} of the {h} m it fell "
          "from (apex {a} m against {h} m; one step's lag allows a loss of 0.0792: v dt + |g| "
          "dt^2 = 0.0768 m); 2 bounce(s) judged, each from the engine's own previous apex) "
          "(120 steps of dt = 0.0167 s)")
PASSED = ("velocities off by 2 of the largest initial speed: the bodies passed through each "
          "other at step travel 10 (|vb - va| dt / 2(ra + rb), dt = 0.0167 s): B ends 0.8 past "
          "A along the exact contact normal, still closing at 60 m/s along it, and its "
          "velocities are no run's a declared rule or the step gives")
TOI_REASON = ("at the engine's time {t} the surfaces are {s} apart, within 2.37e-05 (declared "
              "toi_tolerance 0 plus rtol 4.77e-07 of the case's magnitudes) of touching "
              "(separation 0)")
ROWS = [  # case, engine, quantity, value, category, reason, the audit's right verdict
    ("drop", "gainer", "apex", "[1.05, 1.05]", "timestep",
     WITHIN.format(k=2, loss="0", h="1.05", a="1.05"), "wrong"),
    ("drop", "honest", "apex", "[0.97, 0.94]", "timestep",
     WITHIN.format(k=2, loss="0.0309", h="0.97", a="0.94"), "true"),
    ("drop", "gainer", "velocities", "[[0.0, -4.5]]", "error",
     "velocities off by 0.1 of the largest initial speed: the run's bounces decide it (dt = "
     "0.0167 s): bounce 1 gains 0.05 of the 1 m it fell from (apex 1.05 m against 1 m; only "
     "the precision's 1e-15 m is allowed either way: step lag never adds height): no step lag "
     "adds energy, and nothing declared does", "true"),
    ("fast", "sampler", "velocities", "[[30.0, 0.0], [-30.0, 0.0]]", "error", PASSED, "wrong"),
    ("fast", "wild", "velocities", "[[20.0, 5.0], [-20.0, -5.0]]", "error", PASSED, "true"),
    ("toi", "f32", "toi", "nan", "tolerance", "within the engine's declared precision", "wrong"),
    ("toi", "f32", "normal", "[1.0, 0.0, 0.0]", "tolerance",
     TOI_REASON.format(t="0.95000001", s="-2e-08"), "true"),
    ("toi", "f32", "hit", "true", "tolerance", TOI_REASON.format(t="0.5", s="0.9"), "misleading"),
    ("toi", "far", "toi", "0.5", "tolerance", TOI_REASON.format(t="0.5", s="-2e-08"), "wrong"),
    ("toi", "near", "toi", "0.95000001", "tolerance",
     TOI_REASON.format(t="0.95000001", s="-2e-08"), "true"),
    ("toi", "near", "normal", "[1.0, 0.0, 0.0]", "error", "", "misleading"),
]


def write_run(folder: Path) -> Path:
    """A run folder in the stored format: results.csv, cases.jsonl, run.json."""
    folder.mkdir(parents=True, exist_ok=True)
    with (folder / "results.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, HEADER)
        writer.writeheader()
        for case, engine, quantity, value, category, reason, _ in ROWS:
            kind = {"toi": "sphere_toi"}.get(case, "sphere_scene")
            truth = {"apex": "[1.0, 1.0]", "toi": "0.95"}.get(quantity, "")
            writer.writerow({**dict.fromkeys(HEADER, ""), "case_id": case, "kind": kind,
                             "engine": engine, "quantity": quantity, "value": value,
                             "truth": truth, "status": "disagree", "category": category,
                             "reason": reason, "tolerance": "1e-09"})
        writer.writerow({**dict.fromkeys(HEADER, ""), "case_id": "drop", "kind": "sphere_scene",
                         "engine": "honest", "quantity": "energy", "status": "agree"})
    (folder / "cases.jsonl").write_text(
        "".join(json.dumps(c) + "\n" for c in (DROP, FAST, TOI)), encoding="utf-8")
    # "sampler" declares sampled contacts: a pass-through explains only a declared sampler
    engines = [{"name": name, "engine": name,
                "conventions": {"rtol": rtol, "sampled_contacts": name == "sampler"}}
               for name, rtol in [("gainer", 2.0**-53), ("honest", 2.0**-53),
                                  ("sampler", 2.0**-53), ("wild", 2.0**-53),
                                  ("f32", 2.0**-22), ("far", 2.0**-22), ("near", 2.0**-22)]]
    (folder / "run.json").write_text(json.dumps({"format_version": 7, "engines": engines}),
                                     encoding="utf-8")
    return folder


@pytest.mark.parametrize("index", range(len(ROWS)),
                         ids=[f"{r[1]}-{r[2]}-{r[4]}-{r[6]}" for r in ROWS])
def test_each_hand_made_row_gets_its_known_verdict(tmp_path: Path, index: int) -> None:
    run = load_run(write_run(tmp_path / "run"))
    row = [r for r in run.rows if r["status"] == "disagree"][index]
    found = audit(row, run)
    assert found.verdict == ROWS[index][6], found.note
    assert found.note


def test_the_gain_is_named_with_its_numbers(tmp_path: Path) -> None:
    run = load_run(write_run(tmp_path / "run"))
    found = audit(run.rows[0], run)
    assert "bounce 1: apex 1.05 m against 1 m" in found.note
    assert "a gain" in found.note


def test_the_bounce_bound_is_one_steps_lag() -> None:
    """A loss just inside v dt + |g| dt^2 (+ |g| dt^2 / 2 for the recording) passes, one
    just beyond it fails; a gain of 1e-5 fails."""
    g, height = 9.81, 1.0
    lag = math.sqrt(2 * g * height) * DT + g * DT * DT * 1.5
    events = audit_dynamics.bounces(DROP, {}, [height - 0.99 * lag], 1)
    assert not events[0][4] and not events[0][5]
    assert audit_dynamics.bounces(DROP, {}, [height - 1.01 * lag], 1)[0][5]
    assert audit_dynamics.bounces(DROP, {}, [height + 1e-5], 1)[0][4]


def test_the_sample_is_stratified_and_seeded(tmp_path: Path) -> None:
    run = load_run(write_run(tmp_path / "run"))
    rows, strata = sample(run.rows, 5, seed=39)  # 9 strata: one each beats the 5 asked
    assert strata[("f32", "tolerance")] == (3, 1)
    assert len(strata) == len(rows) == 9 and all(t == 1 for _, t in strata.values())
    assert rows == sample(run.rows, 5, seed=39)[0]
    assert all(r["status"] == "disagree" for r in rows)
    assert len(sample(run.rows, 100, seed=39)[0]) == len(ROWS)


def test_the_command_prints_a_summary_and_writes_the_table(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder, out = write_run(tmp_path / "run"), tmp_path / "audit.md"
    assert main([str(folder), "--rows", "200", "--seed", "39", "--markdown", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "verdicts: true 5, misleading 2, wrong 4, unchecked 0" in printed
    assert "wrong: 36.4% of 11 checked rows" in printed
    table = out.read_text(encoding="utf-8").splitlines()
    assert table[0].startswith("| case | engine | quantity | category | audit |")
    assert len(table) == 2 + len(ROWS)
    assert "| fast | sampler | velocities | error | wrong |" in "\n".join(table)


@pytest.mark.parametrize(("args", "said"), [
    (["{tmp}/nowhere"], "run folder not found: {tmp}/nowhere"),
    (["{tmp}"], "no results.csv in {tmp}"),
    (["{run}", "--rows", "0"], "--rows must be at least 1, not 0"),
])
def test_bad_input_is_one_line_and_exit_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], said: str) -> None:
    run = write_run(tmp_path / "run")
    fill = {"tmp": str(tmp_path), "run": str(run)}
    assert main([a.format(**fill) for a in args]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == f"audit_dynamics: error: {said.format(**fill)}\n"
