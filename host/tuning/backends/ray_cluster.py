"""The Ray backend: scores parameter sets as Ray tasks, on a local cluster it starts or on an
existing one at an address. The score (with its images) goes to the object store once."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
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
                kw["num_cpus"] = os.cpu_count() or 1
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
