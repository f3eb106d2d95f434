"""The marker of every item of the plugin (``pytest -m crosscheck``), in a module of its own
so that the plugin's entry point and its items both read it without importing each other."""

from __future__ import annotations

MARKER = "crosscheck"
"""The marker of every item of the plugin (``pytest -m crosscheck``)."""
