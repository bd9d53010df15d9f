"""The recovery state machine alone (host/servo/recovery.py): waits, resumes, bounds."""

from __future__ import annotations

import numpy as np

from host.servo.perception import Floor
from host.servo.recovery import (
    BOUNDS,
    GIVE_UP,
    LANE,
    MOVED,
    RESET,
    RESUME,
    WAIT,
    Bound,
    Recovery,
    no_recovery,
)
from host.servo.rereference import refit_floor


def test_a_condition_that_clears_resumes_after_its_clear_time():
    rec = Recovery()
    assert rec.begin(1.0, LANE, "an object in the lane 0.30 m ahead")
    assert rec.update(1.1, False) == WAIT
    assert rec.update(2.0, True) == WAIT  # clear, but not for clear_s yet
    assert rec.update(2.5, False) == WAIT  # back: the clear time starts again
    assert rec.update(3.0, True) == WAIT
    assert rec.update(3.0 + BOUNDS[LANE].clear_s, True) == RESUME
    assert not rec.active and not rec.fault
    assert rec.recovered[-1][1] == LANE


def test_a_condition_that_lasts_ends_the_run_with_its_reason():
    rec = Recovery()
    assert rec.begin(0.0, LANE, "an object in the lane 0.30 m ahead")
    limit = BOUNDS[LANE].limit_s
    assert rec.update(limit - 0.01, False) == WAIT
    assert rec.update(limit, False) == GIVE_UP
    assert rec.fault == f"an object in the lane 0.30 m ahead for {limit:g} s"


def test_a_condition_that_recurs_too_often_ends_the_run():
    rec = Recovery({**BOUNDS, RESET: Bound(10.0, 0.0, 2)})
    for t in (1.0, 2.0):
        assert rec.begin(t, RESET, "the robot reset")
        assert rec.update(t, True) == RESUME
    assert not rec.begin(3.0, RESET, "the robot reset")
    assert rec.fault == "the robot reset (the third time in this run)"


def test_the_same_condition_again_during_its_wait_is_one_wait():
    rec = Recovery({**BOUNDS, RESET: Bound(10.0, 0.5, 1)})
    assert rec.begin(1.0, RESET, "the robot reset")
    assert rec.update(1.4, True) == WAIT
    assert rec.begin(1.45, RESET, "the robot reset")  # again: the clear time restarts
    assert rec.update(1.5, True) == WAIT
    assert rec.update(1.9, True) == WAIT
    assert rec.update(2.0, True) == RESUME
    assert rec.counts[RESET] == 1


def test_without_recovery_every_condition_ends_the_run_but_the_lane_after_its_time():
    rec = Recovery(no_recovery(3.0))
    assert not rec.begin(1.0, MOVED, "the camera moved")
    assert rec.fault == "the camera moved"
    rec = Recovery(no_recovery(3.0))
    assert rec.begin(1.0, LANE, "an object in the lane")
    assert rec.update(3.9, False) == WAIT
    assert rec.update(4.0, False) == GIVE_UP


def test_a_failed_recovery_ends_the_run_naming_both():
    rec = Recovery()
    assert rec.begin(1.0, MOVED, "the camera moved")
    rec.give_up("re-referencing failed: no floor")
    assert rec.update(1.1, True) == GIVE_UP
    assert rec.fault == "the camera moved: re-referencing failed: no floor"


def _floor_map(slope: float, offset: float, box_rows: int = 0) -> np.ndarray:
    h, w = 240, 320
    rows = np.arange(h, dtype=np.float32)[:, None]
    disp = np.repeat(slope * rows + offset, w, axis=1).astype(np.float32)
    disp[:120] = np.nan
    if box_rows:  # a box filling most of the low rows' width at one disparity
        disp[144:144 + box_rows, : int(w * 0.7)] = 21.0
    disp[200:, 100:160] = np.nan  # the robot's region left out
    return disp


def test_the_floor_refitted_after_a_pitch_keeps_its_slope_and_finds_the_new_offset():
    reference = Floor(0.24, -28.5)
    pitched = _floor_map(0.24, -28.5 + 3.5, box_rows=40)
    floor = refit_floor(pitched, reference)
    assert floor is not None
    assert floor.slope == reference.slope
    assert abs(floor.offset - (-25.0)) < 0.3


def test_no_floor_to_refit_where_the_low_rows_show_none():
    disp = np.full((240, 320), np.nan, np.float32)
    assert refit_floor(disp, Floor(0.24, -28.5)) is None


def test_a_lane_met_while_the_camera_moved_does_not_end_the_wait_for_the_re_reference():
    """The moved camera's wait goes on when an object in the lane is met in the same frame
    (seen on the old floor line): before, the lane wait replaced it, the next re-measure found
    the camera moved again, and the third time ended the run. A reset still replaces it."""
    rec = Recovery(dict(BOUNDS))
    assert rec.begin(1.0, MOVED, "the camera moved")
    assert rec.begin(1.0, LANE, "an object in the lane")
    assert rec.kind == MOVED and rec.reason == "the camera moved"
    assert rec.update(1.1, False) == WAIT
    assert rec.begin(1.2, RESET, "the board reset")
    assert rec.kind == RESET
