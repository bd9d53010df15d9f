"""A target that moved farther is followed where it stands even when it is cut by the
picture's edge (it grows past its old columns) or a flicker phantom lies nearer in its columns
(host/servo/tracker.py, TargetTracker._moved_back): constructed maps after seed 17 #873 and
#555, both "target vanished" in flicker with the box standing 16 cm and 25 cm farther."""

from __future__ import annotations

import numpy as np

from host.servo.perception import Target
from host.servo.tracker import TargetTracker

OLD = Target(23.1, 9200, (28, 71, 65, 142), 0.1)
# flicker phantoms elsewhere, nearer than anything, a new place each re-measure (x, y, w, h, d)
PHANTOMS = [(174, 27, 87, 26, 34.0), (132, 59, 53, 27, 33.0), (250, 201, 66, 26, 39.9),
            (217, 37, 52, 27, 36.8)]


class Views:
    """How well a region's two views agree at its disparity: where the map has that disparity
    (the box, the wall), never on a phantom (a flat strip)."""
    disp = np.zeros((240, 320), np.float32)

    def __call__(self, t: Target) -> float:
        x, y, w, h = t.bbox
        if h < 30:
            return 0.0
        return float(np.mean(np.abs(self.disp[y:y + h, x:x + w] - t.disparity) < 1.0))


def _follow(moved: np.ndarray) -> TargetTracker:
    """The tracker on the box before, then a re-measure of the moved scene with each phantom
    in turn: the target must never be taken for gone."""
    before = np.full((240, 320), 6.0, np.float32)
    before[71:213, 28:93] = 23.1
    tracker, views = TargetTracker(OLD, 768), Views()
    views.disp = before
    tracker.update(before, views)
    for x, y, w, h, d in PHANTOMS:
        views.disp = disp = moved.copy()
        disp[y:y + h, x:x + w] = d
        tracker.update(disp, views)
        assert not tracker.gone and not tracker.stop_reason
    return tracker


def test_a_target_cut_by_the_edge_that_moved_farther_is_followed():
    """The box, cut on the left where the right view cannot see, moves 16 cm farther: at
    20.2 px it reaches from column 22 (the strip is narrower at a smaller disparity) to 100
    (its inner edge moved toward the centre): it filled its old columns edge to edge and was
    taken for the wall seen through them, then for gone, the phantoms leaving no successor
    (#873)."""
    moved = np.full((240, 320), 6.0, np.float32)
    moved[67:203, 22:100] = 20.2
    tracker = _follow(moved)
    assert abs(tracker.target.disparity - 20.2) < 0.05
    assert tracker.target.bbox[0] == 22 and tracker.target.bbox[2] == 78


def test_a_phantom_nearer_in_its_columns_does_not_hide_the_target_moved_farther():
    """The box moves to 19.6 px, narrower, with a flicker phantom at 21 px over part of its
    columns: the nearest object in its columns was the phantom, not farther than the target,
    so the box was taken for gone (#555)."""
    moved = np.full((240, 320), 6.0, np.float32)
    moved[71:213, 28:88] = 19.6
    moved[63:87, 45:85] = 21.0  # the phantom in its columns (960 px): views disagreeing
    tracker = _follow(moved)
    assert abs(tracker.target.disparity - 19.6) < 0.05


def test_the_wall_filling_its_columns_is_still_not_the_target_moved_farther():
    """Gone for good, the wall at 16 px (within same_depth) shows through its columns and
    across the picture: no edge of its own, wider than an object: not the target moved."""
    wall = np.full((240, 320), 16.0, np.float32)
    tracker, views = TargetTracker(OLD, 768), Views()
    views.disp = wall
    for _ in range(2):
        tracker.update(wall, views)
    assert tracker.gone and tracker.target.disparity == 23.1
