"""The card lost while driving (refind.py, Servo._refind_step): the robot spins back against the
turn its drive made until the card is square again, or looks for it in the whole view, instead of
standing "lost" until the run's limit (dev seed 104's trial 66: steered 50 degrees off at 2.5 m
and lost for 5 s); a drive does not turn an already turned card farther; a heading found wrong
over the drives before a loss is turned round; a re-acquisition whose find fails says so."""

from __future__ import annotations

import math

import numpy as np

from host.camera.geometry import Geometry
from host.servo.acquire import NEVER_SEEN, NOT_FOUND_AGAIN, AcquireConfig, Acquisition
from host.servo.controller import Command, Controller, Observation
from host.servo.loop import Servo
from host.servo.phase import Phase
from host.servo.refind import FOUND, WHOLE, Refind, RefindConfig
from host.stereo.params import MatcherParams


def test_the_spin_back_turns_against_the_drive_until_the_card_is_square() -> None:
    r = Refind(0.0, turned=120.0)  # the drive turned with right > left
    left, right = r.update(0.1, None)
    assert right - left < 0 < left  # the other way, in place
    assert left == -right
    r.update(0.5, 0.75)  # back at the edge of the view: not yet square, spins on
    assert not r.outcome
    assert r.update(0.6, 0.93) == (0, 0) and r.outcome == FOUND
    r = Refind(0.0, turned=-120.0)
    left, right = r.update(0.1, None)
    assert right - left > 0


def test_the_spin_back_ends_past_the_card_s_best_or_in_the_whole_view() -> None:
    r = Refind(0.0, turned=120.0)
    r.update(0.3, 0.86)
    r.update(0.4, 0.77)  # turned past square (noise kept it below 0.9): found
    assert r.outcome == FOUND
    r = Refind(0.0, turned=120.0)
    t = 0.0
    while not r.outcome:
        t += 0.033
        r.update(t, None)
    assert r.outcome == WHOLE and math.isclose(t, RefindConfig().back_s, abs_tol=0.04)


def test_a_card_lost_without_a_turn_is_waited_for_standing() -> None:
    r = Refind(0.0, turned=5.0)
    assert r.update(1.0, None) == (0, 0) and not r.outcome
    assert r.update(1.2, 1.0) == (0, 0) and r.outcome == FOUND
    r = Refind(0.0, turned=0.0)
    r.update(RefindConfig().stand_s + 0.01, None)
    assert r.outcome == WHOLE


def _servo() -> Servo:
    """A servo past its acquisition, facing the camera 2.5 m away from a target at 1.2 m."""
    servo = Servo(None, None, MatcherParams(), Geometry(300.0, 0.06, 160.0, 120.0))  # type: ignore[arg-type]
    servo.controller = c = Controller(1.2)
    c.facing_away = False
    servo.acquisition.phase = Phase.DONE
    return servo


def _frame(servo: Servo, t: float, depth: float | None, lateral: float = 0.0,
           aspect: float = 1.0) -> Command:
    """One frame the way Servo._decide and step go: the controller, then the refind."""
    assert servo.controller is not None
    cmd = servo.controller.update(Observation(t, depth, lateral if depth else None, aspect))
    cmd = servo._refind_step(t, aspect if depth else None, depth, cmd)
    servo._cmd = cmd
    return cmd


def test_a_card_lost_while_steering_is_spun_back_to_and_driving_resumes() -> None:
    servo = _servo()
    t, sent = 0.0, []
    for i in range(40):  # driving in, drifting sideways: the controller steers one way
        t += 0.033
        sent.append(_frame(servo, t, 2.5 - 0.003 * i, lateral=0.002 * i,
                           aspect=max(0.75, 1.0 - 0.01 * i)))
    drive = [c for c in sent if c.phase == Phase.DRIVE]
    turned = sum(c.right - c.left for c in drive)
    assert drive and abs(turned) > 1000
    lost = []
    for _ in range(40):  # the card turned out of view
        t += 0.033
        lost.append(_frame(servo, t, None))
    spins = [c for c in lost if c.phase == Phase.SEARCH]
    assert spins, [c.phase for c in lost]
    assert all(c.left == -c.right and (c.right - c.left) * turned < 0 for c in spins)
    assert all(c.is_stop or c.left == -c.right for c in lost)  # never driven unseen
    assert servo.recovery.kind == "lost"
    back = _frame(servo, t + 0.033, 2.38, lateral=0.08, aspect=0.8)  # back, not square yet
    assert back.phase == Phase.SEARCH
    again = _frame(servo, t + 0.066, 2.38, lateral=0.08, aspect=0.95)
    assert again.phase == Phase.DRIVE and not servo.recovery.active
    assert any("found again" in n for n in servo.notes)


