"""Stereo core: block matching, metrics and scenes, as pure functions on arrays."""

from host.stereo.grey import to_grey
from host.stereo.matcher import compute_disparity
from host.stereo.metrics import Score, evaluate
from host.stereo.params import MATCHERS, MatcherParams
from host.stereo.scenes import Scene, load_scene

__all__ = ["MATCHERS", "MatcherParams", "Scene", "Score", "compute_disparity", "evaluate",
           "load_scene", "to_grey"]
