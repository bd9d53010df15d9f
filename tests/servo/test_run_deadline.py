"""A wait still on just before the run's deadline ends the run as the stop it waits on, named
(host/servo/loop.py Servo._too_late), instead of running out the run driver's limit as "not
settled": seed 12's trial 482 waited on the lane from 28.5 s, and the lane's 20 s bound reached
past the trials' 45 s."""

from __future__ import annotations

from host.camera.geometry import Geometry
from host.servo.controller import Command, Controller
from host.servo.loop import LATE_S, Servo
from host.servo.phase import Phase
from host.servo.recovery import LANE
from host.stereo.params import MatcherParams


def _servo(now: list[float]) -> Servo:
    servo = Servo(None, None, MatcherParams(), Geometry(300.0, 0.06, 160.0, 120.0),  # type: ignore[arg-type]
                  clock=lambda: now[0])
    servo.controller = Controller(1.2)
    servo.acquisition.phase = Phase.DONE
    return servo


def test_a_wait_on_at_the_run_s_deadline_ends_it_named() -> None:
    now = [28.5]
    servo = _servo(now)
    servo.deadline = 45.0
    assert servo.recovery.begin(now[0], LANE, "an object in the lane 0.20 m ahead")
    for t in (30.0, 40.0, 44.0):
        now[0] = t
        assert servo._too_late() == ""
    now[0] = 45.0 - LATE_S
    why = servo._too_late()
    assert why.startswith("an object in the lane 0.20 m ahead: still waiting (lane)"), why


def test_no_wait_or_no_deadline_ends_nothing() -> None:
    now = [44.9]
    servo = _servo(now)
    servo.deadline = 45.0
    assert servo._too_late() == ""  # driving, creeping: "not settled" stays honest
    servo = _servo(now)
    servo.recovery.begin(30.0, LANE, "an object in the lane 0.20 m ahead")
    assert servo._too_late() == ""  # no limit (a camera run): the wait's own bound


def test_a_wait_at_the_deadline_is_noted_without_the_no_progress_account() -> None:
    """The run ended by a wait at its deadline is noted as that wait, without progress.py's
    "the least depth error ...; since then: ..." (an account of no progress, which says nothing
    of the wait and was not the cause: 979f477 added it to every such note)."""
    now = [30.0]
    servo = _servo(now)
    servo.deadline = 45.0
    assert servo.recovery.begin(now[0], LANE, "an object in the lane 0.20 m ahead")
    wait = Command(0, 0, Phase.WAIT, None)
    assert not servo._stalled(now[0], wait, True) and not servo.notes
    now[0] = 45.0 - LATE_S
    assert servo._stalled(now[0], wait, True)
    assert servo.stop_reason.startswith("an object in the lane 0.20 m ahead: still waiting")
    assert servo.notes == [servo.stop_reason], servo.notes