def test_a_card_not_back_after_the_spin_back_is_looked_for_in_the_whole_view() -> None:
    servo = _servo()
    t = 0.0
    for i in range(30):
        t += 0.033
        _frame(servo, t, 2.5 - 0.003 * i, lateral=0.003 * i, aspect=1.0 - 0.008 * i)
    cmds = [Command(0, 0, Phase.WAIT, None)]
    while t < 5.0 and cmds[-1].phase != Phase.FIND:
        t += 0.033
        cmds.append(_frame(servo, t, None))
    assert cmds[-1].phase == Phase.FIND and not servo.acquisition.done
    assert any(c.phase == Phase.SEARCH for c in cmds)  # after the spin back
    assert servo.acquisition.probes  # the heading is probed again
    assert servo.acquisition.again == "the marker was lost while driving"


def test_a_drive_does_not_turn_a_turned_card_farther() -> None:
    servo = _servo()
    t, sent = 0.0, []
    for i in range(40):
        t += 0.033
        sent.append(_frame(servo, t, 2.5 - 0.003 * i, lateral=0.003 * i,
                           aspect=1.0 - 0.006 * i))
    late = [c for c, i in zip(sent, range(40)) if 1.0 - 0.006 * i < RefindConfig().view
            and c.phase == Phase.DRIVE]
    early = [c for c in sent[:20] if c.phase == Phase.DRIVE]
    assert any(c.right != c.left for c in early)  # it steered while the card was square
    assert late and all(c.right == c.left for c in late)  # past 30 degrees: straight


def _driven_away(servo: Servo, rng: np.random.Generator) -> float:
    """30 frames whose depth moves away from the target, 2.5 to 2.65 m, the card square and
    drifting sideways: the time of the last."""
    t = 0.0
    for i in range(30):
        t += 0.033
        _frame(servo, t, 2.5 + 0.005 * i + float(rng.normal(0, 0.02)), lateral=0.002 * i,
               aspect=1.0)
    return t


def test_a_heading_that_drove_the_robot_away_is_turned_round_at_the_loss() -> None:
    """Far away a short drive moves the depth less than its noise, and hard steering loses the
    card before the motion check has its ten sightings: over the drives since the heading was
    set, the depth moved away from the target (2.5 m to 2.65, target 1.2 m)."""
    servo = _servo()
    assert servo.controller is not None
    rng = np.random.default_rng(3)
    t = _driven_away(servo, rng)
    while t < 2.0:
        t += 0.033
        _frame(servo, t, None)
    assert servo.controller.facing_away is True
    assert any("faces the other way" in n for n in servo.notes)


def test_a_re_acquisition_whose_find_fails_says_so() -> None:
    cfg = AcquireConfig()
    for again, said in (("", NEVER_SEEN), ("the robot's board reset", NOT_FOUND_AGAIN)):
        acq = Acquisition(cfg, again=again)
        t = 0.0
        while not acq.fault:
            t += 0.1
            acq.update(t, None, None)
        assert acq.fault.startswith(said), acq.fault
        assert again in acq.fault


