"""Backing off the other way past the object's end with a body turned more than its heading
shows (seed 15 trial 857, recovery.BackOff): pushed onto the object's side while holding just
in front of its face, the robot backed off toward the camera; its gap to the side (reckoned
for a body square to the axis: half width 0.08 m) shrank from 2.5 cm to 1.0 cm, so it took
the other way, deeper, past the object's end level with its face. The heading was 2.5 degrees
estimated and 23.5 true (the push and the unequal wheels, 1.05/0.86): the turned body's corner
reached 2.5 cm farther than the gap said and hit the side. Level with the face, closing, a gap
below the corner's reach (half diagonal less half width, 3.3 cm) now ends the back-off named;
a wider gap still takes the other way."""

from __future__ import annotations

from host.servo.recovery import BackOff, BackOffConfig

BLOCK = 0.15  # controller.ControlConfig.block_m
TARGET = 1.034  # the object's depth as measured again (m)
# trial 857's back-off frames (s, the robot's depth m, its gap to the object's side m), 27.405 s
# on: reversing toward the camera, facing away, the gap shrinking 1.5 cm over 2.3 cm of depth
FRAMES = ((27.405, 1.0356, 0.0249), (27.471, 1.0365, 0.0243), (27.537, 1.0355, 0.0236),
          (27.603, 1.0343, 0.0220), (27.669, 1.0310, 0.0200), (27.735, 1.0268, 0.0180),
          (27.768, 1.0251, 0.0169), (28.032, 1.0125, 0.0100))


def _replay(widen: float) -> tuple[BackOff, list[tuple[int, int]]]:
    """The frames, each gap widened by `widen` (m): the back-off and its commands."""
    b = BackOff(BLOCK)
    cmds = [b.update(t, z, gap + widen, TARGET, True, True, 0.041, 0.018)
            for t, z, gap in FRAMES]
    return b, cmds


def test_too_near_to_pass_the_end_turned_stops_named() -> None:
    """Trial 857 at 28.03 s: 1.0 cm reckoned, closing level with the face: it stops, named,
    rather than drive deeper past the object's end (on 43f781b it drove 210/535 forward)."""
    b, cmds = _replay(0.0)
    assert cmds[0][0] < 0 and cmds[0][1] < 0  # it did back off, toward the camera
    assert b.outcome == "no safe way back: backing off closes on the object's side"
    assert cmds[-1] == (0, 0)
    assert not b.flipped


def test_wide_enough_to_pass_the_end_turned_takes_the_other_way() -> None:
    """The same closing with 2.5 cm more gap (3.5 cm left, beyond the corner's reach): the
    other way, deeper (forward: the robot faces away)."""
    b, cmds = _replay(0.025)
    assert b.outcome == "" and b.flipped and b.deeper
    assert cmds[-1][0] > 0 and cmds[-1][1] > 0


def test_corner_reach_is_the_body_turned() -> None:
    """The bound is the body's half diagonal less its half width (0.16 m square body)."""
    assert abs(BackOffConfig().corner_m - (0.08 * 2 ** 0.5 - 0.08)) < 0.001
