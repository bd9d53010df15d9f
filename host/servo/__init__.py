"""The disparity-equalising servo: perception, marker, control law and the loop (also on the real
robot; the simulated world is host.sim)."""
