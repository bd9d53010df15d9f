"""One simulated servo run: the world with its faults, the renderer, the firmware's core as the
robot on an in-process line (or a board running the real AVR binary on a pty, in real time), the
link and the servo, all on one simulated clock."""

from __future__ import annotations

import contextlib
import functools
import random
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from host.emulator.emulator import Emulator
from host.emulator.lockstep import LockstepLine
from host.link.client import SERVO_DRIVE_BUDGET_S, RobotLink
from host.servo.controller import ControlConfig
from host.servo.loop import Servo
from host.servo_run import Rules, run_servo
from host.sim.chessboard import calibrate_camera
from host.sim.faults import CameraFaults, WorldFaults
from host.sim.rectify import SimRectifier
from host.sim.renderer import Renderer
from host.sim.source import SimSource
from host.sim.world import Box, World
from host.stereo.params import MatcherParams


@dataclass(frozen=True)
class Setup:
    size: tuple[int, int] = (320, 240)
    start_z_m: float = 1.9
    start_x_m: float = 0.0
    start_theta: float = 0.0
    boxes: tuple[Box, ...] | None = None  # None: the default scene
    faults: WorldFaults = field(default_factory=WorldFaults)
    seed: int = 0
    fps: float = 30.0
    params: MatcherParams = MatcherParams(block_size=9, num_disparities=48, border="clip")
    control: ControlConfig = ControlConfig()
    retries: int = 8
    reply_timeout_s: float = 0.1  # the link's default; on the simulated clock
    board: Any = None  # a running Board (simavr ELF, simulated Uno) instead of the native core
    calib_seed: int | None = None  # seed of the chessboard calibration (None: seed)


@dataclass
class SimRun:
    world: World
    emulator: Any  # the board: the native Emulator, or one running the AVR binary
    source: SimSource
    servo: Servo
    link: RobotLink
    depths: list[float] = field(default_factory=list)

    def step(self) -> None:
        self.servo.step(self.world.robot.z_m)
        self.depths.append(self.world.robot.z_m)

    def run(self, seconds: float, settle: float | None = 1.0) -> None:
        """Steps until `seconds` of simulated time, the servo stops itself, or it has held
        for `settle` seconds (host.servo_run's rules)."""
        if self.source.t >= seconds or self.servo.stop_reason:
            return
        run_servo(self.servo, Rules(settle_s=settle or 0.0, duration_s=seconds - self.source.t),
                  self.source.clock, lambda: self.world.robot.z_m,
                  each=lambda row: self.depths.append(self.world.robot.z_m))

    def depth_error_m(self) -> float:
        """The robot's true depth minus its target object's true depth (m)."""
        return self.world.robot.z_m - self.world.nearest_box().z_m


@contextlib.contextmanager
def simulation(setup: Setup = Setup(), reference: bool = True) -> Iterator[SimRun]:
    kw: dict[str, Any] = {} if setup.boxes is None else {"boxes": setup.boxes}
    faults = setup.faults
    world = World.for_size(*setup.size, seed=setup.seed, motor_faults=faults.motor, **kw)
    r = world.robot
    r.z_m, r.x_m, r.theta = setup.start_z_m, setup.start_x_m, setup.start_theta
    # a servo that matches in grey (the trials) gets grey images from the colour camera: it
    # would turn each view grey itself, several times a frame, after rectifying three channels
    renderer = Renderer(world, faults.camera, seed=setup.seed, grey=not setup.params.colour)
    # the native core: bytes at line rate on the simulated clock; or a board running the AVR
    # binary in real time on a pty (its advance() waits on the wall clock)
    emulator: Any = Emulator(faults.link) if setup.board is None else setup.board
    source = SimSource(world, emulator, setup.fps, renderer=renderer, events=faults.events,
                       latency_ms=faults.motor.latency_ms, seed=setup.seed)
    port: Any = setup.board.path if setup.board else LockstepLine(
        emulator, source.run_ms, lambda: source.now_ms, source.run_until_tx)
    reply_timeout_s = max(0.2, setup.reply_timeout_s) if setup.board else setup.reply_timeout_s
    with RobotLink(port, retries=setup.retries, reply_timeout_s=reply_timeout_s,
                   drive_budget_s=max(SERVO_DRIVE_BUDGET_S, 2 * reply_timeout_s),
                   rng=random.Random(setup.seed)) as link:
        geometry = world.geometry
        key = calibration_key(setup)
        if key is not None:  # rectify as a user would: with a calibration
            calib = _calibration(*key)
            source.rectify = SimRectifier(calib, source)  # the Rectifier's images
            geometry = calib.geometry
        servo = Servo(source, link, setup.params, geometry, setup.control, clock=source.clock)
        run = SimRun(world, emulator, source, servo, link)
        if reference:
            servo.reference()
        yield run


CalibKey = tuple[tuple[int, int], tuple[float, float], int]  # size, lenses, seed


def calibration_key(setup: Setup) -> CalibKey | None:
    """The camera calibration a run needs (_calibration's arguments), or None: lenses without
    distortion are used as they are."""
    distortion = setup.faults.camera.distortion
    if not any(distortion):
        return None
    return setup.size, distortion, setup.seed if setup.calib_seed is None else setup.calib_seed


@functools.lru_cache(maxsize=32)
def _calibrate(size: tuple[int, int], distortion: tuple[float, float], seed: int) -> Any:
    return calibrate_camera(World.for_size(*size), CameraFaults(distortion=distortion), seed)


_given: dict[CalibKey, Any] = {}  # calibrations computed elsewhere (keep_calibration)


def _calibration(size: tuple[int, int], distortion: tuple[float, float], seed: int) -> Any:
    """The simulated camera's chessboard calibration, which depends on its size, lenses and
    seed alone: computed once a process for each (trials share a few cameras), unless another
    process computed it and keep_calibration gave it here (a campaign's workers)."""
    given = _given.get((size, distortion, seed))
    return given if given is not None else _calibrate(size, distortion, seed)


def keep_calibration(key: CalibKey, calib: Any) -> None:
    """Use calib, the calibration _calibration(*key) computed in another process (on one
    thread, as a trial's process does: the same result), instead of computing it here."""
    if len(_given) >= 32:
        _given.clear()
    _given[key] = calib

