"""The host command's subcommands, one module each (host.cli builds the parser)."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["calibrate", "cameras", "capture", "disparity", "emulate", "eval", "options", "servo",
           "servo_outcome", "tune", "view"]
