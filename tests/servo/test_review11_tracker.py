"""An adverse case for the tracker's change of this session (review11, issue 23): 355047a
(_moved_back searches only the disparities behind the target).
Constructed maps in the style of tests/servo/test_tracker_moved_edge.py."""

from __future__ import annotations

import numpy as np

from host.servo.perception import Target
from host.servo.tracker import TargetTracker

OLD = Target(23.1, 9200, (28, 71, 65, 142), 0.1)  # the box, 142 rows tall from row 71


def _scene() -> np.ndarray:
    """The box at 23.1 px before a wall at 16 px (within same_depth: 1.44 times as deep)."""
    disp = np.full((240, 320), 16.0, np.float32)
    disp[71:213, 28:93] = 23.1
    return disp


def _views_no_phantom(disp: np.ndarray):
    """As _views, but a flat strip (a flicker phantom, under 30 rows) never agrees."""
    def agreement(t: Target) -> float:
        x, y, w, h = t.bbox
        if h < 30:
            return 0.0
        return float(np.mean(np.abs(disp[y:y + h, x:x + w] - t.disparity) < 1.0))
    return agreement


def test_a_walker_over_most_of_the_box_does_not_make_the_wall_above_it_the_target() -> None:
    """A walker near the camera, beyond the disparity range (0 px, seed 17 #228's kind), over
    the box's left 40 columns, and a flicker phantom at 34 px elsewhere (the nearest object,
    not in the box's columns): most of the box's area reads behind it and its views no longer
    agree at 23.1 px, so update looks for the target moved farther. The box's right 25 columns
    still stand at 23.1 px (3550 px), the wall at 16 px above them (1775 px). At b6af144 the
    nearest object in its columns was that rest of the box (not farther: no move; "target
    vanished" at the fourth re-measure, a named stop). Since 355047a the search sees only the
    disparities behind it: the strip of wall above the box, an edge of its own (the walker's),
    its views agreeing, becomes the target at 16 px on ONE re-measure (history reset): the
    robot is sent 1.44 times the box's depth, past the box. Fails at 355047a..a50cb3f;
    passes with /work/patch-review11-tracker.diff."""
    disp = _scene()
    disp[:, 0:68] = 0.0  # the walker: garbage read as 0 px, full height
    disp[27:53, 174:261] = 34.0  # a flicker phantom (26 rows: its views disagree)
    tracker = TargetTracker(OLD, 768)
    tracker.update(_scene(), _views_no_phantom(_scene()))
    for k in range(1, 4):
        target = tracker.update(disp, _views_no_phantom(disp))
        assert abs(target.disparity - 23.1) < 0.5, \
            f"re-measure {k}: the target followed to {target.disparity:.1f} px {target.bbox}"
