"""The bench study: ``crosscheck bench``, the harness's own performance figures, each beside its
target, and the comparison of two ``bench.json`` files.

- :mod:`~crosscheck.studies.bench.figures`: every figure, measured and written;
- :mod:`~crosscheck.studies.bench.oracle`: the batch oracle's throughput and agreement;
- :mod:`~crosscheck.studies.bench.streams`: the harness-overhead figures' case streams and
  the harness path over them;
- :mod:`~crosscheck.studies.bench.rawloops`: the engines' own APIs in tight loops;
- :mod:`~crosscheck.studies.bench.counted`: the harness overhead counted in instructions
  under callgrind, in one process (:mod:`~crosscheck.studies.bench.counted_worker`);
- :mod:`~crosscheck.studies.bench.suite`: whole commands timed as subprocesses;
- :mod:`~crosscheck.studies.bench.kit`: what the figures share (:class:`Figure`, memory probes);
- :mod:`~crosscheck.studies.bench.comparison`: ``bench --compare``.
"""

from crosscheck.studies.bench.comparison import BenchFileError, Comparison, compare, load
from crosscheck.studies.bench.figures import FORMAT_VERSION, measure, write
from crosscheck.studies.bench.kit import ROOT, Figure

__all__ = [
    "FORMAT_VERSION",
    "ROOT",
    "BenchFileError",
    "Comparison",
    "Figure",
    "compare",
    "load",
    "measure",
    "write",
]
