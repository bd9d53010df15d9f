"""The servo's phases: one name for each, written as its lower-case string in logs, JSON and views.

A StrEnum: a Phase is its string (Phase.STOP == "stop", f"{Phase.STOP}" == "stop"), so CSV logs,
trial JSON, recordings and the live view's page read and write the same text as ever.
"""

from __future__ import annotations

from enum import StrEnum


class Phase(StrEnum):
    # before the robot: the scene measured without it (Servo.reference), or no robot at all
    REFERENCE = "reference"
    VIEW = "view"  # `host view`: looking only
    # acquisition (host/servo/acquire.py): find the marker, measure its noise, probe the heading
    FIND = "find"
    MEASURE = "measure"
    PROBE = "probe"
    DONE = "done"
    # the control law (host/servo/controller.py)
    WAIT = "wait"
    HOLD = "hold"
    DRIVE = "drive"
    CREEP = "creep"
    TURN = "turn"
    LOST = "lost"
    STALE = "stale"
    SEARCH = "search"
    BLOCKED = "blocked"
    # the servo loop (host/servo/loop.py)
    RECOVER = "recover"  # standing while a recovery is under way (recovery.py)
    OBSTACLE = "obstacle"  # the lane is blocked: stopped until it clears
    STOP = "stop"  # the run must end (its stop_reason says why)
    # the live view (host/view/feed.py): the run is over
    ENDED = "ended"
