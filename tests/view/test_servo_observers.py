"""The servo's read-only interface to the view: every step reaches the observers as a Snapshot
(image, disparity, target, marker, row, link stats), and request_stop makes the next step send
STOP with phase "stop"."""

from __future__ import annotations

import numpy as np

from host.emulator.emulator import Emulator, PtyService
from host.link.client import RobotLink
from host.servo.phase import Phase
from host.servo.snapshot import Snapshot
from host.sim.run import Setup, simulation


def test_observers_see_every_step_and_stop_is_sent():
    seen: list[Snapshot] = []
    with simulation(Setup(), reference=False) as sim:
        servo, link, emulator = sim.servo, sim.link, sim.emulator
        servo.observers.append(seen.append)
        servo.reference()
        assert [s.phase for s in seen] == [Phase.REFERENCE] * 5
        assert seen[0].disparity.shape == (240, 320) and seen[0].disparity_y0 == 0
        rows = [servo.step() for _ in range(40)]
        moving = [s for s in seen[5:] if s.row.left or s.row.right]
        assert moving and moving[-1].reason == ""
        assert len(seen) == 45 and [s.row for s in seen[5:]] == rows
        marked = [s for s in seen[5:] if s.marker_pair is not None]
        assert marked, "the marker is found in some steps"
        band = marked[-1]
        assert band.disparity is not None and band.disparity.shape[1] == 320
        v = band.marker_pair.left.v
        assert band.disparity_y0 <= v < band.disparity_y0 + len(band.disparity)
        assert band.target is servo.target and band.left.shape[:2] == (240, 320)
        assert band.link.schema_hash == link.hello.schema_hash and band.link.rtt_ms > 0
        assert band.link.reset_cause == "power on"
        servo.request_stop("pressed")
        row = servo.step()
        assert row.phase == Phase.STOP and (row.left, row.right) == (0, 0)
        assert seen[-1].phase == Phase.STOP and seen[-1].reason == "pressed"
        assert link.status().left == 0 and emulator.motors() == (0, 0)
    assert not any(np.shares_memory(s.left, t.left) for s, t in zip(seen, seen[1:]))


def test_link_stats_count_resends_and_nacks_on_a_faulty_line():
    from host.emulator.emulator import Faults
    from host.servo.snapshot import link_stats

    emulator = Emulator(Faults(corrupt=0.03, seed=3))
    with PtyService(emulator, realtime=True) as service, RobotLink(service.path) as link:
        clean = link_stats(link, 1.0)
        for i in range(12):
            link.drive(100 + i, 100 + i)
        stats = link_stats(link, 2.0)
    assert clean.resends == 0 and clean.nacks == 0
    assert stats.resends > 0 and stats.resends >= stats.nacks
    assert stats.rtt_ms == 2.0 and stats.schema_hash == clean.schema_hash
