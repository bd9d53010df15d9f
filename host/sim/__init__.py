"""The simulated world of host servo --sim: scene, robot, renderer, fault models, trials."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["chessboard", "faults", "renderer", "run", "source", "trials", "world"]
