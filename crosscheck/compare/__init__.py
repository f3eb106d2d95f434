"""Comparing runs.

Two runs' verdicts, timing and cost (`crosscheck compare`), a run against its baseline
(`check`) and the CI outputs (JUnit, markdown).  What changed from one engine version to
another is :mod:`crosscheck.results.changes`: the report shows it too, and the report sits
below this package.
"""
