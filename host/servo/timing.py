"""Frame timing from the capture timestamps: stale and skewed pairs, and the skew correction of
the marker's disparity (a pure state machine, one call per frame)."""

from __future__ import annotations

from dataclasses import dataclass

STALE, SKEW = "stale", "skew"


@dataclass(frozen=True)
class TimingConfig:
    stale_s: float = 0.3  # a capture this long after the previous one, or this much later than
    # frames usually arrive, is stale
    max_skew_s: float = 0.045  # a pair whose two captures differ by more is not used
    max_shift: float = 0.2  # of the disparity: the largest skew correction


class FrameTiming:
    """Whether each frame is usable by its capture times, and its skew-free disparity."""

    def __init__(self, config: TimingConfig = TimingConfig()) -> None:
        self.cfg = config
        self._latency_floor: float | None = None
        self._last_capture: float | None = None
        self._prev: tuple[float, float] | None = None  # t_right, right u of the last marker

    def check(self, now: float, t_left: float, t_right: float) -> str:
        """Why the frame captured at t_left / t_right (s) and arriving at now (s, the same
        clock) is unusable ("stale", "skew"), or ""."""
        latency = now - t_left
        if self._latency_floor is None or latency < self._latency_floor:
            self._latency_floor = latency
        gap = t_left - self._last_capture if self._last_capture is not None else 0.0
        self._last_capture = t_left
        if gap > self.cfg.stale_s or latency - self._latency_floor > self.cfg.stale_s:
            return STALE
        if abs(t_right - t_left) > self.cfg.max_skew_s:
            return SKEW
        return ""

    def skew_free(self, t_left: float, t_right: float, disparity: float, right_u: float
                  ) -> float:
        """The marker's disparity (px) as if the right sensor had captured with the left: its
        right centre right_u (px) moved back by its measured image speed times the skew."""
        skew = t_right - t_left
        d = disparity
        prev = self._prev
        if prev is not None and skew and t_right > prev[0] \
                and t_right - prev[0] < 3 * self.cfg.stale_s:
            shift = (right_u - prev[1]) / (t_right - prev[0]) * skew
            # more than a fifth of the disparity is no motion of the robot's (it moves
            # mostly in depth, its image slowly): the last sighting was another marker (a
            # look-alike left out, a re-acquisition), and the pair is left as it came
            if abs(shift) <= self.cfg.max_shift * abs(d):
                d += shift
        self._prev = (t_right, right_u)
        return d
