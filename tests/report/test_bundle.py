"""The report inlines plotly's cartesian partial bundle, fetched at setup and checked by hash."""

from __future__ import annotations

import base64
import hashlib
import io
import re
import tarfile
from dataclasses import replace
from pathlib import Path

import pytest

from crosscheck.report import bundle, style


def test_setup_fetched_the_pinned_cartesian_bundle_and_the_page_uses_it() -> None:
    text = bundle.cartesian()
    assert text is not None, f"no {bundle.PINNED.path}: 'make venv' fetches it"
    assert f"plotly.js (cartesian - minified) v{bundle.PINNED.version}" in text[:200]
    assert style.plotly_js() == text
    assert len(text) < 2_000_000  # the full bundle is 4.8 MB


def test_the_declared_trace_list_is_the_bundles() -> None:
    text = bundle.cartesian()
    assert text is not None
    assert set(re.findall(r'moduleType:"trace",name:"(\w+)"', text)) == bundle.TRACES


def tarball(member: str, content: bytes) -> bytes:
    out = io.BytesIO()
    with tarfile.open(fileobj=out, mode="w:gz") as archive:
        info = tarfile.TarInfo(member)
        info.size = len(content)
        archive.addfile(info, io.BytesIO(content))
    return out.getvalue()


def integrity(data: bytes) -> str:
    return "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode()


def test_a_download_is_used_only_when_its_hash_is_the_pinned_one() -> None:
    data = tarball(bundle.PINNED.member, b"/* plotly */")
    pinned = replace(bundle.PINNED, integrity=integrity(data))
    assert bundle.verified(data, pinned) == "/* plotly */"
    tampered = tarball(bundle.PINNED.member, b"/* not plotly */")
    with pytest.raises(ValueError, match="SHA-512"):
        bundle.verified(tampered, pinned)
    wrong_member = tarball("package/other.js", b"x")
    with pytest.raises(KeyError):
        bundle.verified(wrong_member, replace(pinned, integrity=integrity(wrong_member)))


def test_without_the_bundle_the_page_falls_back_to_the_full_one(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    absent = replace(bundle.PINNED, package="no-such-bundle")
    monkeypatch.setattr(bundle.sys, "prefix", str(tmp_path))
    assert bundle.cartesian(absent) is None
    assert bundle.cartesian(replace(bundle.PINNED, version="0.0.1")) is None


def test_a_chart_the_bundle_cannot_draw_is_refused() -> None:
    with pytest.raises(ValueError, match="surface"):
        style.plot_div({"data": [{"type": "scatter"}, {"type": "surface"}]}, "c")
