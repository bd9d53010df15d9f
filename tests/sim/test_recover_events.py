"""The servo waits out what passes and recovers (host/servo/recovery.py), in the simulated world.

Each recoverable event of issue 23 in a short scenario: the run must go on to hold (safely, as
the trials judge it) and say that it recovered; each bound must end the run in its named stop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest

from host.emulator.emulator import Faults as LinkFaults
from host.link import protocol_gen as gen
from host.servo.recovery import BOUNDS, LANE, MOVED, RESET, TARGET, Bound, Recovery
from host.servo_run import HELD, Rules, run_servo
from host.sim.faults import Event, WorldFaults
from host.sim.run import Setup, simulation
from host.sim.trials import HOLD_WITHIN_M, Judge

SEED = 3  # never 7 or 8 (held out)


@dataclass
class Run:
    how: str
    reason: str
    error_m: float
    recovered: list[str]  # the kinds of wait that resumed
    notes: list[str]


def run(events: tuple[Event, ...] = (), link: LinkFaults = LinkFaults(), start_z: float = 1.9,
        seconds: float = 25.0, bounds: dict[str, Bound] | None = None) -> Run:
    setup = Setup(start_z_m=start_z, faults=WorldFaults(events=events, link=link), seed=SEED)
    last = max((e.t_s + e.duration_s for e in events), default=0.0)
    with simulation(setup) as sim:
        if bounds is not None:
            sim.servo.recovery = Recovery(bounds)
        end = run_servo(sim.servo, Rules(settle_s=1.0, limit_s=seconds, lost_s=5.0,
                                         hold_from_s=last + 2.5),
                        sim.source.clock, lambda: sim.world.robot.z_m, watch=Judge(sim))
        return Run(end.how, end.reason, sim.depth_error_m(),
                   [k for _, k, _ in sim.servo.recovery.recovered], list(sim.servo.notes))


def _held(r: Run, kind: str) -> None:
    assert r.how == HELD, (r.how, r.reason, r.notes)
    assert abs(r.error_m) <= HOLD_WITHIN_M
    assert kind in r.recovered, r.notes


BOOT_LOST = LinkFaults(reset_at_ms=3000, reset_cause=int(gen.ResetCause.WATCHDOG),
                       boot_lost=True)


@pytest.mark.parametrize("angle", [1.5, -2.0], ids=["down 1.5 deg", "up 2 deg"])
def test_a_knocked_camera_is_re_referenced_and_the_robot_holds(angle):
    r = run((Event(2.0, "knock", angle_deg=angle),), bounds=BOUNDS)  # re-reference on
    _held(r, MOVED)
    assert any(n.startswith("re-referenced") for n in r.notes)


def test_a_reset_whose_boot_frame_is_lost_is_waited_out_and_the_robot_re_acquired():
    _held(run(link=BOOT_LOST), RESET)


def test_a_box_put_down_in_the_lane_is_waited_out_and_the_target_taken_up_again():
    r = run((Event(1.0, "lane-box", ahead_m=0.35, width_m=0.3, duration_s=5.0),), start_z=0.6)
    _held(r, LANE)


def test_a_box_left_in_the_lane_ends_the_run_after_the_lane_bound():
    bounds = {**BOUNDS, LANE: Bound(4.0, 1.0, 6), TARGET: Bound(0.0, 0.0, 0)}
    r = run((Event(1.0, "lane-box", ahead_m=0.35, width_m=0.3),), start_z=0.6,
            bounds=bounds)
    assert r.how == "stopped"
    assert r.reason.startswith("an object in the lane") and r.reason.endswith("for 4 s"), r


def test_a_camera_knocked_more_often_than_the_bound_ends_the_run_with_its_reason():
    bounds = {**BOUNDS, MOVED: Bound(10.0, 0.0, 1)}
    r = run((Event(2.0, "knock", angle_deg=1.5), Event(7.0, "knock", angle_deg=1.5)),
            bounds=bounds)
    assert r.how == "stopped"
    assert "the camera moved since the reference" in r.reason
    assert r.reason.endswith("(the second time in this run)"), r.reason
    assert not math.isnan(r.error_m)


def test_at_the_defaults_a_knocked_camera_is_re_referenced_and_the_robot_holds():
    """The re-reference is on by default (ServoConfig.rereference); before, a moved camera
    ended the run ("the camera moved since the reference")."""
    r = run((Event(2.0, "knock", angle_deg=1.5),))
    _held(r, MOVED)
    assert any(n.startswith("re-referenced after the camera moved") for n in r.notes), r.notes


def test_a_look_alike_that_replaced_the_target_during_a_knock_is_no_re_reference():
    """The rig is knocked while the target box (1.2 m, left of the lane) is taken away and a
    box appears right of the lane at its depth: the nearest object after the knock, within the
    10 % of disparity the re-reference allowed before, which took it for the target and drove
    the robot to it. It is not where the target was, moved with the picture, and the target's
    own picture is gone (the first check to say so, since the picture is taken from the last
    re-measure and the reference no longer faded by the phase correlation's window): the robot
    stays stopped and the run ends naming why."""
    events = (Event(2.0, "knock", angle_deg=1.5), Event(2.0, "vanish", 0),
              Event(2.0, "appear", box=(1.2, 0.25, 0.5, 0.38)))
    r = run(events)
    assert r.how == "stopped", (r.how, r.reason, r.notes)
    assert "re-referencing failed: the nearest object is not where the target was" in \
        r.reason or "re-referencing failed: the target's picture is not where the " \
        "picture's shift puts it" in r.reason, r.reason
    assert not any(n.startswith("re-referenced") for n in r.notes), r.notes


def test_a_knock_with_the_marker_hidden_ends_the_run_at_the_moved_bound():
    """With the card hidden behind a post after a knock, the re-reference masks the robot by
    its last admitted sighting (moved by the picture's shift): the post, nearer than the
    target, is then the nearest object and the re-reference fails, named; were it to wait for a
    sighting instead, the wait ends the run at its 10 s bound with its reason. Either way the
    run ends stopped, naming the moved camera. Before, the wait's give-up set the reason but
    left the phase "recover": the run went on standing until its time limit."""
    r = run((Event(2.0, "knock", angle_deg=1.5),
             Event(2.0, "occlude", fraction=1.0, duration_s=30.0)), start_z=0.6, seconds=20.0)
    assert r.how == "stopped", (r.how, r.reason, r.notes)
    assert "the camera moved since the reference" in r.reason, r.reason
    assert r.reason.endswith("for 10 s") or "re-referencing failed" in r.reason, r.reason


def test_a_knock_after_a_nearer_object_became_the_target_is_re_referenced():
    """A box put down at 1.05 m right of the lane becomes the target (nearer than the one at
    1.2 m); then the rig is knocked. The reference phase's picture has only the wall and the
    floor where the new target stands: its picture is looked for in the last re-measure's
    frame instead (before, "the target's picture is not where the picture's shift puts it"
    and the run ended)."""
    r = run((Event(0.5, "appear", box=(1.05, 0.25, 0.5, 0.38)),
             Event(6.0, "knock", angle_deg=1.5)), seconds=30.0)
    assert any(n.startswith("a nearer object appeared") for n in r.notes), r.notes
    _held(r, MOVED)
    assert any(n.startswith("re-referenced after the camera moved") for n in r.notes), r.notes
