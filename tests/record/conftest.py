"""A short simulated run recorded once for these tests, with what it saw."""

from __future__ import annotations

import argparse

import pytest


@pytest.fixture(scope="package")
def run(tmp_path_factory):
    """(file, recorder, [(raw pair, snapshot) per step], servo) of a recorded simulated run:
    five reference frames and STEPS steps, the right view captured 8 ms after the left."""
    pytest.importorskip("rosbags")
    from host.record import record_servo
    from host.sim.faults import CameraFaults, WorldFaults
    from host.sim.run import Setup, simulation

    path = tmp_path_factory.mktemp("rec") / "run.mcap"
    # a queue with room for every item: the lockstep loop outruns a real camera, and on a
    # loaded machine the (lower-priority) worker would drop some
    args = argparse.Namespace(record=path, record_compression="zstd", record_queue=10_000)
    seen = []
    faults = WorldFaults(camera=CameraFaults(skew_ms=8.0))  # the right view's stamps differ
    with simulation(Setup((320, 240), 1.9, faults=faults), reference=False) as sim:
        with record_servo(args, sim.servo, sim.source.clock) as rec:
            tap = sim.servo.source
            sim.servo.observers.append(lambda snap: seen.append((tap.last, snap)))
            sim.servo.reference()
            for _ in range(STEPS):
                sim.step()
    return path, rec, seen, sim.servo


STEPS = 30
