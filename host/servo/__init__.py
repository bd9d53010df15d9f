"""The disparity-equalising servo: perception, marker, control law and the loop (also on the real
robot; the simulated world is host.sim)."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["controller", "loop", "marker", "perception", "report", "snapshot"]
