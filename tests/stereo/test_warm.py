"""numba's cache under processes compiling at once (the warm step's parts, the trial and tuning
workers, pytest's workers): host.stereo.numba_cache.lock_cache_files makes each index update
whole, and importing host.stereo installs it in every process that compiles our kernels."""

from __future__ import annotations

import multiprocessing
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from numba.core.caching import IndexDataCacheFile

from host.stereo.numba_cache import lock_cache_files


def _save_two_signatures_at_once(folder: str) -> tuple[object, object]:
    """What the cache then gives for two signatures of one function saved at once: numba's save
    reads the index, takes the first free data file number and writes the index back; the
    first save is held between its read and its write while a second save of another signature
    runs (two processes; here two threads, each with its own lock file descriptor). Unlocked,
    both take number 1 and one signature is lost or names the other's code."""
    first = IndexDataCacheFile(folder, "kernel-1.py311", ("source", 1))
    second = IndexDataCacheFile(folder, "kernel-1.py311", ("source", 1))
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
    reader = IndexDataCacheFile(folder, "kernel-1.py311", ("source", 1))
    return reader.load("sig a"), reader.load("sig b")


def test_two_signatures_saved_at_once_each_keep_their_own_machine_code(tmp_path: Path) -> None:
    lock_cache_files()
    assert _save_two_signatures_at_once(str(tmp_path)) == ("code a", "code b")


def _in_a_worker(folder: str) -> tuple[object, object]:
    import host.stereo.sad  # noqa: F401  what a trial or tuning worker imports to compile

    return _save_two_signatures_at_once(folder)


def test_a_worker_process_that_imports_the_kernels_saves_under_the_lock(tmp_path: Path) -> None:
    # host servo --workers and host tune --workers start fresh interpreters (spawn), which
    # never run the CLI: the lock must come with the kernels themselves
    with ProcessPoolExecutor(1, multiprocessing.get_context("spawn")) as pool:
        got = pool.submit(_in_a_worker, str(tmp_path)).result(timeout=120)
    assert got == ("code a", "code b")
