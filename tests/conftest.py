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


ROOT = Path(__file__).resolve().parent.parent
PROTOCOL_C = ROOT / "protocol" / "c"
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all"]


@pytest.fixture(scope="session")
def native_build(tmp_path_factory):
    """Compile C sources natively with gcc (warnings are errors); returns the executable."""
    import shutil
    import subprocess

    if shutil.which("gcc") is None:
        pytest.skip("gcc not found")
    out_dir = tmp_path_factory.mktemp("native")

    def build(name: str, sources: list[Path], flags: list[str] = (), sanitize: bool = True,
              includes: list[Path] = ()) -> Path:
        exe = out_dir / name
        cmd = ["gcc", "-std=gnu11", "-O1", "-g", "-Wall", "-Wextra", "-Werror",
               f"-I{PROTOCOL_C}", *[f"-I{i}" for i in includes], *(SANITIZE if sanitize else []),
               *flags, *map(str, sources), "-o", str(exe)]
        subprocess.run(cmd, check=True)
        return exe

    return build
