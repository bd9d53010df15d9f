"""Former names still read, and the names they now have: the matcher parameters' old command-line
spellings (options and flags) and the tuning space named after one (each read with a one-line
note, or refused where it was never valid: host.params_file, host.commands.options,
host.commands.tune)."""

from __future__ import annotations

# --window, --num-disp, --min-disp, --uniqueness: the MatcherParams field (params files' key,
# --block-size ...)
PARAMETERS = {"window": "block_size", "num_disp": "num_disparities", "min_disp": "min_disparity",
              "uniqueness": "uniqueness_ratio"}
FLAGS = {"grey": "no_colour"}  # --grey: --no-colour (the field colour = false)
SPACES = {"window": "block-size"}  # host tune --space, params files' [tuning] space
TUNE_OPTIONS = {"windows": "block_sizes"}  # host tune --windows: the block-size space's sizes
