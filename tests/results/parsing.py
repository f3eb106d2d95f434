"""What the results tests share: counting the JSON-lines files a reader parses."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest

from crosscheck.results import jsonlines


def counting(monkeypatch: pytest.MonkeyPatch) -> Counter[str]:
    """Count the calls of the one JSON-lines reader from now on, by file name."""
    calls: Counter[str] = Counter()
    read = jsonlines.read_lines

    def counted(path: Path) -> list[jsonlines.Line]:
        calls[path.name] += 1
        return read(path)

    monkeypatch.setattr(jsonlines, "read_lines", counted)
    return calls
