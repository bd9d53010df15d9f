"""A firmware that does not compile is a failure, never a skip; test images stay out of git."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from host.emulator import build

ROOT = Path(__file__).resolve().parents[2]


def test_a_compile_error_raises_build_failed_not_tool_missing(tmp_path: Path,
                                                              firmware_elf: Path) -> None:
    # firmware_elf first: without avr-gcc this test skips with the toolchain's reason
    shutil.copytree(ROOT / "protocol" / "c", tmp_path / "protocol" / "c")
    fw = tmp_path / "firmware" / "atmega328"
    shutil.copytree(ROOT / "firmware" / "atmega328", fw,
                    ignore=shutil.ignore_patterns("build"))
    robot = fw / "core" / "robot.c"
    robot.write_text(robot.read_text().replace("void robot_tick(", "void robot_tick(int x, ", 1))
    with pytest.raises(build.BuildFailed, match="firmware build failed"):
        build.firmware_elf(firmware=fw)
    assert not issubclass(build.BuildFailed, build.ToolMissing)


def test_test_images_are_built_in_ignored_folders(firmware_elf: Path, hang_elf: Path) -> None:
    for elf in (firmware_elf, hang_elf):
        rel = elf.relative_to(ROOT)
        assert "build" in rel.parts
        ignored = subprocess.run(["git", "-C", str(ROOT), "check-ignore", "-q", str(rel)])
        assert ignored.returncode == 0, f"{rel} is not ignored by git"
    tracked = subprocess.run(["git", "-C", str(ROOT), "ls-files", "firmware", "*.elf", "*.hex"],
                             capture_output=True, text=True).stdout
    assert not [f for f in tracked.split() if f.endswith((".elf", ".hex"))]
