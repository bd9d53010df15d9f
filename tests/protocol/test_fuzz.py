"""A short run of the C parser's sanitizer fuzz driver (the long run is in make bench)."""

from __future__ import annotations

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_c_parser_survives_random_and_mutated_input_under_sanitizers(native_build) -> None:
    exe = native_build("fuzz_frame", [ROOT / "tests/c/fuzz_frame.c", ROOT / "protocol/c/frame.c"])
    r = subprocess.run([str(exe), "20000", "12345"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "burst_corruptions 20000 accepted 0" in r.stdout
    assert "frames_after_garbage 20000 lost 0" in r.stdout
