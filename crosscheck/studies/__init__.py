"""Layer 7, studies built on runs, one sub-package per study.

- :mod:`crosscheck.studies.fuzz`: fuzz campaigns (generation, lanes, grouped findings);
- :mod:`crosscheck.studies.bench`: the harness's own performance figures (``crosscheck
  bench``: the batch oracle's throughput, harness overhead over raw engine loops, suite time,
  memory, scale-out, and a fuzz campaign's throughput, which is why it may use ``fuzz``);
- :mod:`crosscheck.studies.repro`: standalone repro scripts of a run's breaking pairs.

``fuzz`` and ``repro`` never import each other, nor ``bench`` (``pyproject.toml``'s
import-linter contracts).
"""
