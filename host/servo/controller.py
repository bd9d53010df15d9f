"""The disparity-equalising control law: a pure state machine, one call per frame.

Error e = robot disparity - target disparity (px). e > 0: the robot is nearer than the object
and must move away from the camera; e < 0: it is farther and must come back. The robot starts
facing away from the camera. Moving in the direction it faces, it drives forward; otherwise it
turns round in place (mode "turn", as in the paper; timed, turn_s at turn_duty) or reverses
(mode "reverse").

Speed is proportional to |e| (gain permille per px) between min_duty (against stiction) and
max_duty. Within tolerance_px it stops and holds; it moves again only when |e| exceeds
resume_factor * tolerance_px (hysteresis, so it does not chatter at the edge). The marker's
sideways position, x = B (u - cx) / d from its column u and disparity d, against where the
servo first saw it, adds a small differential correction (steer_gain permille per cm) so the
robot keeps to its line; using x rather than the bare column keeps perspective out of it.

Safety: a frame without the marker stops the robot at once (hold); after more than lost_frames
such frames the phase is "lost" and stays stopped until the marker is seen again. While turning
the marker is edge-on and unseen: the turn goes on, timed, and the count starts after it.
"""

from __future__ import annotations

from dataclasses import dataclass

HOLD, DRIVE, TURN, LOST = "hold", "drive", "turn", "lost"


@dataclass(frozen=True)
class ControlConfig:
    tolerance_px: float = 0.25
    resume_factor: float = 2.0
    gain: float = 160.0  # permille per px of error
    min_duty: int = 180
    max_duty: int = 600
    steer_gain: float = 25.0  # permille per cm of sideways drift
    mode: str = "turn"  # or "reverse"
    turn_duty: int = 400
    turn_s: float = 2.0
    lost_frames: int = 3


@dataclass(frozen=True)
class Observation:
    """What perception saw in one frame: the marker's disparity and sideways position, or
    nothing (disparity None)."""

    t: float  # s
    disparity: float | None
    lateral_m: float | None = None


@dataclass(frozen=True)
class Command:
    left: int
    right: int
    phase: str
    error: float | None

    @property
    def is_stop(self) -> bool:
        return self.left == 0 and self.right == 0


class Controller:
    def __init__(self, target_px: float, config: ControlConfig = ControlConfig()) -> None:
        if config.mode not in ("turn", "reverse"):
            raise ValueError(f"mode must be turn or reverse, got {config.mode!r}")
        self.target = target_px
        self.cfg = config
        self.facing_away = True
        self.phase = HOLD
        self.holding = False  # inside the tolerance band (with hysteresis)
        self.missing = 0
        self.lateral_ref: float | None = None
        self._turn_end: float | None = None

    def _stop(self, phase: str, error: float | None) -> Command:
        self.phase = phase
        return Command(0, 0, phase, error)

    def update(self, obs: Observation) -> Command:
        cfg = self.cfg
        if self._turn_end is not None:
            if obs.t < self._turn_end:
                self.phase = TURN
                return Command(cfg.turn_duty, -cfg.turn_duty, TURN, None)
            self._turn_end = None
            self.facing_away = not self.facing_away
            self.missing = 0
        if obs.disparity is None:
            self.missing += 1
            return self._stop(LOST if self.missing > cfg.lost_frames else HOLD, None)
        self.missing = 0
        if self.lateral_ref is None:
            self.lateral_ref = obs.lateral_m
        e = obs.disparity - self.target
        band = cfg.tolerance_px * (cfg.resume_factor if self.holding else 1.0)
        self.holding = abs(e) <= band
        if self.holding:
            return self._stop(HOLD, e)
        away = e > 0  # the robot must move away from the camera
        forward = away == self.facing_away
        if not forward and cfg.mode == "turn":
            self._turn_end = obs.t + cfg.turn_s
            self.phase = TURN
            return Command(cfg.turn_duty, -cfg.turn_duty, TURN, e)
        duty = min(cfg.max_duty, max(cfg.min_duty, int(round(cfg.gain * abs(e)))))
        duty = duty if forward else -duty
        steer = 0.0
        if obs.lateral_m is not None and self.lateral_ref is not None:
            # x' = v sin(theta): to cancel a drift to the right, turn so that v cos(theta) * dtheta
            # is negative; v cos(theta) is positive exactly when moving away from the camera
            s = 1.0 if away else -1.0
            steer = s * cfg.steer_gain * 100 * (obs.lateral_m - self.lateral_ref) / 2
        self.phase = DRIVE
        return Command(int(round(duty - steer)), int(round(duty + steer)), DRIVE, e)
