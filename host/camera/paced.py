"""A source held to a pace: each pair is handed on no sooner than its capture time (from the
first pair's) divided by speed, on the wall clock; for a simulated camera that is otherwise
as fast as the loop. A pair that comes late restarts the pace: the time lost is not made up
by running fast."""

from __future__ import annotations

import time

from host.camera.source import StereoFrame, StereoSource
from host.camera.wrapper import WrappedSource

LATE_S = 0.1  # a pair this much behind its pace restarts the pace from it


class PacedSource(WrappedSource):
    """inner at speed times real time (speed > 0); inner rectifies as it did. catch_up: a
    late pair does not restart the pace, the pairs after it come at once until the pace is
    kept again (as a camera's frames wait for a slow loop)."""

    def __init__(self, inner: StereoSource, speed: float = 1.0, catch_up: bool = False) -> None:
        if speed <= 0:
            raise ValueError("a paced source needs a speed above 0")
        super().__init__(inner)
        self.speed, self.catch_up = speed, catch_up
        self._t0: tuple[float, float] | None = None  # (first capture, wall time then)
        self.late = 0  # pairs handed on later than their pace (the loop was slower)

    def _read(self) -> StereoFrame | None:
        frame = self.inner.read()
        if frame is None:
            return None
        now = time.monotonic()
        if self._t0 is None:
            self._t0 = (frame.t_left, now)
        due = self._t0[1] + (frame.t_left - self._t0[0]) / self.speed
        if due > now:
            time.sleep(due - now)
        elif now - due > LATE_S:  # behind (a slow step): go on from here, or catch up
            self.late += 1
            if not self.catch_up:
                self._t0 = (frame.t_left, now)
        return frame
