"""Tuning the matcher: the paper's Q-learner, general Q-learning, grid and random search, TPE;
the disparity-range policies."""

from host.tuning.disparity_range import RangePolicy, apply_range
from host.tuning.learners import METHODS, Move, TuneResult, tune
from host.tuning.objective import Objective
from host.tuning.spaces import SPACES, Space, make_space

__all__ = ["METHODS", "SPACES", "Move", "Objective", "RangePolicy", "Space", "TuneResult",
           "apply_range", "make_space", "tune"]
