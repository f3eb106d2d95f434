"""The results format: typed run.json, fields instead of parsed ids, and loading older runs.

``tests/data/format1-run`` was written by the harness before the layered
architecture (format 1: run.json as a free dict, sweep coordinates and twin
links only inside case ids), with ``crosscheck run tiny.toml --quick --engine
reference --engine pymunk``; ``results-as-written.csv`` is the results.csv that
harness wrote for it.
"""

from __future__ import annotations

import io
import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from crosscheck.cases.expand import expand, with_swaps
from crosscheck.cases.load import load_paths
from crosscheck.cli import main
from crosscheck.core.model import COLUMNS
from crosscheck.core.options import RunOptions
from crosscheck.core.schema import CASE_ADAPTER
from crosscheck.core.values import decode, upgrade
from crosscheck.report.render import render
from crosscheck.report.stability import sweep_points
from crosscheck.results.run import read_run
from crosscheck.results.runinfo import FORMAT_VERSION
from crosscheck.results.store import ResultsStore, StoreError
from crosscheck.run.launch import launch, new_info
from tests import fakes
from tests.conftest import embedded, sphere

FORMAT1 = Path(__file__).resolve().parent.parent / "data" / "format1-run"
NEW_COLUMNS = ("origin", "coords", "twin_of", "error_at_contact")


@pytest.fixture
def old_run(tmp_path: Path) -> Path:
    directory = tmp_path / "old"
    shutil.copytree(FORMAT1, directory)
    return directory


def test_a_format_1_run_reads_back_with_the_rows_it_wrote(old_run: Path) -> None:
    stored = read_run(old_run)
    assert stored.info.options.quick and stored.info.engine_names == ["reference", "pymunk"]
    written = pd.read_csv(old_run / "results-as-written.csv", dtype=str, keep_default_na=False)
    old_columns = [c for c in COLUMNS if c not in NEW_COLUMNS]
    assert list(written.columns) == old_columns
    again = pd.read_csv(io.StringIO(stored.results[old_columns].to_csv(index=False)),
                        dtype=str, keep_default_na=False)
    values = ["value", "truth"]  # format 4 writes them as strict JSON; all else as written
    assert again.drop(columns=values).equals(written.drop(columns=values))
    assert "" in set(written["value"])  # the fixture has old texts to upgrade
    for column in values:
        assert list(again[column]) == [upgrade(text) for text in written[column]]
        for old, new in zip(written[column], again[column], strict=True):
            json.loads(new, parse_constant=not_strict)
            assert _same(decode(old), decode(new)), (old, new)


def not_strict(token: str) -> None:
    pytest.fail(f"{token} is not strict JSON")


def _same(a: object, b: object) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b or (a != a and b != b)


def test_a_format_1_run_gets_its_coordinates_and_twin_links(old_run: Path) -> None:
    stored = read_run(old_run)
    frame = stored.results.drop_duplicates("case_id").set_index("case_id")
    assert frame.loc["tiny-gap.gap=0.001.swapped", "twin_of"] == "tiny-gap.gap=0.001"
    assert json.loads(frame.loc["tiny-gap.gap=0.001", "coords"]) == {"gap": 0.001}
    assert frame.loc["tiny-scene.dt=0.01", "origin"] == "tiny-scene"
    case = stored.cases["tiny-gap.gap=0.1.swapped"]
    assert (case.origin, case.coords, case.twin_of) == ("tiny-gap", {"gap": 0.1},
                                                        "tiny-gap.gap=0.1")
    points = sweep_points(stored.results, stored.cases)
    assert sorted(set(points["value"])) == [0.001, 0.1]
    assert "swapped" not in " ".join(points["case_id"])


def test_a_format_1_run_renders_and_resumes_as_format_2(old_run: Path) -> None:
    html = render(old_run)["report"].read_text(encoding="utf-8")
    assert "Dynamics" in html and "tiny-gap.gap=0.1" in json.dumps(embedded(html, "results-data"))
    assert main(["run", "--resume", str(old_run)]) == 0  # nothing left to run: finish only
    assert json.loads((old_run / "run.json").read_text())["format_version"] == FORMAT_VERSION


def test_an_unknown_format_is_a_clear_error(old_run: Path) -> None:
    info = json.loads((old_run / "run.json").read_text())
    (old_run / "run.json").write_text(json.dumps(info | {"format_version": 99}))
    with pytest.raises(StoreError, match="format 99; this harness reads formats 1, 2, 3"):
        read_run(old_run)
    (old_run / "run.json").unlink()
    with pytest.raises(StoreError, match="does not exist"):
        read_run(old_run)


def test_a_new_run_stores_typed_cases_and_linking_fields(tmp_path: Path) -> None:
    block = CASE_ADAPTER.validate_python(sphere(0.0, 1.0, id="g").model_dump() | {
        "sweep": {"gap": [0.5]}, "source": "cases/g.toml"})
    cases = list(with_swaps(expand(block)))
    options = RunOptions(quick=True, isolate=False)
    engines = [fakes.AlwaysRight()]
    folder = tmp_path / "run"
    launch(ResultsStore(folder), cases, engines, options,
           new_info(folder, "test", options, engines, cases))
    stored = read_run(folder)
    assert list(stored.cases.values()) == cases
    rows = stored.results.drop_duplicates("case_id").set_index("case_id")
    assert rows.loc["g.gap=0.5", "origin"] == "g" and rows.loc["g.gap=0.5", "twin_of"] == ""
    assert json.loads(rows.loc["g.gap=0.5.swapped", "coords"]) == {"gap": 0.5}
    assert rows.loc["g.gap=0.5.swapped", "twin_of"] == "g.gap=0.5"
    assert json.loads((folder / "run.json").read_text())["format_version"] == FORMAT_VERSION


def test_a_case_file_may_not_set_what_the_loader_sets(tmp_path: Path) -> None:
    path = tmp_path / "c.toml"
    path.write_text('[[case]]\nid = "x"\ndescription = "d"\nkind = "sphere"\ndim = 2\n'
                    'twin_of = "y"\na = { center = [0.0, 0.0], radius = 0.5 }\n'
                    'b = { center = [2.0, 0.0], radius = 0.5 }\n')
    (error,) = load_paths([path]).errors
    assert error.field == "twin_of" and "set by the loader" in error.reason


def test_compare_warns_when_the_machines_differ(old_run: Path, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    other = tmp_path / "other"
    shutil.copytree(old_run, other)
    info = json.loads((other / "run.json").read_text())
    info["machine"]["cpu"] = "another CPU"
    (other / "run.json").write_text(json.dumps(info))
    assert main(["compare", str(old_run), str(old_run), "--out", str(tmp_path / "same")]) == 0
    assert "different machines" not in capsys.readouterr().err
    assert main(["compare", str(old_run), str(other), "--out", str(tmp_path / "cmp")]) == 0
    assert "different machines: cpu:" in capsys.readouterr().err.replace("\n", " ")
    assert "different machines" in (tmp_path / "cmp" / "compare.html").read_text()
