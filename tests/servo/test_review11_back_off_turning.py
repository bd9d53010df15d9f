"""An adverse case for 4ca2a8e (recovery.BackOff: closing is the centre's approach, no longer
the turned body's gap). Level with the object's face, 3 cm beyond it, the centre 2.8 cm from
the side and not approaching, the body turning toward the side: the card's turn bound grows
steadily 0.9 -> 3.4 cm in 0.4 s (far beyond the 0.5-1 cm its median wanders at a steady turn,
seed 17 #226/#364). At b6af144 the shrink of the turned gap was closing: "no safe way back:
backing off closes on the object's side" with 1.0 cm of turned gap left. Since 4ca2a8e only the
gap's own rules act: the stop comes when the turned gap is below 0, i.e. at the modelled
contact, and the run-down (0.08 m/s x 0.33 s) then carries the corner on (review11, issue 23).
xfail (strict): it documents the weakening and turns into an error once a mend lands."""

from __future__ import annotations

import pytest

from host.servo.recovery import BackOff, BackOffConfig


@pytest.mark.xfail(strict=True, reason="4ca2a8e: a steadily growing turn stops at gap < 0")
def test_a_body_turning_toward_the_side_stops_before_its_turned_gap_is_gone() -> None:
    b = BackOff(0.15, BackOffConfig())
    target, raw = 1.245, 0.028
    left = None
    for k in range(14):
        t, z, turned = 5.0 + k / 30, 1.275 + 0.002 * k, 0.009 + 0.002 * k
        b.update(t, z, raw, target, True, True, 0.0, 0.0, 180, 0.0, True, turned, 0)
        if b.outcome:
            left = raw - turned
            break
    assert left is not None and left >= 0.005, (left, b.outcome)
