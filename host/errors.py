"""The one exception type the CLI turns into a one-line message and exit status 2, and how
the CLI states the other errors that bad user data or a signal raise inside libraries."""

from __future__ import annotations

import signal


class HostError(Exception):
    """A problem with the user's input or environment, stated in one line."""

    status = 2  # the exit status


class NotReached(HostError):
    """The command ran but did not reach its goal (the servo never held at the target)."""

    status = 3


class RecordingEnded(NotReached):
    """A replay ran out before the robot held at the target."""

    status = 4


class Interrupted(KeyboardInterrupt):
    """A signal that ends a command like Ctrl-C does (SIGTERM, SIGHUP); exit status 128+n."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def _chain(e: BaseException) -> list[BaseException]:
    seen: list[BaseException] = []
    while e is not None and e not in seen:
        seen.append(e)
        e = e.__cause__ or e.__context__  # type: ignore[assignment]
    return seen


def _first_line(e: BaseException) -> str:
    text = str(e).strip()
    return text.splitlines()[0] if text else type(e).__name__


def describe(e: BaseException) -> tuple[int, str] | None:
    """(exit status, one line) for an error the user's data or a signal caused; None for a
    bug, which keeps its traceback."""
    for link in _chain(e):  # numba's parallel code may wrap Ctrl-C in a SystemError
        if isinstance(link, KeyboardInterrupt):
            signum = getattr(link, "signum", signal.SIGINT)
            name = signal.Signals(signum).name
            return 128 + signum, "interrupted" + ("" if signum == signal.SIGINT else f" ({name})")
    if isinstance(e, NotReached):
        return e.status, f"not reached: {e}"
    if isinstance(e, HostError):
        return e.status, f"error: {e}"
    if isinstance(e, OSError):
        where = f"{e.filename}: " if e.filename else ""
        return 2, f"error: {where}{(e.strerror or _first_line(e)).lower()}"
    if isinstance(e, UnicodeDecodeError):
        return 2, (f"error: a file is not UTF-8 text (byte 0x{e.object[e.start]:02X} at "
                   f"{e.start})")
    import cv2

    if isinstance(e, cv2.error):
        return 2, f"error: OpenCV refused the input ({_first_line_cv(e)})"
    if isinstance(e, ValueError):
        return 2, f"error: {_first_line(e)}"
    return None


def _first_line_cv(e: BaseException) -> str:
    err = getattr(e, "err", "") or _first_line(e)
    func = getattr(e, "func", "")
    return f"{func}: {err}" if func else err
