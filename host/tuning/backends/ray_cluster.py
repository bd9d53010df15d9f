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
            try:
                ray.init(address=address, **kw)
            except (ConnectionError, RuntimeError, ValueError) as e:
                where = address or "a local cluster"
                raise HostError(f"cannot start Ray on {where}: "
                                f"{str(e).splitlines()[0] if str(e) else type(e).__name__}"
                                ) from None
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


def _evaluate(score: Callable[[MatcherParams], list[float]], params: MatcherParams
              ) -> list[float]:
    return score(params)