def test_the_probe_decides_the_heading_by_the_move_in_depth_not_a_sideways_wobble() -> None:
    """Far away a sighting wobbles sideways by 6 cm while its depth has moved only its noise,
    and the wrong way: the heading is not decided on that (the move's size was once taken
    from both directions; dev seed 104's trial 78 decided "faces the camera" at 2.9 m and drove
    away), but on the move in depth that follows."""
    acq = Acquisition(AcquireConfig())
    t = 0.0
    while acq.phase != Phase.PROBE:
        t += 0.033
        acq.update(t, (2.9, 0.0), 12.0, noise_m=0.01)
    acq.direction = -1  # toward the camera, if it faces away (it does: the depth will fall)
    t0, z = t, 2.9
    while acq.phase == Phase.PROBE and t - t0 < 0.8:  # barely moving yet
        t += 0.033
        wobble = 0.03 if t - t0 > 0.4 else -0.03
        acq.update(t, (z + 0.012 * (t - t0 > 0.4), wobble), 12.0, noise_m=0.01)
    assert acq.phase == Phase.PROBE and not acq.fault
    while acq.phase == Phase.PROBE and t - t0 < 1.5:  # then it moves, toward the camera
        t += 0.033
        z -= 0.004
        acq.update(t, (z, 0.03), 12.0, noise_m=0.01)
    assert acq.done and acq.facing_away is True


def test_a_marker_hidden_during_the_probe_is_no_look_alike() -> None:
    """Hidden for 1.4 s just after the probe began (the robot stands, unseen): the probe's clock
    stops for the gap, instead of timing on through it and finding that the marker "did not
    move" (dev seed 104's trial 61 then left the true marker out as a look-alike and ended "the
    marker was never seen")."""
    acq = Acquisition(AcquireConfig())
    t = 0.0
    while acq.phase != Phase.PROBE:
        t += 0.033
        acq.update(t, (0.9, 0.0), 40.0, noise_m=0.001)
    acq.direction = 1
    for _ in range(3):
        t += 0.033
        acq.update(t, (0.9, 0.0), 40.0, noise_m=0.001)
    while t < 3.0:
        t += 0.033
        acq.update(t, None, None)
    z = 0.9
    while acq.phase == Phase.PROBE and t < 6.0:
        t += 0.033
        order = acq.update(t, (z, 0.0), 40.0, noise_m=0.001)
        z += 0.003 if order.left > 0 else 0.0
    assert not acq.fault and acq.done and acq.facing_away is True


def test_a_card_seen_only_in_glimpses_is_looked_for_as_lost() -> None:
    """Turned 42 degrees, the far card is seen one frame in a few: each glimpse restarted the
    drive for a frame and the "lost" count, which never reached its 0.4 s, so the refind never
    began and the robot stood in place 6 s between glimpses (seed 11's trial 868, not settled in
    45 s). A glimpse shorter than back_frames does not end the loss."""
    servo = _servo()
    t = 0.0
    for i in range(40):  # driving in, steering one way, the card turning away
        t += 0.033
        _frame(servo, t, 2.5 - 0.003 * i, lateral=0.002 * i, aspect=max(0.78, 1.0 - 0.01 * i))
    sent = []
    for _ in range(6):  # a glimpse, then 0.36 s unseen: 0.26 s of it "lost", each time
        t += 0.033
        sent.append(_frame(servo, t, 2.38, lateral=0.08, aspect=0.78))
        for _ in range(11):
            t += 0.033
            sent.append(_frame(servo, t, None))
    assert any(c.phase == Phase.SEARCH for c in sent), [str(c.phase) for c in sent]
    assert servo.recovery.kind == "lost" or any("found again" in n for n in servo.notes)


def test_drives_before_a_re_acquisition_do_not_turn_the_robot_round_after_it() -> None:
    """The depth moved away from the target over drives (2.5 to 2.65 m), then the robot was
    re-acquired (a reset, a moved camera, a whole-view search), its probe setting the heading
    afresh. A loss after three drives on the new heading judges those alone: the drives before
    the probe (LostCard's bookkeeping kept through it) turned the robot round against what the
    probe had just shown."""
    servo = _servo()
    assert servo.controller is not None
    rng = np.random.default_rng(3)
    t = _driven_away(servo, rng)
    servo._reacquire(probe=True, why="the robot's board reset")
    servo.acquisition.phase = Phase.DONE  # its probe showed the heading kept
    for _ in range(3):
        t += 0.033
        _frame(servo, t, 2.65 + float(rng.normal(0, 0.02)), lateral=0.06, aspect=1.0)
    while t < 3.0:
        t += 0.033
        _frame(servo, t, None)
    assert servo.controller.facing_away is False
    assert not any("faces the other way" in n for n in servo.notes), servo.notes
