"""What the servo assumes of the robot it drives: one source for the configs that use it."""

REACT_S = 0.33  # a command's reaction and the wheels' run-down (s): the servo's checks
MAX_SPEED_MPS = 0.4  # the robot's speed at full duty (m/s), with room
WHEELBASE_M = 0.14  # the wheels' track (m): a duty difference bends the path
