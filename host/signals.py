"""Signals during a command: ending it the way Ctrl-C does, so every exit runs the same
clean-up (the robot's STOP, the run's log and plot), or held while it writes what the user
keeps."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

from host.errors import Interrupted

ENDING = (signal.SIGTERM, signal.SIGHUP)
HELD = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@contextlib.contextmanager
def _handling(signums: tuple[int, ...], handler: Callable[[int, Any], None]) -> Iterator[bool]:
    """handler for signums inside the block, the previous handlers back after it; yields
    False (and installs nothing) outside the main thread, where Python takes no handler."""
    if threading.current_thread() is not threading.main_thread():
        yield False
        return
    previous = {s: signal.signal(s, handler) for s in signums}
    try:
        yield True
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


@contextlib.contextmanager
def signals_interrupt(signums: tuple[int, ...] = ENDING) -> Iterator[None]:
    """Inside the block the signals raise Interrupted (a KeyboardInterrupt) in the main
    thread; the first one only: a second, during the clean-up, is ignored so that the clean-up
    can finish. The previous handlers come back at the end."""
    fired = False

    def handler(signum: int, _frame: object) -> None:
        nonlocal fired
        if not fired:
            fired = True
            raise Interrupted(signum)

    with _handling(signums, handler):
        yield


@contextlib.contextmanager
def signals_held(signums: tuple[int, ...] = HELD) -> Iterator[None]:
    """Inside the block the signals are noted, not acted on; after it, the first one noted
    ends the command (KeyboardInterrupt for SIGINT, else Interrupted), unless an exception is
    already on its way out (an interruption, say), which then goes on as it was."""
    noted: list[int] = []
    with _handling(signums, lambda n, _f: noted.append(n)):
        yield
    if noted and sys.exc_info()[0] is None:
        raise KeyboardInterrupt if noted[0] == signal.SIGINT else Interrupted(noted[0])


@contextlib.contextmanager
def interrupt_ends_at_once(line: str) -> Iterator[None]:
    """Inside the block (the libraries loading, before a command runs: nothing to clean up)
    Ctrl-C writes line to stderr and ends the process at once with status 130. The usual
    KeyboardInterrupt is not safe there: raised inside a C extension's import (numpy's
    PyCapsule_Import of datetime) it comes out as an ImportError, numpy's page-long "bad
    install" message and status 1."""

    def handler(_signum: int, _frame: object) -> None:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
        os._exit(128 + signal.SIGINT)

    with _handling((signal.SIGINT,), handler):
        yield
