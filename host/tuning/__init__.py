"""Tuning the matcher: the paper's Q-learner, general Q-learning, grid and random search."""

from host.tuning.learners import METHODS, TuneResult, tune
from host.tuning.objective import Objective
from host.tuning.spaces import SPACES, Space, make_space

__all__ = ["METHODS", "SPACES", "Objective", "Space", "TuneResult", "make_space", "tune"]
