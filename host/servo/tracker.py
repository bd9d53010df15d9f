"""The target kept true during the run: each re-measure of the nearest object (on a whole map
with the floor and the robot left out) follows it when it moves (median of the last three),
retargets onto a nearer object only once NearerObject vouches for it (three re-measures running
at the same place and depth, its two views agreeing: a flicker phantom moves and does not
match), and ends the run ("target vanished") when most of its area twice shows what lay behind
it and its two views no longer agree at its disparity (a map spoilt by flicker is not a box
gone; a pure state machine)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from host.errors import HostError
from host.servo.inputs import NearerObject
from host.servo.perception import Target, nearest_object

VANISHED = "target vanished"


@dataclass(frozen=True)
class TrackerConfig:
    history: int = 3  # re-measures the target's disparity is the median of
    agree: int = 2  # re-measures that must agree before a "vanished"
    overlap: float = 0.3  # of the narrower region's width: the same object
    still_there: float = 0.6  # views agreeing this well at the object's disparity: not gone


class TargetTracker:
    def __init__(self, target: Target, min_area: int, config: TrackerConfig = TrackerConfig()
                 ) -> None:
        self.target, self.min_area, self.cfg = target, min_area, config
        self.history = [target.disparity] * (config.history - 1)
        self.stop_reason = ""  # set when the run must end
        self.retargeted = False  # the last update moved the target to a new object
        self._doubt = (0, "")  # consecutive re-measures that disagree, and how
        self.nearer = NearerObject()

    def update(self, disp: np.ndarray, agreement: Callable[[Target], float] = lambda t: 1.0
               ) -> Target:
        """Measure again on disp (px, NaN = invalid: floor and robot left out): the target.
        agreement: how well a region's two views match at its disparity (views_agree)."""
        self.retargeted = False
        old = self.target
        bx, by, bw, bh = old.bbox
        there = disp[by:by + bh, bx:bx + bw]
        there = there[np.isfinite(there)]
        if there.size < self.min_area // 4:
            return old  # the robot hides the object: nothing to learn
        try:
            found: Target | None = nearest_object(disp, self.min_area, near=old.disparity)
        except HostError:
            found = None
        overlap = found is not None and min(bx + bw, found.bbox[0] + found.bbox[2]) - max(
            bx, found.bbox[0]) > self.cfg.overlap * min(bw, found.bbox[2])
        nearer = found is not None and not overlap and found.disparity > old.disparity
        vouched = self.nearer.update(found if nearer else None,
                                     agreement(found) if nearer and found else float("nan"))
        if found is not None and overlap:
            if not agreement(found) >= self.cfg.still_there:
                return old  # its two views disagree there: a spoilt map (flicker), not it
            self._doubt = (0, "")
            self.history.append(found.disparity)
            del self.history[:-self.cfg.history]
            median = float(np.median(self.history))
            self.target = Target(median, found.area, found.bbox, found.spread)
            return self.target
        # gone means seen through: most of the object's area now shows what lies behind it; a
        # region hidden by something nearer (or masked as the robot) is not gone
        behind = int(np.count_nonzero(there < old.disparity - max(1.0, 0.1 * old.disparity)))
        if behind >= old.area // 2 and not agreement(old) >= self.cfg.still_there:
            n = self._doubt[0] + 1 if self._doubt[1] == "vanished" else 1
            self._doubt = (n, "vanished")
            if n >= self.cfg.agree:
                self.stop_reason = VANISHED
            return old
        if vouched is None:
            return old  # hidden, a nearer object not yet vouched for, or nothing clear
        found = vouched
        self._doubt = (0, "")
        self.nearer.reset()
        self.target = found
        self.history = [found.disparity] * (self.cfg.history - 1)
        self.retargeted = True
        return found
