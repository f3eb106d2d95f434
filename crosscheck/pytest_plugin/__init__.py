"""The pytest plugin: the crosscheck suite and the conformance kit as pytest items.

Registered through the ``pytest11`` entry point (``crosscheck``), so that in an engine's
own repository ::

    pytest --crosscheck-engine NAME [--crosscheck-cases PATH] [--crosscheck-baseline FILE]

runs the suite on that engine (a plug-in of the ``crosscheck.adapters`` group or a
built-in) into a run folder, then reports one item per case x quantity (x engine, for
several ``--crosscheck-engine``), judged as ``crosscheck check`` judges them
(:mod:`crosscheck.results.baseline`), and one item per check of the conformance kit
(:mod:`crosscheck.testing.conformance`).  The options and what fails are in
docs/pytest-plugin.md.

It is the second face beside the CLI (the top layer, docs/architecture.md): it may use
the engine registry and the public test kit, and never imports ``crosscheck.cli``.

Every pytest run that has crosscheck installed loads this module, so it costs nothing when
its options are not given: it imports only pytest here, adds no item and registers
nothing; :mod:`crosscheck.pytest_plugin.suite` (the library, pandas, the engines) is
imported, and registered as a plugin, only when ``--crosscheck-engine`` is given.
"""

from __future__ import annotations

import pytest

from crosscheck.pytest_plugin.marker import MARKER


def pytest_addoption(parser: pytest.Parser) -> None:
    """The plugin's options, in a group of their own in ``pytest --help``."""
    group = parser.getgroup("crosscheck", "Collision Crosscheck (the crosscheck suite as tests)")
    group.addoption("--crosscheck-engine", action="append", default=[], metavar="NAME",
                    help="run the crosscheck suite and the conformance kit on this engine, a "
                         "built-in or a plug-in (repeatable); without it the plugin does "
                         "nothing")
    group.addoption("--crosscheck-cases", action="append", default=[], metavar="PATH",
                    help="a case file or folder (repeatable; default: the cases/ folder of "
                         "the crosscheck checkout, if the package is installed from one)")
    group.addoption("--crosscheck-baseline", metavar="FILE", default=None,
                    help="judge against this baseline file, as 'crosscheck check' does "
                         "(default: none: every wrong or missing answer fails)")
    group.addoption("--crosscheck-out", metavar="DIR", default=None,
                    help="the run folder to write (default: a new folder in pytest's "
                         "temporary directory; its path is printed at the end)")
    group.addoption("--crosscheck-quick", action="store_true", default=False,
                    help="skip the long scenes, as 'crosscheck run --quick' does")


def pytest_configure(config: pytest.Config) -> None:
    """With ``--crosscheck-engine``: check every option (a bad one is a usage error before
    any work) and register the suite; without it: nothing."""
    if not config.getoption("crosscheck_engine"):
        return
    from crosscheck.pytest_plugin.suite import Suite  # the library loads only when asked for

    config.addinivalue_line("markers", f"{MARKER}: an item of the crosscheck suite or of its "
                                       "conformance kit (pytest --crosscheck-engine NAME)")
    config.pluginmanager.register(Suite.from_config(config), "crosscheck-suite")
