"""The tracker keeps a target that moved farther where it stood instead of taking it for gone and
handing it to a nearer object elsewhere (host/servo/tracker.py): constructed maps."""

from __future__ import annotations

import numpy as np

from host.servo.perception import Target
from host.servo.tracker import TargetTracker


def _scene(box_d: float, box_cols: tuple[int, int]) -> np.ndarray:
    """A map (floor removed) with the target box and, right of it, another robot-like body
    nearer than the box will be after it moved (a wall far behind everything)."""
    disp = np.full((240, 320), 6.0, np.float32)  # the wall
    disp[150:176, 218:265] = 16.1  # the other body, beside the lane
    disp[70:145, box_cols[0]:box_cols[1]] = box_d
    return disp


def test_a_target_moved_farther_is_followed_not_replaced_by_a_nearer_object_elsewhere():
    """The target box moves from 17.5 to 15.0 px (toward a robot standing behind it); another
    body stands at 16.1 px elsewhere. The tracker before took the box for gone (its pixels now
    farther) and, two re-measures on, the body for its successor: the robot turned and drove
    toward it, beside and into the box (seed 8's trial 45 with the re-reference on). Now the
    box is followed at its new depth at once (the controller's checks then see the robot's
    line through it); the body nearer than it becomes the target only the way any nearer
    object does (NearerObject: three agreeing re-measures)."""
    disp = _scene(17.5, (22, 111))
    tracker = TargetTracker(Target(17.5, 6000, (22, 70, 89, 75), 0.1), 768)

    def agreement(t: Target) -> float:  # the views agree where the map has t's disparity
        x, y, w, h = t.bbox
        return float(np.mean(np.abs(disp[y:y + h, x:x + w] - t.disparity) < 1.0))

    tracker.update(disp, agreement)
    disp = _scene(15.0, (30, 106))  # moved farther: narrower
    for _ in range(2):
        target = tracker.update(disp, agreement)
        assert not tracker.retargeted and not tracker.stop_reason and not tracker.gone
        assert abs(target.disparity - 15.0) < 0.05 and target.bbox[:3] == (30, 70, 76)
