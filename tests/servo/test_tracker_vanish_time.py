"""A target is not declared vanished on re-measures run back to back faster than something
crossing in front of it takes to pass (host/servo/tracker.py, TrackerConfig.vanish_s):
constructed maps after seed 17 #228 (a walker near the camera, beyond the disparity range, its
map reading 0 px over the box for 1.3 s; the five re-measures to "vanished" took 0.2 s)."""

from __future__ import annotations

import numpy as np

from host.servo.perception import Target
from host.servo.tracker import VANISHED, TargetTracker

BOX = Target(22.8, 9700, (27, 69, 68, 144), 0.1)


def _maps() -> tuple[np.ndarray, np.ndarray]:
    """The scene with the box, and with a walker's garbage (0 px) over it and beyond."""
    box = np.full((240, 320), 6.0, np.float32)
    box[69:213, 27:95] = 22.8
    walker = box.copy()
    walker[4:236, 4:217] = 0.0
    return box, walker


def _views(disp: np.ndarray):
    def agreement(t: Target) -> float:
        x, y, w, h = t.bbox
        return float(np.mean(np.abs(disp[y:y + h, x:x + w] - t.disparity) < 1.0))
    return agreement


def test_a_target_hidden_by_garbage_for_a_second_is_not_vanished_at_frame_rate():
    box, walker = _maps()
    tracker = TargetTracker(BOX, 768)
    tracker.update(box, _views(box), t=0.0)
    t = 0.0
    while t < 1.3:  # the walker's 1.3 s, re-measured every frame
        t += 1 / 30
        tracker.update(walker, _views(walker), t=t)
        assert tracker.stop_reason == "", f"vanished at {t:.2f} s"
    for _ in range(3):  # it passed: the box again, found as the next object
        t += 1 / 30
        tracker.update(box, _views(box), t=t)
    assert not tracker.stop_reason and not tracker.gone
    assert abs(tracker.target.disparity - 22.8) < 0.05


def test_a_target_gone_for_good_still_ends_the_run():
    """The time floor delays, never cancels: gone for 2 s with no successor, the run ends;
    with no times given the count of re-measures alone decides, as before."""
    _, walker = _maps()
    tracker = TargetTracker(BOX, 768)
    t = 0.0
    while not tracker.stop_reason and t < 5.0:
        t += 1 / 30
        tracker.update(walker, _views(walker), t=t)
    assert tracker.stop_reason == VANISHED and 2.0 <= t <= 2.3
    untimed = TargetTracker(BOX, 768)
    for _ in range(5):
        untimed.update(walker, _views(walker))
    assert untimed.stop_reason == VANISHED
