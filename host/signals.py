"""Signals that end a command the way Ctrl-C does, so every exit runs the same clean-up
(the robot's STOP, the run's log and plot)."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

from host.errors import Interrupted

ENDING = (signal.SIGTERM, signal.SIGHUP)


@contextlib.contextmanager
def signals_interrupt(signums: tuple[int, ...] = ENDING) -> Iterator[None]:
    """Inside the block the signals raise Interrupted (a KeyboardInterrupt) in the main
    thread; the first one only: a second, during the clean-up, is ignored so that the clean-up
    can finish. The previous handlers come back at the end."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    fired = False

    def handler(signum: int, _frame: object) -> None:
        nonlocal fired
        if not fired:
            fired = True
            raise Interrupted(signum)

    previous = {s: signal.signal(s, handler) for s in signums}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
