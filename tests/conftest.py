"""Shared fixtures: where the Middlebury reference scenes are (STEREO_SERVO_DATA)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest


def _middlebury() -> Path | None:
    root = os.environ.get("STEREO_SERVO_DATA")
    if not root:
        return None
    d = Path(root) / "middlebury"
    return d if (d / "cones").is_dir() else None


@pytest.fixture(scope="session")
def middlebury() -> Path:
    d = _middlebury()
    if d is None:
        pytest.skip("Middlebury scenes not found: set STEREO_SERVO_DATA to shared/data "
                    "(make test does when ../shared/data exists)")
    return d
