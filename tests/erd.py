"""Locate the URDFs shipped by the example-robot-data package (test-only dependency)."""

from __future__ import annotations

from pathlib import Path


def robots_dir() -> Path | None:
    """The folder ``.../share/example-robot-data/robots`` of the installed package, or None."""
    from serialkin.collision.reference import example_robot_data_share

    share = example_robot_data_share()
    return None if share is None else share / "example-robot-data" / "robots"


def urdf(relative: str) -> Path | None:
    """Path of a URDF under the robots folder, or None when the package is missing."""
    root = robots_dir()
    if root is None:
        return None
    p = root / relative
    return p if p.is_file() else None
