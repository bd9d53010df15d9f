"""The serial link: protocol framing and messages, and the client that drives the robot."""
