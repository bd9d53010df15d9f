"""The objective a learner sees: f(state) -> a score to minimise, memoised; its count of distinct
evaluations is what a tuning method pays. Where the score is computed (this process, worker
processes, Ray) is the backend's business, never the learner's."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from host.stereo.params import MatcherParams
from host.tuning.backends import Backend

State = tuple[int, ...]


class SceneTable:
    """state -> one score per scene, computed by a backend and remembered, so that objectives
    over different subsets of the scenes (leave-one-out folds) share every evaluation."""

    def __init__(self, backend: Backend, params_of: Callable[[State], MatcherParams]) -> None:
        self.backend, self.params_of = backend, params_of
        self.rows: dict[State, tuple[float, ...]] = {}

    def get(self, states: Sequence[State]) -> list[tuple[float, ...]]:
        todo = [s for s in dict.fromkeys(states) if s not in self.rows]
        if todo:
            got = self.backend.map([self.params_of(s) for s in todo])
            self.rows.update((s, tuple(r)) for s, r in zip(todo, got))
        return [self.rows[s] for s in states]

    def close(self) -> None:
        self.backend.close()


class Objective:
    """f(state) -> score (lower is better), memoised. Either a score of matcher parameters run
    by a backend (Objective.of), or any function of the state (landscapes in tests, tables)."""

    def __init__(self, fn: Callable[[State], float],
                 batch: Callable[[list[State]], list[float]] | None = None,
                 owner: SceneTable | None = None) -> None:
        self._fn = fn
        self._batch = batch
        self._owner = owner  # its backend is shut down by close()
        self.cache: dict[State, float] = {}
        # evaluations worth asking for at once (the backend's parallelism)
        self.parallel = owner.backend.parallel if owner is not None else 1

    @classmethod
    def of(cls, table: SceneTable, scenes: Sequence[int] | None = None) -> Objective:
        """The mean of the table's per-scene scores over the given scenes (default: all)."""
        def mean(row: tuple[float, ...]) -> float:
            picked = row if scenes is None else [row[i] for i in scenes]
            return sum(picked) / len(picked)

        return cls(lambda s: mean(table.get([s])[0]),
                   lambda states: [mean(r) for r in table.get(states)], table)

    @property
    def evaluations(self) -> int:
        return len(self.cache)

    def __call__(self, state: State) -> float:
        if state not in self.cache:
            self.cache[state] = self._fn(state)
        return self.cache[state]

    def many(self, states: list[State]) -> list[float]:
        """Evaluate several states (in one batch for the backend)."""
        todo = [s for s in dict.fromkeys(states) if s not in self.cache]
        if todo and self._batch is not None:
            self.cache.update(zip(todo, self._batch(todo)))
        return [self(s) for s in states]

    def close(self) -> None:
        if self._owner is not None:
            self._owner.close()

    def __enter__(self) -> Objective:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
