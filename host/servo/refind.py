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

LostCard keeps the search's bookkeeping over the frames (the wheels' recent turns, the turn since
the card was last square, the depths admitted while driving one way, how long "lost" has lasted):
one pure update a frame; the servo (loop.py) decides from it when a Refind begins.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from host.servo.controller import Command
from host.servo.phase import Phase

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
    back_frames: int = 3  # the card seen this many frames running ends a loss: a glimpse
    # (one frame in a few, a far card turned near the detector's edge) does not, or each one
    # restarts the wait_s count and the refind never begins (seed 11's trial 868)


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


DRIVING = (Phase.DRIVE, Phase.CREEP)


class LostCard:
    """The lost-card search's bookkeeping, one update a frame: which way the wheels turned the
    card, whether the drives since the heading was set moved the depth against their way, and
    since when the controller has said "lost"."""

    def __init__(self, config: RefindConfig = RefindConfig()) -> None:
        self.cfg = config
        self.steered: list[tuple[float, int, bool]] = []  # (t, right - left, driving) of the
        # command in force up to t, over the turn window
        self.drive_depths: list[float] = []  # admitted while driving one way, this heading
        self.drive_facing, self.drive_toward = True, 0  # that heading and way
        self.lost_since: float | None = None  # the controller has said "lost" since then
        self.seen_run = 0  # frames the card was seen running (back_frames ends a loss)
        self.lost_now = False  # the controller says "lost" this frame
        self.off_square = 0.0  # the wheels' turn since the card was last square

    def update(self, t: float, was: Command, cmd: Command, aspect: float | None,
               depth: float | None, target_m: float, facing_away: bool) -> None:
        """The frame at t: was, the command in force up to t; cmd, the controller's this frame;
        aspect and depth, the card's (None when no sighting was admitted); target_m and
        facing_away, the controller's."""
        drove = was.phase in DRIVING and not was.is_stop
        dt = t - self.steered[-1][0] if self.steered else 0.0
        self.steered.append((t, was.right - was.left if drove else 0, drove))
        window = self.cfg.turn_window_s
        self.steered = [e for e in self.steered if t - e[0] <= window]
        # the turn since the card was last square to the camera (any wheel difference in
        # force, spins included: permille x s; its sign says which way the card turned)
        if aspect is not None and aspect >= self.cfg.square or cmd.phase == Phase.TURN \
                or dt > 0.25:  # (a turn round ends at an angle it measures itself; frames
            self.off_square = 0.0  # not decided here, an acquisition's, are not counted)
        else:
            self.off_square += (was.right - was.left) * dt
        self._track_drive(depth, cmd, target_m, facing_away)
        self.seen_run = 0 if aspect is None else self.seen_run + 1
        self.lost_now = cmd.phase == Phase.LOST
        if self.lost_now:
            self.lost_since = t if self.lost_since is None else self.lost_since
        elif self.seen_run >= self.cfg.back_frames or cmd.phase not in (
                Phase.WAIT, *DRIVING):  # back for good, or another phase took over (a hold,
            self.lost_since = None  # a turn, a stop): glimpses between "lost" do not end it

    def lost_while_driving(self, t: float) -> bool:
        """"lost" now and for wait_s but for glimpses, with a drive in the turn window: the
        refind may begin."""
        return self.lost_now and self.lost_since is not None and \
            t - self.lost_since >= self.cfg.wait_s and any(e[2] for e in self.steered)

    def turned(self) -> float:
        """Which way the card turned (right - left, permille x s): since it was square, else
        by the last drives."""
        s = self.steered
        return self.off_square or sum(b[1] * (b[0] - a[0]) for a, b in zip(s, s[1:]))

    def keep_in_view(self, aspect: float | None, cmd: Command) -> Command:
        """A drive whose wheel difference would turn the card farther from square when its
        aspect is already below view (about 30 degrees off) is driven straight at its mean
        duty: the card stays in view (far away, a card much past 40 degrees is lost)."""
        if aspect is None or aspect >= self.cfg.view or cmd.is_stop or \
                cmd.phase not in DRIVING:
            return cmd
        if (cmd.right - cmd.left) * self.off_square <= 0:
            return cmd  # it turns the card back toward square (or not at all)
        mean = (cmd.left + cmd.right) // 2
        return Command(mean, mean, cmd.phase, cmd.error_m)

    def _track_drive(self, depth: float | None, cmd: Command, target_m: float,
                     facing_away: bool) -> None:
        """The depths admitted while driving one way with one heading (drove_against)."""
        toward = 0 if depth is None else (1 if target_m > depth else -1)
        if cmd.phase in DRIVING and depth is not None and \
                facing_away == self.drive_facing and toward == self.drive_toward:
            self.drive_depths.append(depth)
        elif cmd.phase in (Phase.DRIVE, Phase.CREEP, Phase.TURN) or \
                facing_away != self.drive_facing:
            self.drive_depths = [] if depth is None else [depth]
            self.drive_facing, self.drive_toward = facing_away, toward

    def drove_against(self) -> bool:
        """Whether the depths admitted while driving one way since the heading was last set
        moved against that way: the median of the last five against the first five's, beyond
        5 cm and three of that difference's noise (from the sightings' own frame-to-frame
        spread, which moving shows and standing does not)."""
        z = self.drive_depths
        if len(z) < 10:
            return False
        steps = np.diff(z)
        sigma = float(np.median(np.abs(steps - np.median(steps)))) * 1.4826 / math.sqrt(2)
        dz = float(np.median(z[-5:]) - np.median(z[:5]))
        # a median of five has about 0.54 of a sighting's noise; the difference of two, 0.77
        return dz * self.drive_toward < -max(0.05, 3 * 0.77 * sigma)
