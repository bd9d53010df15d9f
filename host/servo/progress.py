"""Whether the servo is getting anywhere: a run that neither comes nearer its target nor holds
there is a fault the servo names itself, not something left to an outer time limit (a pure
state machine, one call a frame).

Progress is either of:
  - a step: the depth error's magnitude below its least so far by step_m, or by half the
    least when that is smaller (not below min_step_m: noise); the least is forgotten when the
    target's depth moves by step_m (a new goal), and the count restarts then if an error was
    measured since the last goal began (a target that keeps moving while the servo measures
    nothing against it, the re-measure taking the unseen robot's own body for it, restarts
    nothing: seed 11's trial 322);
  - a steady hold: holding hold_s without a break (each frame of it counts).
A recovery (the phase "recover": a back-off from the object, a wait and a re-acquisition)
begins an approach of its own: the least error is forgotten, and the errors measured after
it, while they grow (backing off), set the new approach's start without counting as progress
(seed 18 #62 held at 7.8 s, backed off 15 cm when pushed, came back on a new heading and was
creeping in 1.2 cm from its target when "no progress in 20 s" ended the run: its least error
was the hold's, before the back-off).
No progress for stall_s while the servo commands (waits that recovery.py bounds do not count:
the robot stands for a reason with its own limit) ends the run: the robot that oscillates
about the target, creeps without closing in, holds only between frames without the marker, or
re-acquires again and again stops with NO_PROGRESS, saying what it last did.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from host.servo.phase import Phase

NO_PROGRESS = "no progress toward the target"


@dataclass(frozen=True)
class ProgressConfig:
    stall_s: float = 20.0  # no progress this long ends the run: a turn (at most 8 s), its
    # search and a turn back (dev seed 104's trial 1 needed 15 s after the target moved)
    step_m: float = 0.02  # twice the default tolerance
    min_step_m: float = 0.005  # below this a step may be the depth noise at the hold
    hold_s: float = 1.0  # a hold this long without a break is where the servo means to be


class Progress:
    def __init__(self, config: ProgressConfig = ProgressConfig()) -> None:
        self.cfg = config
        self.best = math.inf  # the least |error| so far (m)
        self.target: float | None = None  # the target's depth the best belongs to
        self.since: float | None = None  # the last progress (or the start)
        self._hold_t0: float | None = None  # the hold without a break began then
        self._paused = 0.0  # time in bounded waits since the last progress
        self._last_t: float | None = None
        self._measured = True  # an error measured since the goal began (the first goal counts)
        self._fresh = False  # a recovery since the last progress: growing errors set the least
        self.last_phases: list[Phase] = []  # the phases since the last progress, in order

    def update(self, t: float, phase: Phase, error_m: float | None, target_m: float,
               waiting: bool = False) -> str:
        """The frame at t: its phase, the depth error (m, None when not measured), the
        target's depth; waiting: a wait recovery.py bounds. Returns why the run must end, or
        ""."""
        cfg = self.cfg
        dt = 0.0 if self._last_t is None else max(0.0, t - self._last_t)
        self._last_t = t
        if self.since is None:
            self.since = t
        if self.target is None or abs(target_m - self.target) >= cfg.step_m:
            self.target, self.best = target_m, math.inf  # a new goal
            if self._measured:
                self._progress(t)
            self._measured = False
        if error_m is not None and math.isfinite(error_m):
            self._measured = True
        if waiting:
            self._paused += dt
        if phase == Phase.RECOVER:  # a new approach: its least error is its own
            self.best, self._fresh = math.inf, True
        if phase == Phase.HOLD:
            self._hold_t0 = t if self._hold_t0 is None else self._hold_t0
            if t - self._hold_t0 >= cfg.hold_s:
                self._progress(t)
        else:
            self._hold_t0 = None
        step = min(cfg.step_m, max(cfg.min_step_m, self.best / 2))
        if error_m is not None and math.isfinite(error_m) and self._fresh and (
                not math.isfinite(self.best) or abs(error_m) > self.best):
            self.best = abs(error_m)  # going away (the back-off): the approach starts farther
        elif error_m is not None and math.isfinite(error_m) and abs(error_m) < self.best - step:
            self._fresh = False
            self.best = abs(error_m)
            self._progress(t)
        if phase not in self.last_phases:
            self.last_phases.append(phase)
        if t - self.since - self._paused >= cfg.stall_s:
            return f"{NO_PROGRESS} in {cfg.stall_s:g} s"
        return ""

    def detail(self) -> str:
        """What the servo did since its last progress, for the run's notes."""
        least = (f"the least depth error was {self.best * 100:.1f} cm"
                 if math.isfinite(self.best) else "no depth error measured")
        return f"{least}; since then: {', '.join(self.last_phases)}"

    def _progress(self, t: float) -> None:
        self.since, self._paused = t, 0.0
        self.last_phases = []
