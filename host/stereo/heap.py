"""Keep freed large blocks in the C heap, so the matchers' per-call arrays cost no page faults.

glibc hands a block of 128 KiB or more (a threshold that grows with use) straight to the OS
with mmap and returns it on free, and trims the top of the heap past 128 KiB of free space;
every call of a matcher then touches its arrays as fresh pages (2,278 minor faults and ~4 ms
of system time per own SGM call at 640x480 / 64, 11 % of its CPU time). With blocks up to
32 MiB served from the heap and the heap trimmed only past 1 GiB free, the second call of the
same size reuses the first call's memory: no faults. Elsewhere than glibc this does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util

M_TRIM_THRESHOLD = -1  # glibc's mallopt parameters (malloc.h)
M_MMAP_THRESHOLD = -3
MMAP_BYTES = 32 << 20  # glibc's largest mmap threshold on 64-bit
TRIM_BYTES = 1 << 30


def keep_freed_blocks() -> bool:
    """Set glibc's mmap and trim thresholds (once per process); False where there is no glibc."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_BYTES)) and bool(mallopt(M_TRIM_THRESHOLD,
                                                                        TRIM_BYTES))
