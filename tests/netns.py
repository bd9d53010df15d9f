"""A loopback-only network namespace for tests that start servers (../shared/local-servers.md)."""

from __future__ import annotations

import shutil
import subprocess

import pytest


def loopback_only() -> list[str]:
    """The command prefix that runs a shell inside a loopback-only network namespace (skips the
    test where unshare or ip is absent, or unshare -n is not permitted)."""
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        pytest.skip("unshare or ip is not installed")
    probe = subprocess.run(["unshare", "-n", "sh", "-c", "ip link set lo up"],
                           capture_output=True, text=True)
    if probe.returncode:
        pytest.skip(f"unshare -n is not permitted here: {probe.stderr.strip()}")
    return ["unshare", "-n", "sh", "-c"]
