"""The compiled millisecond (host/emulator/fast_ms.py) that does not build is a failure on every
call in the process, not on the first only: a campaign's worker would otherwise fail one trial and
run the rest on the Python loop without a word."""

from __future__ import annotations

import shutil

import pytest

from host.emulator import fast_ms
from host.emulator.build import BuildFailed


def test_a_failed_build_fails_every_call(monkeypatch, tmp_path) -> None:
    if shutil.which("gcc") is None:
        pytest.skip("gcc is not installed: the compiled millisecond is not built at all")
    monkeypatch.delenv("STEREO_SERVO_NO_FAST_MS", raising=False)
    monkeypatch.setattr(fast_ms, "CACHE", tmp_path)
    monkeypatch.setattr(fast_ms, "SOURCE", "this is not C;\n")
    monkeypatch.setattr(fast_ms, "_lib", None)
    monkeypatch.setattr(fast_ms, "_tried", False)
    monkeypatch.setattr(fast_ms, "_failed", None)
    for _ in range(2):
        with pytest.raises(BuildFailed, match="compiled millisecond"):
            fast_ms.library()
