"""Snapshots as the servo makes them, for the view's tests (a small synthetic scene)."""

from __future__ import annotations

import numpy as np

from host.camera.geometry import Geometry
from host.servo.loop import LogRow
from host.servo.marker import Blob, MarkerPair
from host.servo.perception import Target
from host.servo.phase import Phase
from host.servo.snapshot import LinkStats, Snapshot

GEOMETRY = Geometry.minoru_default(320, 240)


def snapshot(t: float = 1.0, robot_px: float = 20.0, phase: Phase = Phase.DRIVE) -> Snapshot:
    left = np.full((240, 320, 3), 90, np.uint8)
    disp = np.full((240, 320), 12.0, np.float32)
    disp[:, :20] = np.nan  # the left border has no disparity
    depth = GEOMETRY.depth_m(robot_px)
    target_m = GEOMETRY.depth_m(21.3)
    row = LogRow(t, phase, "", target_m, depth, depth - target_m, 21.3, robot_px, robot_px, 300,
                 310, 30.0, 4.0, 0.0)
    return Snapshot(t, phase, "", left, disp, 0, Target(21.3, 900, (100, 60, 40, 50), 0.3),
                    MarkerPair(Blob(200.0, 150.0, 6.0), Blob(200.0 - robot_px, 150.0, 6.0)),
                    row, LinkStats(1.5, 2, 1, 0, "power on", 0, 0xB0CE5B41), GEOMETRY)
