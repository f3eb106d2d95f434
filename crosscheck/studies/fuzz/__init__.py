"""The fuzz study: random cases near engine failure boundaries, run in chunks, findings grouped.

- :mod:`~crosscheck.studies.fuzz.generator`: the cases, chunk by chunk, from a seed;
- :mod:`~crosscheck.studies.fuzz.lanes`: lane processes that run and score whole chunks, crash
  and hang safety per case;
- :mod:`~crosscheck.studies.fuzz.findings`: finding rows, their groups and the case files
  written for them;
- :mod:`~crosscheck.studies.fuzz.shrink`: a finding shrunk to a minimal case that still fails
  the same way;
- :mod:`~crosscheck.studies.fuzz.campaign`: a campaign from start to finish (resumable, its
  chosen findings shrunk), and the bench's throughput figure.
"""

from crosscheck.studies.fuzz.campaign import (
    SHRINK,
    CampaignError,
    campaign_throughput,
    finished_chunks,
    fuzz,
    resume,
    shrink_findings,
    stored_plan,
)
from crosscheck.studies.fuzz.findings import (
    Group,
    Groups,
    Signature,
    by_severity,
    choose,
    group_findings,
    write_findings,
)
from crosscheck.studies.fuzz.generator import CHUNK, Generated, generate, generate_chunk
from crosscheck.studies.fuzz.shrink import MAX_CALLS, Shrunk, shrink_case

__all__ = [
    "CHUNK",
    "MAX_CALLS",
    "SHRINK",
    "CampaignError",
    "Generated",
    "Group",
    "Groups",
    "Shrunk",
    "Signature",
    "by_severity",
    "campaign_throughput",
    "choose",
    "finished_chunks",
    "fuzz",
    "generate",
    "generate_chunk",
    "group_findings",
    "resume",
    "shrink_case",
    "shrink_findings",
    "stored_plan",
    "write_findings",
]
