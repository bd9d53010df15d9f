"""The process backend: scores parameter sets in parallel worker processes on this machine."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor

from host.stereo.params import MatcherParams

_score: Callable[[MatcherParams], list[float]] | None = None


def _init(score: Callable[[MatcherParams], list[float]]) -> None:
    global _score
    _score = score


def _run(params: MatcherParams) -> list[float]:
    assert _score is not None
    return _score(params)


class ProcessBackend:
    """workers processes, each given the score (with its images) once at start."""

    def __init__(self, score: Callable[[MatcherParams], list[float]], workers: int) -> None:
        self.score = score
        self.parallel = workers
        # spawn: numba's OpenMP threads and fork do not mix
        self._pool = ProcessPoolExecutor(workers, multiprocessing.get_context("spawn"),
                                         initializer=_init, initargs=(score,))

    def map(self, params: Sequence[MatcherParams]) -> list[list[float]]:
        if len(params) == 1:  # a learner's single step: no round trip to a worker
            return [self.score(params[0])]
        return list(self._pool.map(_run, params))

    def close(self) -> None:
        self._pool.shutdown()
