"""The disparity-equalising servo: perception, marker, control law, the loop and its simulation."""
