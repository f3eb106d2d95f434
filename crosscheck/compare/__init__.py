"""Comparing runs.

Two runs' verdicts, timing and cost (`crosscheck compare`), a run against its baseline
(`changes`, `check`) and the CI outputs (JUnit, markdown).
"""
