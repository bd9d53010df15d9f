"""Stand-ins for the robot: the firmware's own C core built natively, and the real ELF in simavr."""
