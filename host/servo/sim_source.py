"""The simulated camera: renders the world, and moves its robot with the emulator's motor
outputs, both in one deterministic simulated clock."""

from __future__ import annotations

from host.camera.source import StereoFrame, StereoSource
from host.emulator.emulator import Emulator
from host.servo.world import World


class SimSource(StereoSource):
    """Frames at fps; before each frame the world and the emulator advance one frame period in
    1 ms steps, the robot driven by the duties the firmware applies. The first
    reference_frames frames show the scene without the robot (the reference phase)."""

    def __init__(self, world: World, emulator: Emulator, fps: float = 30.0,
                 reference_frames: int = 5) -> None:
        self.world, self.emulator, self.fps = world, emulator, fps
        self.reference_frames = reference_frames
        self.index = 0
        self.t = 0.0

    def _read(self) -> StereoFrame | None:
        if self.index:
            steps = int(round(1000 / self.fps))
            for _ in range(steps):
                left, right = self.emulator.motors()
                self.world.step(0.001, left, right)
                self.emulator.advance(1)
            self.t += steps / 1000
        frame, _ = self.world.render(self.t, with_robot=self.index >= self.reference_frames)
        self.index += 1
        return frame

    def clock(self) -> float:
        return self.t
