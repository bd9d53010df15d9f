"""The numba cache lock (host.stereo.numba_cache) where there is no fcntl (Windows): the module
imports and its saves hold msvcrt's lock, seen here through a stand-in msvcrt on this machine."""

from __future__ import annotations

import errno
import importlib.util
import subprocess
import sys
import types
from collections.abc import Callable
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

# A fresh interpreter made to look like Windows for the lock's module only: fcntl cannot be
# imported, sys.platform says win32 while host/stereo/numba_cache.py is loaded (numba and the
# test's helpers are imported before, as they would be on Windows), and msvcrt.locking is a
# stand-in that really excludes: LK_LOCK takes a lock per lock file, LK_UNLCK gives it back.
SCRIPT = r"""
import importlib.util, os, sys, threading, types
from numba.core.caching import IndexDataCacheFile as cache_file
from tests.stereo.test_warm import _save_two_signatures_at_once  # installs the Linux lock
for name in ("save", "load"):  # take it off again
    fn = getattr(cache_file, name)
    setattr(cache_file, name, getattr(fn, "__wrapped__", fn))
cache_file.locked_by_stereo_servo = False

locks, calls = {}, []
def locking(fd, mode, nbytes):
    assert nbytes == 1 and os.lseek(fd, 0, os.SEEK_CUR) == 0, "msvcrt locks from byte 0"
    lock = locks.setdefault(os.fstat(fd).st_ino, threading.Lock())
    calls.append(mode)
    lock.acquire() if mode == msvcrt.LK_LOCK else lock.release()
msvcrt = types.ModuleType("msvcrt")
msvcrt.LK_LOCK, msvcrt.LK_UNLCK, msvcrt.locking = 1, 0, locking
sys.modules["msvcrt"], sys.modules["fcntl"] = msvcrt, None

platform, sys.platform = sys.platform, "win32"
spec = importlib.util.spec_from_file_location("numba_cache_on_windows",
                                              "host/stereo/numba_cache.py")
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
sys.platform = platform
module.lock_cache_files()
print(_save_two_signatures_at_once(sys.argv[1]), calls.count(1), calls.count(0))
"""


def test_the_cache_lock_imports_without_fcntl_and_locks_with_msvcrt(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path)], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    # both signatures keep their own code (the stand-in lock really excluded the two saves),
    # and every lock taken was given back
    saved, locked, unlocked = run.stdout.rsplit(" ", 2)
    assert saved == "('code a', 'code b')"
    assert int(locked) >= 4 and int(locked) == int(unlocked)


def _windows_module(monkeypatch: pytest.MonkeyPatch,
                    locking: Callable[[int, int, int], None]) -> types.ModuleType:
    """host/stereo/numba_cache.py loaded as on Windows, its msvcrt.locking the given stand-in."""
    msvcrt = types.ModuleType("msvcrt")
    msvcrt.LK_LOCK, msvcrt.LK_UNLCK, msvcrt.locking = 1, 0, locking  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "msvcrt", msvcrt)
    monkeypatch.setitem(sys.modules, "fcntl", None)
    monkeypatch.setattr(sys, "platform", "win32")
    spec = importlib.util.spec_from_file_location("numba_cache_win",
                                                  ROOT / "host/stereo/numba_cache.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_windows_lock_waits_out_a_held_lock_and_raises_any_other_error(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """LK_LOCK's EDEADLOCK (10 tries failed: another process compiles) is waited out; a bad
    descriptor or no access is raised at once, never retried for ever."""
    tries: list[int] = []

    def held_twice(fd: int, mode: int, nbytes: int) -> None:
        tries.append(mode)
        if len(tries) <= 2:
            raise OSError(errno.EDEADLOCK, "Resource deadlock avoided")

    module = _windows_module(monkeypatch, held_twice)
    with open(tmp_path / "lock", "a") as f:
        module._lock(f)
    assert tries == [1, 1, 1]

    def bad(fd: int, mode: int, nbytes: int) -> None:
        tries.append(mode)
        if len(tries) > 10:
            raise AssertionError("retried a permanent error")
        raise OSError(errno.EBADF, "Bad file descriptor")

    tries.clear()
    module = _windows_module(monkeypatch, bad)
    with open(tmp_path / "lock", "a") as f:
        try:
            module._lock(f)
        except OSError as e:
            assert e.errno == errno.EBADF
        else:
            raise AssertionError("no error")
    assert tries == [1]
