"""The report's advise form speaks the same space as ``crosscheck advise``: a scene's limits
(time step, step travel, body speed), one tolerance per unit, and declared behaviours judged
on their error, filled as a reader fills them, write the command whose answer ranks them.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from crosscheck.cli import main
from crosscheck.testing import fakes
from tests.report.advise_form import cli_rows, form_and_cli
from tests.report.browser import needs_chromium
from tests.report.test_advise_space import PAIRS, SCENES, Damped, Soft, Tilted, stored

pytestmark = pytest.mark.browser

PROFILES = [
    ({"kind": "sphere_scene", "quantities": "energy_drift", "fraction": "1e-3"},
     ["--kind", "sphere_scene", "--fraction-tolerance", "1e-3", "--quantities", "energy_drift"]),
    ({"kind": "sphere_scene", "dt": "1/60", "travel": "30", "speed": "300", "fraction": "1"},
     ["--kind", "sphere_scene", "--speed", "300", "--dt", "1/60", "--step-travel", "30",
      "--fraction-tolerance", "1"]),
    ({"kind": "sphere_scene", "travel": "1", "lasts": "2"},
     ["--kind", "sphere_scene", "--step-travel", "1", "--duration", "2"]),
    ({"kind": "sphere", "tolerance": "1e-3"}, ["--kind", "sphere", "--tolerance", "1e-3"]),
    ({"kind": "sphere", "tolerance": "1e-3", "angle": "1e-5"},
     ["--kind", "sphere", "--tolerance", "1e-3", "--angle-tolerance", "1e-5"]),
]
"""Scene profiles that behaviours fail and a tolerance in metres that demands nothing of the
normals (the tilted engine fails on them until an angle tolerance is given)."""


@pytest.fixture(scope="module")
def page_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    needs_chromium()
    folder = tmp_path_factory.mktemp("form") / "run"
    stored(folder, [*SCENES, *PAIRS], [fakes.AlwaysRight(), Damped(), Soft(), Tilted()],
           quick=True)
    assert main(["report", str(folder)]) == 0
    return folder


def test_the_form_writes_scene_limits_units_and_behaviours_as_the_cli_reads_them(
        page_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    found, expected, errors = form_and_cli(page_run, PROFILES, capsys)
    assert errors == []
    assert found == expected
    answers = [cli_rows(page_run, options, capsys) for _, options in PROFILES]
    assert any(row[1] == "fail" for row in answers[0])  # the damped and the soft engine
    assert [row[1] for row in answers[3] if row[0] == "fake-tilted"] == ["fail"]
    assert [row[1] for row in answers[4] if row[0] == "fake-tilted"] == ["pass"]
