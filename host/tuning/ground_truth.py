"""The ground-truth objective: mean nonocc bad % over scenes, each with its own disparity range."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from host.errors import HostError
from host.stereo.matcher import compute_disparity
from host.stereo.metrics import evaluate
from host.stereo.params import MatcherParams
from host.stereo.scenes import Scene
from host.tuning.disparity_range import apply_range


def map_bad(scene: Scene, disp: np.ndarray, rho: float = 1.0) -> float:
    """Bad % of a disparity map of the scene: over the nonocc region where the scene has that
    mask, else over every pixel with known ground truth."""
    assert scene.gt is not None
    return evaluate(disp, scene.gt, scene.masks.get("nonocc"), rho).bad


def scene_bad(scene: Scene, params: MatcherParams, rho: float = 1.0) -> float:
    """Bad % of params on one scene (map_bad of its disparity)."""
    return map_bad(scene, compute_disparity(scene.left, scene.right, params), rho)


class GroundTruthScore:
    """params -> bad % per scene (lower is better); picklable, so any backend runs it."""

    name = "ground truth (nonocc bad %)"

    def __init__(self, scenes: Sequence[Scene], ranges: Sequence[tuple[int, int]],
                 rho: float = 1.0) -> None:
        for s in scenes:
            if s.gt is None:
                raise HostError(f"scene {s.name} has no ground truth to tune against")
        self.scenes, self.ranges, self.rho = list(scenes), list(ranges), rho

    def __call__(self, params: MatcherParams) -> list[float]:
        return [scene_bad(s, apply_range(params, r), self.rho)
                for s, r in zip(self.scenes, self.ranges)]
