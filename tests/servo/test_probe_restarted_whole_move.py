"""A probe started again decides on its whole move since the measure, not on its last start's
sightings alone (issue 23): seed 15's trial 358 (0.84 m, drop-burst) drove 0.56 s, lost its
frames, was started again by a stale one, and when its time in all ran out its last start had
seen 1.4 cm of a move that was 4.8 cm since the measure (the robot standing in it): "the marker
did not move when the robot was driven" left the robot's own card out as a look-alike, and the
search for another ended "not found again". A marker that truly does not move still shows no
move either way."""

from __future__ import annotations

from host.servo.acquire import NOT_MOVED, AcquireConfig, Acquisition
from host.servo.phase import Phase

DT = 0.07
FB = 25.8  # focal length times baseline (px m), as the trials' 320x240 rig


def _run(moves: bool) -> Acquisition:
    """A robot facing away at 0.84 m (the probe drives it forward, 0.1 m/s per 1000 of duty,
    its wheels a frame late; it stands when the probe does), or a look-alike (moves False).
    0.56 s into the probe its frames are lost (unseen) for 0.3 s, a stale frame starts the
    probe again, and the card is unseen 0.27 s more."""
    acq = Acquisition(AcquireConfig())
    t, z, left = 0.0, 0.84, 0
    began: float | None = None
    while not acq.done and not acq.fault and t < 10.0:
        t += DT
        z += (0.1 * left / 1000 * DT) if moves else 0.0
        if acq.phase == Phase.PROBE and began is None:
            began = t
        rel = -1.0 if began is None else t - began
        if 0.56 < rel < 0.86:
            order = acq.update(t, None, None, 0.0005)  # frames lost: unseen
        elif 0.86 <= rel < 0.86 + DT:
            acq.interrupted(t)  # a stale frame: the probe begins again
            left = 0
            continue
        elif 0.86 + DT <= rel < 1.13 + DT:
            order = acq.update(t, None, None, 0.0005)
        else:
            seen = z - 0.005
            order = acq.update(t, (seen, 0.0), FB / seen, 0.0005)
        if acq.phase == Phase.MEASURE:
            acq.direction = 1
        left = order.left
    return acq


def test_a_restarted_probe_decides_on_its_whole_move_since_the_measure() -> None:
    acq = _run(moves=True)
    assert acq.fault != NOT_MOVED, "the robot's own card taken for a look-alike"
    assert acq.done and acq.facing_away is True, acq.fault


def test_a_restarted_probe_of_a_still_marker_is_still_not_moved() -> None:
    acq = _run(moves=False)
    assert acq.fault == NOT_MOVED and not acq.done
