"""numba's cache under processes compiling at once (the warm step's parts, pytest's workers):
host.stereo.warm.lock_cache_files makes each index update whole."""

from __future__ import annotations

import threading
import time

from numba.core.caching import IndexDataCacheFile

from host.stereo.warm import lock_cache_files


def test_two_signatures_saved_at_once_each_keep_their_own_machine_code(tmp_path) -> None:
    # numba's save reads the index, takes the first free data file number and writes the index
    # back: the first save is held between its read and its write while a second save of
    # another signature of the same function runs (two processes; here two threads, each
    # with its own lock file descriptor). Unlocked, both take number 1 and one signature is
    # lost or names the other's code.
    lock_cache_files()
    first = IndexDataCacheFile(str(tmp_path), "kernel-1.py311", ("source", 1))
    second = IndexDataCacheFile(str(tmp_path), "kernel-1.py311", ("source", 1))
    started = threading.Event()
    write_index = first._save_index

    def held(overloads):
        started.wait(5)
        time.sleep(0.5)  # the second save, unlocked, is done by now
        write_index(overloads)

    first._save_index = held
    other = threading.Thread(target=lambda: (started.set(), second.save("sig b", "code b")))
    saving = threading.Thread(target=first.save, args=("sig a", "code a"))
    saving.start()
    time.sleep(0.1)  # the first save has read the index and waits
    other.start()
    saving.join(10)
    other.join(10)
    reader = IndexDataCacheFile(str(tmp_path), "kernel-1.py311", ("source", 1))
    assert (reader.load("sig a"), reader.load("sig b")) == ("code a", "code b")
