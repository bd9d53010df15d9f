"""Stereo core: block matching, metrics and scenes, as pure functions on arrays."""

from host.stereo.grey import to_grey
from host.stereo.matcher import compute_disparity
from host.stereo.metrics import Score, evaluate
from host.stereo.numba_cache import lock_cache_files
from host.stereo.params import MATCHERS, MatcherParams
from host.stereo.scenes import Scene, load_scene

# Every process that compiles a numba kernel imports this package first (the kernels all live
# under it or import from it): the CLI, its trial and tuning workers (spawned), Ray's workers.
lock_cache_files()

__all__ = ["MATCHERS", "MatcherParams", "Scene", "Score", "compute_disparity", "evaluate",
           "load_scene", "to_grey"]
