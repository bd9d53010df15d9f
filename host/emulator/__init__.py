"""Stand-ins for the robot: the firmware's own C core built natively, the real ELF in simavr,
and a simulated Uno that runs what was flashed through its bootloader (one Board interface)."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["board", "build", "core", "emulator", "pins", "simavr", "uno"]
