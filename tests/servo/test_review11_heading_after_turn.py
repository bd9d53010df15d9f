"""After a spin (a turn round, a search) the heading is forgotten (clearance.Heading) and a
drive is checked against the fixed objects along the depth axis within unknown_spread (5
degrees: motion_heading, loop.py _fixed_fault) until its travel shows the heading again (a
chord of 5-10 cm at 1.7-1.9 m). Seed 17's turns round ended 12-36 degrees off the axis
(docs/servo.md, fixed2: 762, 763, 969, where the error lay away from box 2's end and the axis
check stopped them falsely). Mirrored, toward the end, the axis check sees the end only once
the heading is learnt, and the reaction and run-down then carry the turned body onto it
(review11, issue 23). Pure functions only: the check composed as _fixed_fault composes it,
the robot moved on its true heading frame by frame, the estimate = the truth."""

from __future__ import annotations

import math

from host.servo.clearance import (
    Body,
    Heading,
    depth_noise_m,
    facing_shown,
    motion_heading,
    run_fault,
    swept,
)
from host.servo.perception import stopping_distance_m
from tests.servo.test_clearance import _face

END = _face(1.60, -0.60, -0.25)  # box 2's face; its end at x = -0.25
FB = 25.6  # px m, focal x baseline at 320x240 (docs/servo.md)
SIGMA = 0.05  # px, a sighting's disparity noise
SPEED = 0.24  # m/s, the drive at max_duty 600
DT = 1 / 30
BODY = Body(0.08, 0.08, 0.02 + 0.01)  # half width, half length, block_margin_m + cell / 2
TRUE_BODY = Body(0.08, 0.08, 0.0)
RUN_ON = SPEED * (0.25 + 0.08)  # the reaction and run-down after the check fires


def _drive_after_spin(z0: float, x0: float, off_deg: float, shown: bool = True
                      ) -> tuple[int | None, float | None]:
    """A spin at (z0, x0), then a drive toward the camera (facing_away False) on a true heading
    off_deg off the axis (positive: toward -x, box 2's end). The frame the check fires and
    how far on (m) the true body meets a cell by the time it stands (None: clear). shown: the
    card's turn bound (loop.py passes the median of the controller's last three) is the true
    turn, noise-free; else none is known."""
    turned = math.radians(abs(off_deg)) if shown else None
    hd = Heading()
    t = 0.0
    for _ in range(10):
        hd.update(t, z0, x0, 300, -300, depth_noise_m(z0, SIGMA, FB, 1.0))
        t += DT
    true_h = math.pi + math.radians(off_deg)
    z, x = z0, x0
    for k in range(60):
        noise = depth_noise_m(z, SIGMA, FB, 1.0)
        hd.update(t, z, x, 600, 600, noise)
        h, spread = motion_heading(hd, False, turned)
        travel = stopping_distance_m(SPEED, margin_m=0.02)
        hit = run_fault(END, z, x, 600, 600, h, spread, travel, BODY, 0.12)
        if hit is None and not facing_shown(hd, False):
            hit = run_fault(END, z, x, 600, 600, h + math.pi, spread, travel + 3 * noise,
                            BODY, 0.12)
        if hit is not None:
            done = math.hypot(z - z0, x - x0) + RUN_ON
            return k, swept(END, z0, x0, true_h, done, TRUE_BODY)
        z += SPEED * DT * math.cos(true_h)
        x += SPEED * DT * math.sin(true_h)
        t += DT
    return None, swept(END, z0, x0, true_h, math.hypot(z - z0, x - x0), TRUE_BODY)


def test_a_drive_after_a_turn_ended_toward_an_end_stops_short_of_it() -> None:
    """At 1.75 m, the body's side 7 cm from box 2's end (axis-clear by 4 cm beyond the check's
    margins), the turn round ended 30 degrees toward the end: the check must fire while the
    body can still stand clear. At b6af144..a50cb3f (5 degrees while unknown) it fires at frame
    6, once the chord shows the heading, and the body meets the end 0.12 m on."""
    fired, met = _drive_after_spin(1.75, -0.10, 30.0)
    assert fired is not None
    assert met is None, f"the check fired at frame {fired}; the true body met the end {met} m on"


def test_the_same_turn_ended_20_degrees_toward_the_end() -> None:
    """At 1.75 m, the side 5 cm from the end, 20 degrees off toward it: the same (frame 4, the
    end met 0.10 m on at the 5 degrees)."""
    fired, met = _drive_after_spin(1.75, -0.12, 20.0)
    assert fired is not None and met is None, (fired, met)


def test_with_no_turn_shown_the_spread_covers_a_turns_end() -> None:
    """No sighting's turn bound: spun_spread (40 degrees) covers the 12-36 degrees seen."""
    for x0, off in ((-0.10, 30.0), (-0.12, 20.0)):
        fired, met = _drive_after_spin(1.75, x0, off, shown=False)
        assert fired is not None and met is None, (x0, off, fired, met)


def test_a_straight_drive_after_a_spin_well_clear_of_an_end_goes_on() -> None:
    """The mend's other side: 25 cm from the end (the body's side 17 cm), square to the axis
    or 30 degrees off either way, the drive goes on unstopped while it passes the end: the
    wide spread covers the stopping distance only (seen failing with the check refusing every
    drive whose heading is unknown after a spin). Its price, not asserted here: with the side
    within ~12 cm of an end (x0 -0.06..-0.10 at 1.75 m) a drive after a spin is now refused
    even when truly straight (a named stop; at 5 degrees it went on)."""
    for off in (0.0, 30.0, -30.0):
        fired, met = _drive_after_spin(1.75, 0.0, off)
        assert met is None and fired is None, (off, fired, met)


def test_known_heading_unchanged() -> None:
    """Once the travel shows the heading, the check runs along it within its own spread (the
    mend touches only the unknown heading after a spin)."""
    hd = Heading()
    hd.value, hd.spread = math.pi + 0.1, 0.05
    assert motion_heading(hd, False) == (math.pi + 0.1, 0.05)
