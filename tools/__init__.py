"""The project's own tools for its documentation, run from the repository root.

- :mod:`tools.cli_page`: ``docs/generated/cli.md``, the CLI reference written from the
  argument parser (``make docs`` regenerates it);
- :mod:`tools.docs_figures`: every other file of ``docs/generated/`` from a stored run and a
  bench.json (``make docs-figures RUN=DIR``), and the README's generated blocks;
- :mod:`tools.stated_numbers`: the check that no page states a measured count, size or
  time outside ``docs/generated/``;
- :mod:`tools.measure_report`: a report page's load figures in headless Chromium
  (``python -m tools.measure_report RUN_DIR``);
- :mod:`tools.measure_setup`: the set-up time of ``make venv`` and ``make test`` in a fresh
  clone (``python -m tools.measure_setup``);
- :mod:`tools.stiff_precision`: the precision of the stiff MuJoCo contact, measured on random
  cases outside the suite (the source of that variant's ``response_rtol``);
- :mod:`tools.label_changes`: the label changes between two runs, per engine variant, in
  Markdown (``python -m tools.label_changes OLD_RUN NEW_RUN``);
- :mod:`tools.audit_dynamics`: a self-audit of a run's dynamic labels, a stratified sample
  re-judged by independent recomputation (``python -m tools.audit_dynamics RUN_DIR``).

Nothing in the harness imports this package: it is not installed with it.
"""
