"""The serial link: protocol framing and messages, and the client that drives the robot."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["client", "frame", "messages", "protocol_gen"]
