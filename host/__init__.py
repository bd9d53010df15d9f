"""stereo-servo host: Minoru capture, tuned block matching, Q-learning and the depth servo."""

__version__ = "0.1.0"
