"""numba's cache made safe between processes compiling at once: lock_cache_files, installed by
importing host.stereo (every process that compiles one of our kernels imports it first)."""

from __future__ import annotations

import errno
import functools
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import IO, Any

if sys.platform == "win32":
    import msvcrt

    def _lock(f: IO[str]) -> None:
        f.seek(0)  # msvcrt locks bytes from the file's position: byte 0 of the lock file
        while True:  # LK_LOCK gives up after 10 tries a second apart (EDEADLOCK); a compile can
            try:  # take longer. Any other error (a bad descriptor, no access) is raised
                msvcrt.locking(f.fileno(), msvcrt.LK_LOCK, 1)
                return
            except OSError as e:
                if e.errno != errno.EDEADLOCK:
                    raise

    def _unlock(f: IO[str]) -> None:
        f.seek(0)
        msvcrt.locking(f.fileno(), msvcrt.LK_UNLCK, 1)
else:
    import fcntl

    def _lock(f: IO[str]) -> None:
        fcntl.flock(f, fcntl.LOCK_EX)

    def _unlock(f: IO[str]) -> None:
        fcntl.flock(f, fcntl.LOCK_UN)


@contextmanager
def exclusive(path: str) -> Iterator[None]:
    """An exclusive lock between processes on the file at path (created if missing), held for
    the with block: flock where there is fcntl (Linux, macOS), msvcrt.locking on Windows."""
    with open(path, "a") as f:
        _lock(f)
        try:
            yield
        finally:
            _unlock(f)


def lock_cache_files() -> None:
    """Make numba's cache updates safe between processes compiling at once (the warm step's
    parts, host servo's and host tune's worker processes, Ray's workers, pytest's workers).
    numba's IndexDataCacheFile.save reads a function's index, adds its new signature with the
    first free data file number and writes both back; two processes adding different
    signatures of one function at once can both take number 1, and the index then names the
    other signature's machine code. Each save and load here holds an exclusive lock on a file
    beside the function's index for its read-modify-write."""
    from numba.core import caching

    cls: Any = caching.IndexDataCacheFile
    if getattr(cls, "locked_by_stereo_servo", False):
        return

    def locked(fn: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(fn)
        def run(self: Any, *args: Any) -> Any:
            os.makedirs(self._cache_path, exist_ok=True)
            with exclusive(self._index_path + ".lock"):
                return fn(self, *args)
        return run

    cls.save, cls.load = locked(cls.save), locked(cls.load)
    cls.locked_by_stereo_servo = True
