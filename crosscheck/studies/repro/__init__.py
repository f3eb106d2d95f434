"""The repro study: one standalone Python script per case x engine, to paste into a bug report.

- :mod:`~crosscheck.studies.repro.script`: a script from a stored run (inputs, printing),
  and the scripts of a run's breaking pairs;
- :mod:`~crosscheck.studies.repro.verdicts`: what a script says beside the engine's answer
  (the exact truth, each verdict against its float64 bound, the declared conventions);
- :mod:`~crosscheck.studies.repro.calls`: the engine part of any adapter whose engine calls
  are a module (:class:`~crosscheck.core.contract.CallsAdapter`, built-in or a plug-in's):
  that module's source, verbatim, and the call on the case's exact inputs;
- :mod:`~crosscheck.studies.repro.code`: what every engine part is made of (exact
  literals, guards);
- :mod:`~crosscheck.studies.repro.issue`: a Markdown bug report around a script.
"""

from crosscheck.studies.repro.issue import issue_report
from crosscheck.studies.repro.script import (
    ReproError,
    Script,
    breaking_pairs,
    engines_for,
    scripted,
    scripts,
    write_run_scripts,
)

__all__ = ["ReproError", "Script", "breaking_pairs", "engines_for", "issue_report", "scripted",
           "scripts", "write_run_scripts"]
