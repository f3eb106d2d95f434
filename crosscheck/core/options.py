"""Run options: how a run runs, the same for every case, recorded in ``run.json``.

>>> RunOptions(quick=True).timeout_s
5.0
>>> RunOptions.from_json({"quick": True, "jobs": 2}).jobs
2
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

QUICK_SCENE_STEPS = 1000
"""``--quick`` runs a scene only up to this many steps (the rest are ``skip`` rows)."""


@dataclass(frozen=True, slots=True)
class RunOptions:
    """How a run runs, the same for every case (the run's options, recorded in run.json).

    ``quick`` is the run's ``--quick``: no timing phase, and scenes over
    :data:`QUICK_SCENE_STEPS` steps skipped (:meth:`skips`).  ``timeout_s``
    limits one case x engine (prepare, query and timing) in its worker;
    ``isolate`` False runs engines in this process (no crash safety); ``jobs``
    is the number of cases run at once in the verdict pass; ``scheduler`` a
    Dask scheduler address to run cases on instead (see
    ``crosscheck.run.distributed``).

    The timing phase (``crosscheck.run.timing_phase``) follows the verdict
    pass, one case at a time: ``timing_cases`` cases per engine x kind (0: no
    timing phase), drawn at random with ``timing_seed`` across every case
    family; each timed with ``samples`` kept samples of at least
    ``min_sample_s`` seconds after a warm-up, scenes run ``scene_repeats``
    times; ``pin`` pins the engine's worker and this process to different
    cores where the OS allows it.

    ``worker_memory_mb`` is the resident memory an engine's worker may reach: past it
    between cases the worker is recycled, past it during a case the worker is killed
    and the case is ``crash`` ("memory limit"); see ``crosscheck.run.worker``.

    ``repeat_check``: after the verdict pass, every pair with a ``disagree``, ``error`` or
    ``crash`` row (and no ``timeout``) is asked once more in a fresh worker process; a pair
    whose answer changes is flagged ``nondeterministic`` (see ``crosscheck.run.repeat``).

    ``timer``: ``"wall"`` times the sample on the wall clock only; ``"instructions"`` also
    counts each sampled pair's instructions per query under Valgrind's callgrind, in one
    Valgrind process per engine library (see ``crosscheck.run.cost``).
    """

    quick: bool = False
    min_sample_s: float = 0.001
    samples: int = 10
    timeout_s: float = 5.0
    isolate: bool = True
    jobs: int = 1
    timing_cases: int = 12
    timing_seed: int = 0
    scene_repeats: int = 5
    pin: bool = True
    scheduler: str | None = None
    worker_memory_mb: float = 2048.0
    repeat_check: bool = False
    timer: str = "wall"

    def skips(self, step_count: int) -> bool:
        """Whether the run skipped a scene of ``step_count`` steps for every engine (``--quick``).

        >>> RunOptions(quick=True).skips(30_000), RunOptions().skips(30_000)
        (True, False)
        """
        return self.quick and step_count > QUICK_SCENE_STEPS

    def to_json(self) -> dict[str, Any]:
        """The options as plain JSON values."""
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RunOptions:
        """Options from :meth:`to_json` output; keys this version does not know are ignored."""
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in known})
