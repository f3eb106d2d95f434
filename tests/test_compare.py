"""crosscheck compare: verdict changes and timing changes beyond the noise."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from crosscheck.cli import main
from crosscheck.core.model import COLUMNS
from crosscheck.report.compare import engine_ratios, timing_changes, verdict_changes


def frame(rows: list[dict[str, object]]) -> pd.DataFrame:
    base: dict[str, object] = {c: "" for c in COLUMNS}
    base.update(error=0.0, query_iqr_s=0.0, query_s=math.nan)
    return pd.DataFrame([{**base, **row} for row in rows], columns=list(COLUMNS))


def test_verdict_changes_list_status_and_category_changes_and_missing_rows() -> None:
    a = frame([{"case_id": "c1", "engine": "e", "quantity": "hit", "status": "agree"},
               {"case_id": "c2", "engine": "e", "quantity": "hit", "status": "disagree",
                "category": "tolerance"},
               {"case_id": "c3", "engine": "e", "quantity": "hit", "status": "agree"},
               {"case_id": "gone", "engine": "e", "quantity": "hit", "status": "agree"}])
    b = frame([{"case_id": "c1", "engine": "e", "quantity": "hit", "status": "disagree",
                "category": "error"},
               {"case_id": "c2", "engine": "e", "quantity": "hit", "status": "disagree",
                "category": "error"},
               {"case_id": "c3", "engine": "e", "quantity": "hit", "status": "agree"},
               {"case_id": "new", "engine": "e", "quantity": "hit", "status": "agree"}])
    changes = verdict_changes(a, b).set_index("case_id")["change"].to_dict()
    assert changes == {"c1": "changed", "c2": "changed", "gone": "removed", "new": "added"}


def test_timing_changes_need_a_big_ratio_beyond_the_iqr() -> None:
    def timed(q: float, iqr: float, case: str) -> dict[str, object]:
        return {"case_id": case, "engine": "e", "quantity": "hit", "query_s": q,
                "query_iqr_s": iqr}
    a = frame([timed(1e-6, 1e-8, "fast"), timed(1e-6, 1e-6, "noisy"), timed(1e-6, 0, "same")])
    b = frame([timed(2e-6, 1e-8, "fast"), timed(2e-6, 1e-6, "noisy"), timed(1.05e-6, 0, "same")])
    changed = timing_changes(a, b)
    assert list(changed["case_id"]) == ["fast"]
    assert changed["ratio"].iloc[0] == 2.0
    ratios = engine_ratios(a, b)
    assert math.isclose(ratios["geomean_ratio"].iloc[0], (2 * 2 * 1.05) ** (1 / 3))


def test_compare_cli_writes_csv_and_html(tmp_path: Path) -> None:
    case_file = str(Path(__file__).resolve().parent.parent / "cases" / "sphere.toml")
    for name, engine in (("a", "reference"), ("b", "reference-f32")):
        assert main(["run", case_file, "--quick", "--engine", engine,
                     "--out", str(tmp_path / name)]) == 0
    out = tmp_path / "cmp"
    assert main(["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--out", str(out)]) == 0
    changes = pd.read_csv(out / "verdict_changes.csv")
    assert set(changes["change"]) == {"added", "removed"}  # engines differ: nothing in common
    assert "reference-f32" in (out / "compare.html").read_text()
