"""A probe whose card stays unseen ends the run, named, instead of standing to the run's limit
(host/servo/acquire.py, AcquireConfig.probe_unseen_s): dev seed 105's trial 24 stood in its
probe from 38 s to 45 s with the marker unseen and ended "did not settle in 45 s"."""

from __future__ import annotations

from host.servo.acquire import PROBE_UNSEEN, AcquireConfig, Acquisition
from host.servo.phase import Phase

DT = 1 / 15


def _in_probe() -> tuple[Acquisition, float]:
    """An acquisition through its find and measure, into the probe's first leg (2.2 m)."""
    acq = Acquisition()
    t = 0.0
    while acq.phase != Phase.PROBE:
        acq.update(t, (2.2, 0.0), 11.6, 0.005)
        t += DT
        assert t < 5.0 and not acq.fault
    return acq, t


def test_a_probe_unseen_for_its_limit_stops_the_run_named() -> None:
    acq, t = _in_probe()
    acq.update(t, (2.2, 0.0), 11.6, 0.005)  # one sighting in the probe, then none
    seen = t
    while not acq.fault and t < seen + 20.0:
        t += DT
        order = acq.update(t, None, None, 0.005)
        assert (order.left, order.right) == (0, 0)  # it stands meanwhile
    limit = AcquireConfig().probe_unseen_s
    assert acq.fault.startswith(PROBE_UNSEEN.split("{")[0]), acq.fault
    assert limit < t - seen <= limit + 2 * DT


def test_a_probe_unseen_for_less_goes_on() -> None:
    """Hidden for 3 s (a walker), the probe stands and goes on when the card is back."""
    acq, t = _in_probe()
    acq.update(t, (2.2, 0.0), 11.6, 0.005)
    end = t + 3.0
    while t < end:
        t += DT
        acq.update(t, None, None, 0.005)
    order = acq.update(t + DT, (2.2, 0.0), 11.6, 0.005)
    assert not acq.fault and order.phase == Phase.PROBE and (order.left, order.right) != (0, 0)
