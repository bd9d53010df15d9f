"""The target's depth has an age (host/servo/tracker.py TargetTracker.aged): gone unmeasured
longer than a box move may go unseen, it is confirmed by a reading agreeing with it or
replaced by two readings agreeing with each other; one reading alone moves nothing
(constructed maps; the servo standing for it: test_timing_and_target.py)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from host.servo.perception import Target
from host.servo.tracker import TargetTracker

BOX = (22, 70, 89, 75)  # the target box's image region (x, y, w, h)


def _scene(box_d: float) -> np.ndarray:
    """A map (floor removed): the target box before a far wall."""
    disp = np.full((240, 320), 6.0, np.float32)
    disp[70:145, 22:111] = box_d
    return disp


def _agree(disp: np.ndarray) -> Callable[[Target], float]:
    """The views agree where the map has the region's disparity."""

    def agreement(t: Target) -> float:
        x, y, w, h = t.bbox
        return float(np.mean(np.abs(disp[y:y + h, x:x + w] - t.disparity) < 1.0))
    return agreement


def _tracker() -> TargetTracker:
    tracker = TargetTracker(Target(21.85, 6000, BOX, 0.1), 768)
    for _ in range(3):  # measured where it stands: a full history
        disp = _scene(21.85)
        tracker.update(disp, _agree(disp))
    assert tracker.confirmed and tracker.measured
    return tracker


def test_an_aged_depth_is_confirmed_by_one_reading_that_agrees_with_it() -> None:
    """Nothing moved while unmeasured: the first reading (within 1 % of it) confirms it."""
    tracker = _tracker()
    tracker.aged()
    assert not tracker.confirmed
    disp = _scene(21.90)
    target = tracker.update(disp, _agree(disp))
    assert tracker.confirmed and tracker.measured
    assert abs(target.disparity - 21.85) < 0.03


def test_a_move_while_unmeasured_registers_on_two_agreeing_readings_at_once() -> None:
    """The box moved 1.17 -> 1.29 m (21.85 -> 19.82 px) during a turn (seed 11's trial 135):
    the first reading leaves the depth unconfirmed (and unchanged: one reading is no move);
    the second, agreeing with it, is the target at once, their mean."""
    tracker = _tracker()
    tracker.aged()
    disp = _scene(19.82)
    target = tracker.update(disp, _agree(disp))
    assert not tracker.confirmed and not tracker.measured
    assert abs(target.disparity - 21.85) < 1e-3
    disp = _scene(19.84)
    target = tracker.update(disp, _agree(disp))
    assert tracker.confirmed and tracker.measured and not tracker.retargeted
    assert abs(target.disparity - 19.83) < 1e-3


def test_one_stray_reading_of_an_aged_depth_moves_nothing() -> None:
    """A single reading elsewhere (a spoilt map) and then one where it was: the depth stays,
    confirmed by the second; two readings that disagree with each other confirm nothing."""
    tracker = _tracker()
    tracker.aged()
    for d in (20.5, 21.86):
        disp = _scene(d)
        target = tracker.update(disp, _agree(disp))
    assert tracker.confirmed and abs(target.disparity - 21.85) < 0.03
    tracker.aged()
    for d in (20.5, 19.6):
        disp = _scene(d)
        target = tracker.update(disp, _agree(disp))
    assert not tracker.confirmed and abs(target.disparity - 21.85) < 1e-3
