"""plotly.js for the page: the cartesian partial bundle, fetched once at setup, checked by hash.

The report draws only cartesian traces (scatter and bar), so it needs
plotly's *cartesian* partial bundle (1.5 MB) rather than the full one that
the ``plotly`` wheel ships (4.8 MB).  The partial bundle is not on PyPI; it
is the npm package ``plotly.js-cartesian-dist-min`` of exactly the plotly.js
version the pinned ``plotly`` wheel was built for.  ``make`` fetches it once
into the virtual environment (``python -m crosscheck.report.bundle``) and
checks it against the registry's pinned SHA-512, so nothing of plotly's is
copied into this repository and nothing is fetched while rendering.

Without it (a setup that did not fetch it, or a ``plotly`` upgraded without
pinning the matching bundle here) the page inlines the wheel's full bundle and
:func:`script` says so in a warning: the report is right, only larger.

>>> PINNED.url
'https://registry.npmjs.org/plotly.js-cartesian-dist-min/-/plotly.js-cartesian-dist-min-4.1.1.tgz'
"""

from __future__ import annotations

import base64
import functools
import hashlib
import io
import sys
import tarfile
import urllib.request
import warnings
from dataclasses import dataclass
from pathlib import Path

from plotly.offline import get_plotlyjs, get_plotlyjs_version

TRACES = frozenset({"bar", "box", "contour", "heatmap", "histogram", "histogram2d",
                    "histogram2dcontour", "image", "pie", "scatter", "scatterternary", "violin"})
"""The trace types the cartesian bundle registers (read from the bundle of the pinned version)."""


@dataclass(frozen=True)
class Bundle:
    """One pinned npm release of a plotly.js partial bundle."""

    package: str
    version: str
    integrity: str
    """The registry's ``dist.integrity``: ``sha512-`` and the base64 digest of the tarball."""
    member: str
    """The minified script inside the tarball."""

    @property
    def url(self) -> str:
        """The tarball's address on the npm registry."""
        name = self.package
        return f"https://registry.npmjs.org/{name}/-/{name}-{self.version}.tgz"

    @property
    def path(self) -> Path:
        """Where setup puts the script: inside the virtual environment."""
        return Path(sys.prefix) / "share" / "crosscheck" / f"{self.package}-{self.version}.js"


PINNED = Bundle(
    package="plotly.js-cartesian-dist-min", version="4.1.1",
    integrity="sha512-o8GrFeusncwBIxbBynRJpY4pkgVB6caM+JLpwrLYbbsO7dZ8FJ+"
              "SVN2Fr+L7kiG/Z6w4P5O0Jus/Qr5EefHVeg==",
    member="package/plotly-cartesian.min.js")
"""The cartesian bundle of the plotly.js version that the locked ``plotly`` wheel ships."""


def verified(tarball: bytes, bundle: Bundle = PINNED) -> str:
    """The bundle's script from its npm tarball, after checking the tarball's SHA-512.

    >>> verified(b"not the tarball")
    Traceback (most recent call last):
    ValueError: plotly.js-cartesian-dist-min 4.1.1: the download's SHA-512 is not the pinned one
    """
    digest = base64.b64encode(hashlib.sha512(tarball).digest()).decode("ascii")
    if f"sha512-{digest}" != bundle.integrity:
        raise ValueError(f"{bundle.package} {bundle.version}: the download's SHA-512 "
                         "is not the pinned one")
    with tarfile.open(fileobj=io.BytesIO(tarball), mode="r:gz") as archive:
        member = archive.extractfile(bundle.member)
        if member is None:
            raise ValueError(f"{bundle.url} has no {bundle.member}")
        return member.read().decode("utf-8")


def fetch(bundle: Bundle = PINNED) -> Path:
    """Download, verify and store the bundle (nothing to do when it is already there)."""
    if bundle.path.exists():
        return bundle.path
    with urllib.request.urlopen(bundle.url, timeout=120) as response:
        text = verified(response.read(), bundle)
    bundle.path.parent.mkdir(parents=True, exist_ok=True)
    partial = bundle.path.with_suffix(".part")
    partial.write_text(text, encoding="utf-8")
    partial.replace(bundle.path)
    return bundle.path


def cartesian(bundle: Bundle = PINNED) -> str | None:
    """The stored partial bundle, if setup fetched it and it matches the wheel's plotly.js."""
    if bundle.version != get_plotlyjs_version() or not bundle.path.exists():
        return None
    return bundle.path.read_text(encoding="utf-8")


@functools.cache
def script() -> str:
    """The plotly.js the page inlines: the cartesian bundle, else the wheel's full one."""
    text = cartesian()
    if text is not None:
        return text
    warnings.warn(f"plotly.js {get_plotlyjs_version()}: no cartesian bundle at {PINNED.path} "
                  f"(pinned {PINNED.version}; run 'make venv' or 'python -m "
                  "crosscheck.report.bundle'); the report inlines the full 4.8 MB bundle",
                  stacklevel=2)
    return str(get_plotlyjs())


def main() -> int:
    """``python -m crosscheck.report.bundle``: fetch the pinned bundle (setup runs this)."""
    if PINNED.version != get_plotlyjs_version():
        print(f"plotly ships plotly.js {get_plotlyjs_version()} but crosscheck pins the "
              f"cartesian bundle {PINNED.version}: update PINNED in {__file__}", file=sys.stderr)
        return 1
    try:
        path = fetch()
    except (OSError, ValueError) as exc:
        print(f"could not fetch {PINNED.url}: {exc}", file=sys.stderr)
        return 1
    print(f"plotly.js cartesian bundle {PINNED.version}: {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
