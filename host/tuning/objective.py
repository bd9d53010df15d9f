"""The tuning objective: mean bad-pixel rate (%) of a state's matcher over scenes, memoised;
its count of distinct evaluations is what a tuning method pays."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor

from host.errors import HostError
from host.stereo.matcher import compute_disparity
from host.stereo.metrics import evaluate
from host.stereo.params import MatcherParams
from host.stereo.scenes import Scene

State = tuple[int, ...]


def scene_bad(scene: Scene, params: MatcherParams, rho: float = 1.0) -> float:
    """Bad % of params on one scene: over the nonocc region where the scene has that mask,
    else over every pixel with known ground truth."""
    assert scene.gt is not None
    disp = compute_disparity(scene.left, scene.right, params)
    return evaluate(disp, scene.gt, scene.masks.get("nonocc"), rho).bad


def mean_bad(scenes: Sequence[Scene], params: MatcherParams, rho: float = 1.0) -> float:
    return sum(scene_bad(s, params, rho) for s in scenes) / len(scenes)


_worker_scenes: Sequence[Scene] = ()


def _init_worker(scenes: Sequence[Scene]) -> None:
    global _worker_scenes
    _worker_scenes = scenes


def _worker_eval(args: tuple[MatcherParams, float]) -> float:
    return mean_bad(_worker_scenes, *args)


class Objective:
    """f(state) -> mean bad %, memoised. Either over scenes (with a params function from a
    space), or any function of the state (synthetic landscapes in tests)."""

    def __init__(self, fn: Callable[[State], float], batch: Callable[[list[State]], list[float]]
                 | None = None, pool: ProcessPoolExecutor | None = None) -> None:
        self._fn = fn
        self._batch = batch
        self._pool = pool  # the worker processes behind batch, shut down by close()
        self.cache: dict[State, float] = {}

    @classmethod
    def on_scenes(cls, scenes: Sequence[Scene], params_of: Callable[[State], MatcherParams],
                  rho: float = 1.0, workers: int = 1) -> Objective:
        for s in scenes:
            if s.gt is None:
                raise HostError(f"scene {s.name} has no ground truth to tune against")
        pool = None
        if workers > 1:
            # spawn: numba's OpenMP threads and fork do not mix
            pool = ProcessPoolExecutor(workers, multiprocessing.get_context("spawn"),
                                       initializer=_init_worker, initargs=(list(scenes),))

        def batch(states: list[State]) -> list[float]:
            assert pool is not None
            return list(pool.map(_worker_eval, [(params_of(s), rho) for s in states]))

        return cls(lambda s: mean_bad(scenes, params_of(s), rho), batch if pool else None, pool)

    @property
    def evaluations(self) -> int:
        return len(self.cache)

    def __call__(self, state: State) -> float:
        if state not in self.cache:
            self.cache[state] = self._fn(state)
        return self.cache[state]

    def many(self, states: list[State]) -> list[float]:
        """Evaluate several states (in parallel processes when workers > 1)."""
        todo = [s for s in dict.fromkeys(states) if s not in self.cache]
        if todo and self._batch is not None:
            self.cache.update(zip(todo, self._batch(todo)))
        return [self(s) for s in states]

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown()
