"""The repro study: one standalone Python script per case x engine, to paste into a bug report.

- :mod:`~crosscheck.studies.repro.script`: a script from a stored run (inputs, printing, the
  expected answers), and the scripts of a run's breaking pairs;
- :mod:`~crosscheck.studies.repro.engines`: the engine part for FCL, pymunk and the textbook
  formula;
- :mod:`~crosscheck.studies.repro.pybullet`: the engine part for PyBullet.
"""

from crosscheck.studies.repro.script import (
    ReproError,
    Script,
    breaking_pairs,
    scripts,
    write_run_scripts,
)

__all__ = ["ReproError", "Script", "breaking_pairs", "scripts", "write_run_scripts"]
