"""Layer 7, the public test kit: the adapter conformance checks and the fake engines.

An engine's own CI runs the checks the built-in adapters pass (as hypothesis ships
``run_conformance_test``)::

    from crosscheck.testing import check_adapter

    def test_my_adapter_honours_the_contract() -> None:
        check_adapter(MyAdapter)

:mod:`crosscheck.testing.fakes` holds fake engines with known behaviour.  The CLI never
imports this package.
"""

from crosscheck.testing.conformance import (
    ConformanceError,
    Failure,
    check_adapter,
    conformance_failures,
)

__all__ = ["ConformanceError", "Failure", "check_adapter", "conformance_failures"]
