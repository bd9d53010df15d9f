"""The local backend: scores parameter sets one after another in this process."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from host.stereo.params import MatcherParams


class LocalBackend:
    parallel = 1

    def __init__(self, score: Callable[[MatcherParams], list[float]]) -> None:
        self.score = score

    def map(self, params: Sequence[MatcherParams]) -> list[list[float]]:
        return [self.score(p) for p in params]

    def close(self) -> None:
        pass
