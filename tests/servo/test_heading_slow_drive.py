"""A slow drive never shows its heading at 2 m (clearance.Heading): the chord it takes must
run 2 depth noises over tan(max_spread) (5.5 cm at 1.95 m, 0.05 px) within window_s (1 s), more
than a drive at 4.5 cm/s (the controller's slow_duty by an end, 220) runs. Seed 18 #85 (traced
singly at a199819, tools/trace_fixed_stop.py 85 --seed 18): after a turn round, driven toward
the camera at 4.5 cm/s by box 2's end 1.95 m deep, truly 28 degrees off the axis and away from
the end, the heading stayed unknown and the check along the axis (5 degrees, the commanded
arc 180/290) stopped it 0.04 m on; on the true heading the run was clear. Kept as xfail
(strict) until a mend lands: the chord's noise taken across it (a depth error moves a
sighting along its line of sight; near the axis the direction is the lateral track's) learns
it, but the spread that gives was over-confident (branch turn12-across: 8 % of noisy frames
beyond it against 1.6 % before, 1.2-3 m, 4.5-24 cm/s, 0-30 degrees); scaled up to as honest a
spread (2.5 of the noise across: 1.1 %) it no longer learns 85's heading within 3 s. Not
merged (turn12, issue 23)."""

from __future__ import annotations

import math

import pytest

from host.servo.clearance import Heading, depth_noise_m

FB = 25.6  # px m at 320x240
SIGMA = 0.05  # px


@pytest.mark.xfail(strict=True, reason="turn12: a slow drive's chord at 2 m (18 #85)")
def test_a_slow_drive_off_the_axis_shows_its_heading() -> None:
    """18 #85's drive: 4.5 cm/s from 1.95 m, 28 degrees off toward -x, facing the camera,
    positions exact: within 1.5 s the heading is known and within its spread of the truth."""
    true_h = math.pi + math.radians(28)
    hd = Heading()
    z, x = 1.95, 0.09
    for k in range(45):
        hd.update(k / 30, z, x, 220, 220, depth_noise_m(z, SIGMA, FB, 1.0))
        z += 0.045 / 30 * math.cos(true_h)
        x += 0.045 / 30 * math.sin(true_h)
    assert hd.value is not None, "the heading is still unknown"
    off = abs((hd.value - true_h + math.pi) % (2 * math.pi) - math.pi)
    assert off <= hd.spread
