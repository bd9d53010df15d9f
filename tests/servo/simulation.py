"""A closed-loop run of the servo in the simulated world (host.sim.run), for the tests."""

from __future__ import annotations

import contextlib
import dataclasses

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
