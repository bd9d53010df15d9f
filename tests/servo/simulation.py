"""A closed-loop run of the servo in the simulated world, with the emulator on a pty."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

from host.emulator.emulator import Emulator, Faults, PtyService
from host.link.client import RobotLink
from host.servo.controller import ControlConfig
from host.servo.loop import Servo
from host.sim.source import SimSource
from host.sim.world import World
from host.stereo import MatcherParams

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")


@dataclass
class Sim:
    world: World
    emulator: Emulator
    source: SimSource
    servo: Servo
    depths: list[float]

    def run(self, seconds: float, settle: float | None = 1.0) -> None:
        while self.source.t < seconds:
            self.servo.step(self.world.robot.z_m)
            self.depths.append(self.world.robot.z_m)
            if settle and self.servo.held_for(settle):
                return


@contextlib.contextmanager
def simulation(start_depth: float, seed: int = 0, faults: Faults = Faults(),
               mode: str = "turn", retries: int = 8):
    world = World(seed=seed)
    world.robot.z_m = start_depth
    emulator = Emulator(faults, line_rate=False)
    with PtyService(emulator, realtime=False) as service, \
            RobotLink(service.path, retries=retries, reply_timeout_s=0.05) as link:
        source = SimSource(world, emulator)
        control = ControlConfig(turn_s=world.motors.turn_seconds(ControlConfig.turn_duty),
                                mode=mode)
        servo = Servo(source, link, PARAMS, world.geometry, control, clock=source.clock,
                      tolerance_m=0.01)
        servo.reference()
        z = world.geometry.depth_m(servo.target.disparity)
        assert abs(z - world.nearest_box().z_m) < 0.02
        yield Sim(world, emulator, source, servo, [])
