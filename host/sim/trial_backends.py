"""Where trials run: in this process, in worker processes on this machine, or as Ray tasks (on a
local cluster bound to 127.0.0.1, or on a cluster at an address). Each yields trials as they
finish; a trial's result depends on its job alone, never on the backend."""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from host.errors import HostError


def one_thread() -> None:
    """A trial computes on one thread: the workers are the parallelism, and the result cannot
    depend on how many threads a machine or a backend gives it (BLAS's thread count changes the
    last bits of the chessboard calibration; Ray sets OMP_NUM_THREADS=1 in its workers)."""
    import cv2
    import numba
    from threadpoolctl import threadpool_limits

    cv2.setNumThreads(1)
    numba.set_num_threads(1)
    threadpool_limits(1)


def _run(job: tuple[Callable[[Any], Any], Any]) -> Any:
    fn, arg = job
    return fn(arg)


def in_process(fn: Callable[[Any], Any], jobs: Sequence[Any]) -> Iterator[Any]:
    one_thread()
    for job in jobs:
        yield fn(job)


def processes(fn: Callable[[Any], Any], jobs: Sequence[Any], workers: int) -> Iterator[Any]:
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(max(1, min(workers, len(jobs))), initializer=one_thread) as pool:
        yield from pool.imap_unordered(_run, [(fn, j) for j in jobs])


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise HostError("--ray needs Ray: pip install 'stereo-servo[ray]'") from None
    return ray


def on_ray(fn: Callable[[Any], Any], jobs: Sequence[Any], address: str | None,
           workers: int) -> Iterator[Any]:
    """Ray tasks, one a trial. address None: a local cluster of `workers` CPUs started here,
    its node bound to 127.0.0.1 (no dashboard, no usage report); else the cluster there."""
    ray = _ray()
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    started = not ray.is_initialized()
    if started:
        kw: dict[str, Any] = {"include_dashboard": False, "logging_level": "ERROR",
                              "log_to_driver": False}
        if address is None:
            kw |= {"num_cpus": workers, "_node_ip_address": "127.0.0.1"}
        try:
            ray.init(address=address, **kw)
        except Exception as e:  # Ray raises bare Exception for a node that did not start
            ray.shutdown()
            first = str(e).splitlines()[0] if str(e) else type(e).__name__
            raise HostError(f"cannot start Ray on {address or 'a local cluster'}: "
                            f"{first}") from None
    task = ray.remote(num_cpus=1)(_ray_task)
    pending = [task.remote(fn, j) for j in jobs]
    try:
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            yield ray.get(done[0])
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        if started:
            ray.shutdown()


def _ray_task(fn: Callable[[Any], Any], job: Any) -> Any:
    one_thread()
    return fn(job)
