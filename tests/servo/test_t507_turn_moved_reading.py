"""Seed 16 trial 507 (session 9): the target box was pushed 22 cm farther (1.35 -> 1.57 m),
onto the depth of the robot standing beside its end; the first re-measure after the move read
it there (16.67 px, 1.55 m) but the target's depth is the median of the last three readings,
so it stayed at 1.34 m. The probe's second leg ended at 1.61 m with the error 27 cm, and the
turn round was checked (Controller.turn_tight -> sweeps) against the object at 1.34 m only: its
circle was clear by depth, the spin began, and 0.7 s later the body's corner was on the box's
side (x -0.18 m). The turn's circle must clear the object at each reading's depth."""

from __future__ import annotations

from host.servo.controller import Controller

FB = 19.21037 * 1.343467  # focal * baseline (px m) from the trial's own target reading
READINGS_PX = (19.22754, 19.21037, 16.66684)  # the tracker's history after the move
KEEP_OUT = (-0.4252, -0.1723)  # the object's measured lateral extent (m)
Z, X = 1.610, -0.065  # the robot's estimate when the turn began (m)


def controller(readings_px: tuple[float, ...]) -> Controller:
    c = Controller(1.343467)
    c.keep_out = KEEP_OUT
    c.readings_m = tuple(FB / d for d in readings_px)
    return c


def test_a_reading_of_the_moved_object_beside_the_robot_refuses_the_turn() -> None:
    c = controller(READINGS_PX)
    e = Z - c.target_m
    assert e > c.cfg.block_m  # by the median alone the turn was clear
    assert c.turn_tight(Z, e, X)  # a reversed leg, not a spin into the box's side
    assert c.sweeps(Z, X)


def test_readings_at_the_median_leave_the_turn_free() -> None:
    c = controller(READINGS_PX[:2] + (READINGS_PX[1],))
    assert not c.turn_tight(Z, Z - c.target_m, X)
    # and a robot well clear of the extent turns even beside the moved reading
    c = controller(READINGS_PX)
    assert not c.turn_tight(Z, Z - c.target_m, 0.15)
