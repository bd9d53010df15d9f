"""numba's cache made safe between processes compiling at once: lock_cache_files, installed by
importing host.stereo (every process that compiles one of our kernels imports it first)."""

from __future__ import annotations

import fcntl
import os
from collections.abc import Callable
from typing import Any


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
        def run(self: Any, *args: Any) -> Any:
            os.makedirs(self._cache_path, exist_ok=True)
            with open(self._index_path + ".lock", "a") as f:
                fcntl.flock(f, fcntl.LOCK_EX)
                return fn(self, *args)
        return run

    cls.save, cls.load = locked(cls.save), locked(cls.load)
    cls.locked_by_stereo_servo = True
