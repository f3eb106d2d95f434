"""The test plug-in distribution (tests/data/plugin_engine) pip-installed into a folder of its
own, once per module: the fixture of tests/adapters/test_plugins.py, shared by name."""

from tests.adapters.test_plugins import site  # noqa: F401  (a fixture: tests ask for it by name)
