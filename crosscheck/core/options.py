"""Run options: how a run runs, the same for every case, recorded in ``run.json``.

>>> RunOptions(quick=True).timeout_s
5.0
>>> RunOptions.from_json({"quick": True, "jobs": 2}).jobs
2
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any


@dataclass(frozen=True, slots=True)
class RunOptions:
    """How a run runs, the same for every case (the run's options, recorded in run.json).

    ``quick`` is the run's ``--quick``: no timing at all, and scenes over
    ``crosscheck.run.runner.QUICK_SCENE_STEPS`` steps skipped; whether one
    case is timed is decided per case by the runner (see ``timed`` of
    ``crosscheck.run.execute.execute``), never by changing these options.  ``min_sample_s`` and
    ``samples``: the timing loop; ``timeout_s`` limits one case x engine
    (prepare, query and timing) in its worker; ``isolate`` False runs engines
    in this process (no crash safety); ``time_per_group`` times only the first
    that many cases of each case file x kind x dim (0: every case), never
    swapped twins or bad input; ``jobs`` is the number of cases run at once;
    ``scheduler`` a Dask scheduler address to run cases on instead (see
    ``crosscheck.run.distributed``).
    """

    quick: bool = False
    min_sample_s: float = 0.02
    samples: int = 5
    timeout_s: float = 5.0
    isolate: bool = True
    jobs: int = 1
    time_per_group: int = 3
    scheduler: str | None = None

    def to_json(self) -> dict[str, Any]:
        """The options as plain JSON values."""
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RunOptions:
        """Options from :meth:`to_json` output; keys this version does not know are ignored."""
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in known})
