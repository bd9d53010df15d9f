"""Evaluation backends: where a batch of parameter sets is scored. The learners see only an
Objective; a backend maps a score (params -> one score per scene) over parameter sets, in order."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from host.stereo.params import MatcherParams

__all__ = ["Backend", "Score", "make_backend"]

Score = Callable[[MatcherParams], list[float]]


class Backend(Protocol):
    """Where evaluations run: map scores each parameter set (one score per scene), in order;
    close releases the workers."""

    parallel: int  # how many evaluations it runs at once

    def map(self, params: Sequence[MatcherParams]) -> list[list[float]]: ...

    def close(self) -> None: ...


def make_backend(score: Score, workers: int = 1, ray: str | None = None) -> Backend:
    """Ray when ray is given ("local" starts a cluster on this machine, else an address),
    worker processes when workers > 1, else this process."""
    if ray is not None:
        from host.tuning.backends.ray_cluster import RayBackend

        return RayBackend(score, None if ray == "local" else ray)
    if workers > 1:
        from host.tuning.backends.processes import ProcessBackend

        return ProcessBackend(score, workers)
    from host.tuning.backends.local import LocalBackend

    return LocalBackend(score)
