"""Signals held while a command writes what the user keeps (a run's log and plot): a Ctrl-C
(or SIGTERM, SIGHUP) then waits until the files are whole, and ends the command after."""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator

from host.errors import Interrupted

HELD = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@contextlib.contextmanager
def signals_held(signums: tuple[int, ...] = HELD) -> Iterator[None]:
    """Inside the block the signals are noted, not acted on; after it, the first one noted
    ends the command (KeyboardInterrupt for SIGINT, else Interrupted), unless an exception is
    already on its way out (an interruption, say), which then goes on as it was."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[int] = []
    previous = {s: signal.signal(s, lambda n, _f: noted.append(n)) for s in signums}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
    if noted and sys.exc_info()[0] is None:
        raise KeyboardInterrupt if noted[0] == signal.SIGINT else Interrupted(noted[0])
