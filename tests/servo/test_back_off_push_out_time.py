"""The back-off's wait for the re-measure under a fitted push, judged against the time a back-off
takes to bring the body out of the object's side's depth (recovery.BackOff._out_s; issue 23).

Seed 17 trial 937 (tools/trace_line_stop.py, the servo's figures): the hold's push check fired
level with the face (1.6 mm in front of it), the body's turned gap 2.07 cm (the centre's 3.56,
the card's turn bound 1.49 cm of reach), the push fitted at 0.86 cm/s toward the side: 2.58 cm
over the 3 s horizon, more than the gap, so the back-off's wait ended the run at once, "no safe
way back: pushed toward the object's side while its depth is measured again". In truth both
straight ways were clear by 3.3-3.6 cm, the push 0.81 cm/s, and the re-measure came the next
frame: a back-off toward the camera takes its body out of the face's depth (0.095 m at ~7 cm/s)
in under 2 s, in which the push closes 1.6 cm. Now the wait is judged every frame against that
time (the push's share of it), not the whole horizon at its first frame.
"""

from __future__ import annotations

from host.servo.controller import ControlConfig
from host.servo.recovery import BackOff

BLOCK = ControlConfig().block_m
HORIZON = ControlConfig().push_horizon_s
FRAME_S = 0.033
FACE = 1.2781


def _wait(raw: float, turned: float, push_mps: float, z: float, confirm_after_s: float,
          away: int = 0) -> tuple[BackOff, float, float]:
    """Frames of the wait (the centre's gap raw closing at push_mps), the target confirmed
    after confirm_after_s: the BackOff, when it first moved or ended (s), the gap then."""
    b, t = BackOff(BLOCK), 0.0
    while t < 8.0:
        cmd = b.update(t, z, raw, FACE, t >= confirm_after_s, True, 0.0, push_mps * HORIZON,
                       180, 0.0, True, turned, away)
        if b.outcome or cmd != (0, 0):
            break
        raw -= push_mps * FRAME_S
        t += FRAME_S
    return b, t, raw - turned


def test_trial_937_waits_for_the_re_measure_and_backs_off() -> None:
    """937's figures, confirmed the next frame: it backs off toward the camera (a199819 ended
    the run on the first frame of the wait)."""
    b, t, gap = _wait(0.0356, 0.0149, 0.0086, 1.2765, 0.03)
    assert b.outcome == "" and b.deeper is False
    assert gap > 0.02


def test_a_long_re_measure_still_ends_named_before_the_push_closes() -> None:
    """The same, the re-measure not done: the wait ends named once the gap is what the push
    closes while a back-off would take the body out, the body still clear of the side (by
    about that much)."""
    b, t, gap = _wait(0.0356, 0.0149, 0.0086, 1.2765, 10.0)
    assert b.outcome.startswith("no safe way back: pushed toward the object's side")
    assert 0.0 < t < 1.0
    assert 0.013 < gap < 0.018


def test_trial_162_still_ends_named_standing() -> None:
    """Seed 14 trial 162 (a right stop, test_back_off_pushed_standing.py): 1.9 cm at 0.89 cm/s,
    1.5 cm behind the face: the wait ends named within a few frames, standing."""
    b, t, gap = _wait(0.019, 0.0, 0.0089, FACE + 0.015, 10.0)
    assert b.outcome.startswith("no safe way back: pushed toward the object's side")
    assert t < 0.5 and gap > 0.015


def test_backing_off_deeper_keeps_the_whole_horizon() -> None:
    """Beyond the face (3 cm: it would back off deeper, beside the side all the way) the push
    over the whole horizon judges the wait, as before: 937's gap at 0.75 cm/s (2.25 cm over
    the horizon) ends it at once."""
    b, t, _ = _wait(0.0356, 0.0149, 0.0075, FACE + 0.03, 10.0)
    assert b.outcome.startswith("no safe way back: pushed toward the object's side")
    assert t == 0.0


def test_its_line_away_from_the_side_deeper_keeps_the_whole_horizon() -> None:
    """Level with the face, the heading taking its line away from the side deeper (away +1:
    the first way is deeper): the whole horizon, as before."""
    b, t, _ = _wait(0.0356, 0.0149, 0.0086, 1.2765, 10.0, away=1)
    assert b.outcome.startswith("no safe way back: pushed toward the object's side")
    assert t == 0.0
