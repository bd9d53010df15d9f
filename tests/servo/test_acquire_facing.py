"""The probe's verdict on the way the robot faces rests on a move beyond the depth noise at its
range, never on the sign of a move within it (issue 23: seed 12's trial 246 at 3 m took a jump of
its sightings' persistent error for its move, "faces the camera", and drove toward the wall
behind it). Unit runs of the acquisition against a robot that answers its orders."""

from __future__ import annotations

from host.servo.acquire import UNSHOWN, AcquireConfig, Acquisition
from host.servo.phase import Phase

DT = 0.033
FB = 25.8  # focal length times baseline (px m): 8.6 px at 3 m, as the trials' 320x240 rig


def _probe(z0: float, away: bool, speed: float, error, noise_m: float = 0.016,
           t_end: float = 12.0) -> tuple[Acquisition, list[float]]:
    """Find, measure and probe a robot standing at z0 (m) that faces away (or the camera) and
    moves at `speed` (m/s per 1000 of duty, its wheels answering the order a frame late); a
    sighting's depth is the truth plus error(t) (m). Backward probe (the target is nearer the
    camera). The acquisition and the true depths."""
    acq = Acquisition(AcquireConfig())
    t, z, left = 0.0, z0, 0
    truth = []
    while not acq.done and not acq.fault and t < t_end:
        t += DT
        z += (1 if away else -1) * speed * left / 1000 * DT
        truth.append(z)
        seen = z + error(t)
        order = acq.update(t, (seen, -0.08), FB / seen, noise_m)
        if acq.phase == Phase.MEASURE:
            acq.direction = -1
        left = order.left
    return acq, truth


def _jump(t: float) -> float:
    """Seed 12 #246's sightings at 3 m: 10 cm short, then 2 cm short for five frames from the
    probe's tenth sighting (a jump of 8 cm in one frame), then 10 cm short again."""
    return -0.02 if 0.62 < t < 0.79 else -0.10


def test_a_far_probe_does_not_take_a_jump_of_its_sightings_for_the_move() -> None:
    """At 3 m the robot, facing away, backs slowly toward the camera (3 cm/s at the probe's
    first duty) while its sightings jump 7.7 cm the other way: beyond three of the measure's
    noise (1.6 cm) but not of a sighting's persistent error there (0.1 px: 3.5 cm). The probe
    must not say "faces the camera"; it backs the other way through its start, and that leg's
    move, twice the first's, shows it faces away. The robot stays within its first leg's reach
    of where it began."""
    acq, truth = _probe(3.0, away=True, speed=0.1, error=_jump)
    assert acq.facing_away is not False, "a jump of the far sightings taken for the move"
    assert acq.done and acq.facing_away is True and not acq.fault, acq.fault
    first_leg = 3.0 - min(truth)
    assert max(truth) - 3.0 <= first_leg + 0.001, (min(truth), max(truth))


def test_a_probe_whose_move_stays_within_the_noise_stops_named() -> None:
    """At 3 m a robot facing the camera that moves 2 cm/s at the probe's duties: its first leg
    (3 cm) and its way back (twice that) stay within the noise there (three of 3.5 cm): the
    probe says so and the run stops; no verdict on the sign of a move within the noise. Its way
    back went no further beyond the start than the first leg went."""
    acq, truth = _probe(3.0, away=False, speed=0.06, error=lambda t: -0.06)
    assert acq.facing_away is None and not acq.done, acq.facing_away
    assert acq.fault.startswith(UNSHOWN.split(":")[0]), acq.fault
    first_leg = max(truth) - 3.0  # backed away from the camera, then forward through the start
    assert first_leg > 0.02 and 3.0 - min(truth) <= first_leg + 0.001, (min(truth), max(truth))


def test_a_near_probe_decides_on_its_first_leg_as_before() -> None:
    """At 1.2 m (a sighting's floor 0.5 cm) a move of 2 cm shows the facing on the probe's first
    leg: a robot facing the camera, backed, moves away from it."""
    acq, truth = _probe(1.2, away=False, speed=0.1, error=lambda t: 0.0, noise_m=0.004)
    assert acq.done and acq.facing_away is False
    assert min(truth) >= 1.2 - 1e-9  # no second leg: it never came back through the start
