"""The probe's second leg after a far first leg whose sightings showed no move (issue 23; the
reviewer's "a far look-alike now gets a blind second leg"): such a sighting may be a
look-alike's (another robot's card, a disc on the wall) while the robot, unseen, is driven;
the clearance checks look where the sighting is, not where the robot is. The first leg's
ground the robot has covered already; the second leg runs back through the start and as far
beyond it, onto ground nobody has checked. So beyond the start it goes only when its own move
back shows the sighting going with the robot (still_factor x probe_m: what the first leg's
"no move" could not rule out at that range); back at the start with less, it stops there:
"did not move" under probe_m (the loop looks for another marker), else a named stop. A robot
whose sightings erred together on its first leg (seed 13's trial 42) still decides on its
second (test_probe_far_still)."""

from __future__ import annotations

from host.servo.acquire import BLIND, NOT_MOVED, AcquireConfig, Acquisition
from host.servo.phase import Phase

DT = 0.033
FB = 25.8  # focal length times baseline (px m), as the trials' 320x240 rig


def _look_alike(z0: float, jump_m: float) -> tuple[Acquisition, list[float]]:
    """A still sighting at z0 (m), a look-alike's (its sightings where the measure saw them on
    the first leg; on the second, after its first ten sightings, jump_m farther: a far
    sighting's error, persistent for frames on end), while the robot, from 2.4 m, is driven
    by the probe (0.15 m/s per 1000 of duty, its wheels a frame late). Backward probe."""
    acq = Acquisition(AcquireConfig())
    t, z, left = 0.0, 2.4, 0
    truth = []
    second = 0
    while not acq.done and not acq.fault and t < 12.0:
        t += DT
        z += 0.15 * left / 1000 * DT
        truth.append(z)
        if acq.phase == Phase.PROBE and acq._leg == 2:
            second += 1
        seen = z0 + (jump_m if second > 10 else 0.0)
        order = acq.update(t, (seen, 0.3), FB / seen, 0.016)
        if acq.phase == Phase.MEASURE:
            acq.direction = -1
        left = order.left
    return acq, truth


def test_a_far_still_sighting_does_not_drive_the_robot_beyond_its_start() -> None:
    """A look-alike at 3 m, its sightings still on both legs: the second leg ends back at the
    start, "did not move" (on 4f2b605 the robot went on the first leg's reach beyond it, 8 cm,
    and only then was the marker found not to move)."""
    acq, truth = _look_alike(3.0, 0.0)
    assert acq.fault == NOT_MOVED and acq._leg == 2
    assert max(truth) <= 2.4 + 0.005, f"{100 * (max(truth) - 2.4):.1f} cm beyond the start"


def test_a_small_move_back_does_not_take_the_robot_beyond_its_start() -> None:
    """The look-alike's sightings jump 3 cm on the second leg (beyond probe_m, under still_factor
    x probe_m and three of the noise there): that shows no move with the robot, and the probe
    stops named at the start (on 4f2b605 it drove on beyond and then stopped "could not
    show")."""
    acq, truth = _look_alike(3.0, 0.03)
    assert acq.fault.startswith(BLIND.split(" (")[0]), acq.fault
    assert max(truth) <= 2.4 + 0.005, f"{100 * (max(truth) - 2.4):.1f} cm beyond the start"


def test_a_sighting_that_goes_back_with_the_robot_still_gets_the_whole_second_leg() -> None:
    """The sightings jump 6 cm on the second leg (beyond still_factor x probe_m, within the
    noise at 3 m): the second leg goes on beyond the start, as before."""
    acq, truth = _look_alike(3.0, 0.06)
    assert not acq.fault.startswith(BLIND.split(" (")[0]), acq.fault
    assert max(truth) > 2.4 + 0.02
