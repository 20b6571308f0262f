"""Locate the URDFs shipped by the example-robot-data package (test-only dependency)."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path


def robots_dir() -> Path | None:
    """The folder ``.../share/example-robot-data/robots`` of the installed package, or None."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    for f in dist.files or []:
        parts = Path(str(f)).parts
        if "robots" in parts and parts[-1].endswith(".urdf"):
            full = Path(str(dist.locate_file(f)))
            idx = full.parts.index("robots")
            return Path(*full.parts[: idx + 1])
    return None


def urdf(relative: str) -> Path | None:
    """Path of a URDF under the robots folder, or None when the package is missing."""
    root = robots_dir()
    if root is None:
        return None
    p = root / relative
    return p if p.is_file() else None
