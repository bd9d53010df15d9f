"""Stereo pairs to tune on from a camera source: a few frames spread over what it gives (the
Minoru, a replay folder or video, or the simulated world seen from several robot depths)."""

from __future__ import annotations

from typing import Any

import numpy as np

from host.camera.source import StereoSource
from host.errors import HostError

SIM_DEPTHS_M = (0.9, 1.3, 1.8, 2.4, 3.0)  # where the simulated robot stands in its frames
SETTLE_FRAMES = 10  # a live camera's first frames, while its exposure settles


def spread_pairs(source: StereoSource, count: int, live: bool
                 ) -> list[tuple[np.ndarray, np.ndarray]]:
    """count pairs: from a recording, evenly spread over all of it; from a live camera, after
    SETTLE_FRAMES, every fifth frame."""
    if live:
        frames = []
        for i, f in enumerate(source):
            if i >= SETTLE_FRAMES and (i - SETTLE_FRAMES) % 5 == 0:
                frames.append((f.left, f.right))
            if len(frames) == count:
                break
    else:
        every = [(f.left, f.right) for f in source]
        picks: Any = np.unique(np.linspace(0, len(every) - 1, count).round().astype(int)) \
            if every else []
        frames = [every[i] for i in picks]
    if not frames:
        raise HostError("the camera gave no frames to tune on")
    return frames


def sim_pairs(width: int, height: int, count: int
              ) -> tuple[list[tuple[np.ndarray, np.ndarray]], float]:
    """Frames of the simulated world with the robot at several depths, and its focal_px *
    baseline_m (for a depth range)."""
    from host.sim.renderer import Renderer
    from host.sim.world import World

    world = World.for_size(width, height)
    renderer = Renderer(world)
    pairs = []
    for i in range(count):
        world.robot.z_m = SIM_DEPTHS_M[i % len(SIM_DEPTHS_M)]
        frame = renderer.frame()
        pairs.append((frame.left, frame.right))
    return pairs, world.geometry.focal_px * world.geometry.baseline_m
