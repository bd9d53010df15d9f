"""A closed-loop run of the servo in the simulated world (host.sim.run), and look-alikes of the
marker painted into its frames, for the tests."""

from __future__ import annotations

import contextlib
import dataclasses

import numpy as np

from host.camera.source import StereoFrame
from host.emulator.emulator import Faults
from host.servo.controller import ControlConfig
from host.sim.faults import WorldFaults
from host.sim.run import Setup
from host.sim.run import simulation as sim_run


@contextlib.contextmanager
def simulation(start_depth: float, seed: int = 0, faults: Faults = Faults(),
               mode: str = "turn", retries: int = 8, world: WorldFaults = WorldFaults(),
               size: tuple[int, int] = (320, 240), **setup):
    world_faults = dataclasses.replace(world, link=faults)
    with sim_run(Setup(size, start_depth, faults=world_faults, seed=seed,
                       control=ControlConfig(mode=mode), retries=retries, **setup)) as sim:
        z = sim.servo.target_m
        assert abs(z - sim.world.nearest_box().z_m) < 0.02
        yield sim


def paint_disc(image: np.ndarray, u: float, v: float, radius: float, ring: float = 1.7) -> None:
    """A look-alike of the marker: a dark disc (radius px) in a light ring, in place."""
    h, w = image.shape[:2]
    ys, xs = np.mgrid[0:h, 0:w]
    q = ((xs - u) ** 2 + (ys - v) ** 2) / radius ** 2
    image[q <= ring * ring] = 235
    image[q <= 1] = 25


def with_look_alike(sim, when, du: float, dv: float, disparity: float, radius: float) -> None:
    """From the first frame for which when(sim) holds on, the camera also sees a look-alike
    disc at (du, dv) px from the true marker's place then, at the given disparity (px)."""
    read = sim.source.read
    at: list[tuple[float, float]] = []

    def faked() -> StereoFrame:
        f = read()
        if not at and when(sim):
            u, v, _ = sim.world.marker_truth()
            at.append((u + du, v + dv))
        if not at:
            return f
        left, right = f.left.copy(), f.right.copy()
        paint_disc(left, at[0][0], at[0][1], radius)
        paint_disc(right, at[0][0] - disparity, at[0][1], radius)
        return StereoFrame(left, right, f.t_left, f.t_right)

    sim.source.read = faked
