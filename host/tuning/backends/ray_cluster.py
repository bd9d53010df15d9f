"""The Ray backend: scores parameter sets as Ray tasks, on a local cluster it starts (bound to
127.0.0.1, so nothing listens beyond this machine and Ray looks up no outside address for its
own) or on an existing one at an address, which must answer within seconds. The score (with
its images) goes to the object store once."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from host.errors import HostError
from host.stereo.params import MatcherParams


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise HostError("--ray needs Ray: pip install 'stereo-servo[ray]'") from None
    return ray


class RayBackend:
    def __init__(self, score: Callable[[MatcherParams], list[float]], address: str | None) -> None:
        ray = _ray()
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        self._started = not ray.is_initialized()
        if self._started:
            kw: dict[str, Any] = {"include_dashboard": False, "logging_level": "ERROR",
                                  "log_to_driver": False}
            if address is None:
                kw |= {"num_cpus": os.cpu_count() or 1, "_node_ip_address": LOCAL_IP}
            else:
                reachable(address)
            with _own_signals():
                _init(ray, address, kw)
        self.parallel = max(1, int(ray.cluster_resources().get("CPU", 1)))
        self._ref = ray.put(score)
        self._task = ray.remote(_evaluate)
        self._ray = ray

    def map(self, params: Sequence[MatcherParams]) -> list[list[float]]:
        refs = [self._task.remote(self._ref, p) for p in params]
        return [list(x) for x in self._ray.get(refs)]

    def close(self) -> None:
        if self._started:
            self._ray.shutdown()


LOCAL_IP = "127.0.0.1"  # the local cluster's node address (../shared/local-servers.md)
CONNECT_S = 3.0  # a cluster's head answers a TCP connection at once, or not at all


def reachable(address: str, timeout_s: float = CONNECT_S) -> None:
    """One line, at once, when nothing answers at host:port (or ray://host:port): Ray itself
    waits minutes for a head that is not there. 'auto' is Ray's own lookup."""
    m = re.fullmatch(r"(?:ray://)?([\w.\-]+):(\d+)", address)
    if m is None:
        return
    try:
        socket.create_connection((m[1], int(m[2])), timeout=timeout_s).close()
    except OSError as e:
        why = "no answer" if isinstance(e, TimeoutError) else (e.strerror or str(e))
        raise HostError(f"--ray {address}: no Ray cluster answers there ({why})") from None


@contextlib.contextmanager
def _own_signals() -> Iterator[None]:
    """Keep the command's signal handlers: ray.init installs a SIGTERM handler that exits with
    status 15 and Ray's stack dump, where the command ends with 143 and one line."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    kept = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for s, h in kept.items():
            signal.signal(s, h)


def _init(ray: Any, address: str | None, kw: dict[str, Any], tries: int = 2) -> None:
    """ray.init, tried again once: a loaded machine can miss Ray's fixed 30 s for a new
    node to register. Any failure becomes one line."""
    for attempt in range(tries):
        try:
            ray.init(address=address, **kw)
            return
        except Exception as e:  # Ray raises bare Exception for a node that did not start
            ray.shutdown()
            if attempt == tries - 1:
                where = address or "a local cluster"
                first = str(e).splitlines()[0] if str(e) else type(e).__name__
                raise HostError(f"cannot start Ray on {where}: {first}") from None


def _evaluate(score: Callable[[MatcherParams], list[float]], params: MatcherParams
              ) -> list[float]:
    return score(params)
