"""`host view ...` started as a process for a test, its page's address read from stderr."""

from __future__ import annotations

import contextlib
import re
import subprocess
import sys
from collections.abc import Iterator


@contextlib.contextmanager
def host_view(*argv: str) -> Iterator[str]:
    """host:port of the page of `host view *argv`; the process ends when the block does."""
    proc = subprocess.Popen([sys.executable, "-m", "host", "view", *argv],
                            stderr=subprocess.PIPE, text=True)
    try:
        line = ""
        while not line.startswith("live view: "):
            line = proc.stderr.readline()  # type: ignore[union-attr]
            assert line, "host view ended without printing its address"
        yield re.search(r"http://(\S+)/", line)[1]  # type: ignore[index]
    finally:
        proc.terminate()
        proc.wait(timeout=10)
