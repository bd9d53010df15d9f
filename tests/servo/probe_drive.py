"""A simulated probe for the acquisition's unit tests: a robot facing away, its sightings a
fraction of its true move, stale frames cutting the probe (tests/servo/test_probe_*.py)."""

from __future__ import annotations

from collections.abc import Callable

from host.servo.acquire import Acquisition
from host.servo.phase import Phase

DT = 0.066
FB = 25.8  # focal length times baseline (px m), as the trials' 320x240 rig


def run_probe(acq: Acquisition, z: float, shows: float, cut_s: float = 1.2,
              stale_s: float = 0.3, speed: float = 0.15,
              until: Callable[[Acquisition], bool] | None = None, z_ref: float | None = None,
              t_end: float = 14.0) -> list[float]:
    """A robot facing away at z (m), moving speed (m/s per 1000 of duty, its wheels a frame
    late); its sightings show the fraction shows of its move from z_ref (default z), 5 cm
    short. The probe backs it; cut_s after the probe began, stale frames for stale_s start it
    again. Until the acquisition ends (or until(acq), or t_end): the robot's true depths, its
    start's first."""
    z0 = z if z_ref is None else z_ref
    t, left = 0.0, 0
    truth: list[float] = [z]
    began: float | None = None
    while not acq.done and not acq.fault and t < t_end and not (until and until(acq)):
        t += DT
        z += speed * left / 1000 * DT
        truth.append(z)
        if acq.phase == Phase.PROBE and began is None:
            began = t
        if began is not None and began + cut_s <= t < began + cut_s + stale_s:
            acq.interrupted(t)  # the loop sends a stop (STALE)
            left = 0
            continue
        seen = z0 + shows * (z - z0) - 0.05
        order = acq.update(t, (seen, 0.0), FB / seen, 0.01)
        if acq.phase == Phase.MEASURE:
            acq.direction = -1
        left = order.left
    return truth
