"""Stopping a simulator process the same way for every board: terminate, then kill on timeout."""

from __future__ import annotations

import subprocess


def stop(proc: subprocess.Popen[str], timeout_s: float = 5.0) -> None:
    """Terminate proc and wait for it; kill it if it has not exited within timeout_s."""
    if proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
