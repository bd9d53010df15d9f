"""The one run driver (host.servo_run): a run ends on the step that sent STOP, never on the step
during which another thread (the view's STOP button) asked for it while a drive went out."""

from __future__ import annotations

from types import SimpleNamespace

from host.servo.phase import Phase
from host.servo_run import STOPPED, Rules, run_servo


class RacedServo:
    """A servo whose first step drives while a STOP is requested meanwhile; the next step sends
    the STOP (as Servo.step does: the request is read once, at the decision)."""

    def __init__(self) -> None:
        self.stop_reason, self.sent = "", []
        self.deadline: float | None = None  # the run driver's (Servo.deadline)

    def step(self, truth: float) -> SimpleNamespace:
        phase = Phase.STOP if self.stop_reason else Phase.DRIVE
        self.sent.append(phase)
        if phase == Phase.DRIVE:
            self.stop_reason = "STOP pressed in the view"  # arrives while the drive goes out
        return SimpleNamespace(phase=phase, t=len(self.sent) * 0.033, reason=self.stop_reason)

    def held_for(self, seconds: float) -> bool:
        return False


def test_a_stop_requested_during_a_drive_ends_the_run_after_the_stop_is_sent() -> None:
    servo = RacedServo()
    end = run_servo(servo, Rules(settle_s=0), clock=lambda: 0.0)
    assert (end.how, end.reason) == (STOPPED, "STOP pressed in the view")
    assert servo.sent == [Phase.DRIVE, Phase.STOP]  # the drive was not the last word


def test_a_run_without_a_limit_does_not_keep_the_deadline_of_one_before_it() -> None:
    """The run driver gives the servo its deadline (Servo._too_late ends a wait near it): a
    second run on the same servo without a limit has none (979f477 left the first run's)."""
    servo = RacedServo()
    run_servo(servo, Rules(settle_s=0, limit_s=45.0), clock=lambda: 10.0)
    assert servo.deadline == 55.0
    servo.stop_reason, servo.sent = "", []
    run_servo(servo, Rules(settle_s=0), clock=lambda: 100.0)
    assert servo.deadline is None
