"""The live view: a web page showing what the servo sees and does, with a STOP button.

Fed read-only by the servo's observers (host.servo.snapshot); imported only by the commands.
"""

from host.view.feed import ViewFeed
from host.view.server import ViewServer, parse_address

__all__ = ["ViewFeed", "ViewServer", "parse_address"]
