"""The target's picture the re-reference looks for (loop.py's _remeasure keeps it) is taken
only while the camera is where it was: a knock whose floor shift a re-measure did not show yet
must not give the picture the knock is then measured against."""

from __future__ import annotations

import numpy as np

from host.sim.run import Setup, simulation


def test_a_re_measure_after_an_unseen_knock_keeps_the_picture_from_before():
    with simulation(Setup(start_z_m=1.9, seed=2)) as sim:
        servo = sim.servo
        frame = sim.source.read()
        shape = frame.left.shape[:2]
        blank = np.full(shape, np.nan, np.float32)  # no floor rows to tell a move by
        servo._remeasure(blank, frame)
        kept = servo._target_picture
        assert kept is not None
        sim.source.renderer.pitch_deg += 1.4  # knocked: the picture moves 10 rows
        servo._remeasure(blank, sim.source.read())
        assert servo._target_picture is kept
        assert not servo.recovery.kind  # the floor showed nothing: no wait began
