"""Finding the marker again when it is lost while driving: a pure state machine, one call a frame.

A robot that steers hard turns its card edge-on (the card's apparent aspect is |cos| of its
angle to the camera), and the card is lost; standing on in "lost" until an outer limit gives
up helps nothing. Instead the robot spins back in place, against the turn the drive's wheel
difference made, until the card is square to the camera again (its aspect at least aspect, or
past its best: it fell by fall from the best since it came back), for at most back_s (FOUND,
or WHOLE: the card not back, look for it in the whole view through the acquisition, which
probes the heading again). Turned back by less than the drive turned, the robot faces the way
it faced (the card shows both sides alike: a spin past a quarter turn could not tell). A card
lost without a turn (hidden by something passing) is waited for stand_s, standing, then
looked for in the whole view. The spin is in place: the servo judges it as any spin (it must
not sweep the body into the object); nothing here drives with the card unseen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

FOUND, WHOLE = "found", "whole"


@dataclass(frozen=True)
class RefindConfig:
    duty: int = 300  # the spin back (permille, each wheel, opposite ways)
    back_s: float = 2.0  # spun back this long without the card square again: whole view
    aspect: float = 0.9  # the card this square to the camera: found
    square: float = 0.97  # the card square to the camera (turns are counted from there)
    view: float = 0.8  # below this a drive must not turn the card farther (the servo's)
    fall: float = 0.08  # or its aspect this far below its best since it came back
    wait_s: float = 0.4  # "lost" this long before the refind begins (a far, small card
    # missing for a few frames comes back by itself)
    min_turn: float = 30.0  # permille x s of wheel difference in the last turn_window_s: a turn
    turn_window_s: float = 2.0  # the drive's steering that may have turned the card away
    stand_s: float = 3.0  # lost without a turn: stand this long, then the whole view (a
    # walker or a hand passes in under 1.5 s)


class Refind:
    def __init__(self, t: float, turned: float, config: RefindConfig = RefindConfig()) -> None:
        """t: the frame where the card was found lost; turned: the wheel difference (right -
        left, permille x s) the drive applied over the last turn_window_s before."""
        self.cfg = config
        self.t0 = t
        # the robot turned one way by (right - left): the spin back goes the other way
        self.spin = 0 if abs(turned) < config.min_turn else int(math.copysign(1, turned))
        self.best = -math.inf  # the card's best aspect since it came back
        self.outcome = ""  # FOUND or WHOLE once decided

    def update(self, t: float, aspect: float | None) -> tuple[int, int]:
        """The frame at t, with the card's aspect when it is seen (None: unseen): the wheels'
        command (permille); outcome set when the refind has ended (the command is then STOP)."""
        cfg = self.cfg
        if self.outcome:
            return 0, 0
        if self.spin == 0:  # nothing turned the card away: wait for it to come back
            if aspect is not None:
                self.outcome = FOUND
            elif t - self.t0 >= cfg.stand_s:
                self.outcome = WHOLE
            return 0, 0
        if aspect is not None:
            a = min(1.0, aspect)
            self.best = max(self.best, a)
            if a >= cfg.aspect or a <= self.best - cfg.fall:
                self.outcome = FOUND
                return 0, 0
        if t - self.t0 >= cfg.back_s:
            self.outcome = WHOLE
            return 0, 0
        d = cfg.duty * self.spin  # (d, -d) turns the way (right > left) did not
        return d, -d
