"""The refused probe's stand (host/servo/acquire.py pause/resume, issue 23): the probe's track
begins again when it resumes, and a frame not fit to use ends the stand."""

from __future__ import annotations

from host.servo.acquire import Acquisition
from host.servo.phase import Phase

DT = 0.0625  # a frame (s)


def _probing_then_standing() -> Acquisition:
    """A probe's first leg, driven 0.5 s with the marker at 2.9 m, refused and standing."""
    acq = Acquisition()
    acq.phase, acq.direction = Phase.PROBE, 1
    for k in range(8):
        acq.update(DT * k, (2.9, 0.0), 8.8, 0.01)
    assert acq.pause(0.5, 0.035)
    return acq


def test_a_push_while_the_probe_stands_is_not_its_move() -> None:
    """Pushed 20 cm nearer while it stood (a person's knock, a hand setting it straight): its
    sightings from before the stand against those after showed a 20 cm move, its facing
    "shown" by a push; its track begins again at the resume, its driving time kept."""
    acq = _probing_then_standing()
    driven = acq.driven_s()
    for k in range(12):  # the stand: its sightings are not the probe's
        assert acq.update(0.5625 + DT * k, (2.7, 0.0), 9.4, 0.01).left == 0
    acq.resume()
    t = 1.3
    for k in range(7):  # standing still where the push put it, the probe driving on
        acq.update(t + DT * k, (2.7, 0.0), 9.4, 0.01)
    assert acq.phase == Phase.PROBE and acq.facing_away is None, acq.facing_away
    assert len(acq._track) == 7 and acq.fault == ""
    assert abs(acq.spent_s - driven - acq.cfg.run_down_s) < 1e-9  # its time before the stand


def test_a_frame_not_fit_to_use_ends_the_stand() -> None:
    """A stale frame while it stands: the probe begins again at the next usable frame
    (interrupted), no longer standing (a stand left set kept it standing with the loop's
    standing check no longer run for it)."""
    acq = _probing_then_standing()
    assert acq.update(0.6, (2.9, 0.0), 8.8, 0.01).left == 0
    acq.interrupted(0.7)
    assert acq.paused_t is None
    assert acq.update(0.8, (2.9, 0.0), 8.8, 0.01).left > 0  # it drives on
