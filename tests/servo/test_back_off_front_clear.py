"""The back-off in front of the object's face judged on the body itself (recovery.front_clear,
issue 23). Seed 18 trial 46 (tools/trace_line_stop.py, the campaign at a199819): pushed
sideways while holding level with the face (0.43 cm/s toward the side), the back-off went
toward the camera, its heading 18.8 degrees, so its line closed on the side (the centre 2.6
cm over 8.8 cm of depth), and 8.6 cm in front of the face it stopped, "no safe way back:
backing off closes on the object's side": the body's reach across (10.2 cm) and its reach in
depth were taken apart, as if one corner reached both. The turned rectangle was 4.3 cm clear
of the side and what runs back from it in truth, both straight ways too; held on, it was out
of the face's depth within 2 cm more. Now, in front of the face going toward the camera, a body
that the rectangle (turned any way within the card's bound) shows clear of that region by
side_m from here until it is in front of the face, the centre closing as it has, is neither
closing nor at the side; nearer the side the rules are as before.
"""

from __future__ import annotations

import math

from host.servo.recovery import DONE, BackOff
from tests.servo.rect_clear import rect_clear

BLOCK = 0.15
SIDE = -0.18  # the box's side (x1); the box runs toward -x
FACE = 1.3275
THETA = math.radians(18.8)  # deeper takes the line away from the side (+x)
TURNED = 0.08 * (math.cos(THETA) + math.sin(THETA)) - 0.08


def _run(gap: float, push: float = -0.0043, z: float = 1.3295) -> tuple[BackOff, float, float]:
    """The back-off from the hold (the centre gap beyond half the width), the robot moving
    along THETA at the duty's speed, the push sideways: the BackOff, the least true clearance
    of the turned body to the side's region, the final depth."""
    b, x, t, least = BackOff(BLOCK), SIDE + 0.08 + gap, 0.0, 1.0
    while t < 12.0 and not b.outcome:
        left, right = b.update(t, z, x - SIDE - 0.08, FACE, True, True, 0.0, push * 3.0,
                               turned_m=TURNED)
        duty = (left + right) / 2
        v = 0.0 if abs(duty) <= 120 else math.copysign(0.35 * (abs(duty) - 120) / 880, duty)
        z, x = z + v * math.cos(THETA) / 30, x + (v * math.sin(THETA) + push) / 30
        least = min(least, rect_clear(x, z, THETA, SIDE, FACE))
        t += 1 / 30
    return b, least, z


# trial 46's back-off frames, the servo's figures: (t, depth, the centre's gap less half the
# width, turned_m); the target confirmed from the second; pushed_m 1.47 cm
FRAMES_46 = [(9.48, 1.3297, 0.0488, 0.0167),
          (9.55, 1.3300, 0.0484, 0.0188),
          (9.62, 1.3293, 0.0481, 0.0189),
          (9.68, 1.3284, 0.0478, 0.0169),
          (9.75, 1.3267, 0.0475, 0.0157),
          (9.81, 1.3236, 0.0469, 0.0157),
          (9.88, 1.3194, 0.0460, 0.0169),
          (9.95, 1.3153, 0.0448, 0.0167),
          (10.01, 1.3113, 0.0435, 0.0190),
          (10.08, 1.3058, 0.0422, 0.0167),
          (10.14, 1.3006, 0.0408, 0.0167),
          (10.21, 1.2948, 0.0395, 0.0167),
          (10.28, 1.2899, 0.0379, 0.0189),
          (10.34, 1.2829, 0.0365, 0.0217),
          (10.41, 1.2802, 0.0347, 0.0219),
          (10.47, 1.2747, 0.0331, 0.0221),
          (10.54, 1.2679, 0.0315, 0.0220),
          (10.61, 1.2635, 0.0296, 0.0220),
          (10.67, 1.2574, 0.0279, 0.0220),
          (10.74, 1.2526, 0.0260, 0.0222),
          (10.80, 1.2463, 0.0242, 0.0222),
          (10.87, 1.2425, 0.0220, 0.0223)]


def test_trial_46_goes_on_toward_the_camera() -> None:
    """Trial 46's back-off as the servo saw it: at its last frame (8.6 cm in front of the
    face, the centre 2.2 cm from the side, turned 2.2 cm) it goes on (a199819 stopped it,
    "no safe way back: backing off closes on the object's side")."""
    b = BackOff(BLOCK)
    for k, (t, z, raw, turned) in enumerate(FRAMES_46):
        b.update(t, z, raw, 1.3277, k > 0, True, 0.0, 0.0147, 180, 0.0, True, turned, 0)
    assert b.outcome == "" and b.deeper is False and not b.flipped


def test_a_kinematic_trial_46_is_clear_all_the_way() -> None:
    """The same hold, the robot moving on its heading at the duty's speed under the push: it
    backs off out of the object's depth, the true turned body clear of the side's region by
    2 cm or more all the way, whichever way it takes."""
    for gap in (0.048, 0.055, 0.06):
        b, least, _ = _run(gap)
        assert b.outcome == DONE
        assert least > 0.02


def test_nearer_the_side_the_body_is_never_run_onto_it() -> None:
    """From 1-3 cm from the side (the rectangle not clear by side_m on the way): the rules as
    before decide (it stops named, or the other way), and the true turned body never touches
    the side's region."""
    for gap in (0.01, 0.02, 0.03):
        b, least, _ = _run(gap)
        assert b.outcome.startswith("no safe way back") or b.flipped
        assert least > 0.0


def test_front_clear_takes_the_turn_either_way() -> None:
    """The rectangle within the card's bound either way: level with the face, 2 cm from the
    side by half the width, turned up to 30 degrees, it is not clear (a turn away from the
    side swings the far corner toward it behind the face), square it is clear by 2 cm."""
    from host.servo.recovery import front_clear
    turned30 = 0.08 * (math.cos(math.radians(30)) + math.sin(math.radians(30))) - 0.08
    assert front_clear(0.02, -0.01, 0.0, 0.0) > 0.019
    assert front_clear(0.02, -0.01, turned30, 0.0) < 0.0
