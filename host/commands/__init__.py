"""The host command's subcommands, one module each (add_arguments and run); host.cli lists them
and imports a command's module only to run it or to build the whole parser."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["bag", "calibrate", "cameras", "capture", "disparity", "emulate", "eval", "options",
           "servo", "servo_outcome", "swap_check", "tune", "view"]
