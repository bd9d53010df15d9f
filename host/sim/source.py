"""The simulated camera: renders the world and moves its robot with the board's motor outputs,
both in one deterministic simulated clock (lockstep: processing takes no simulated time)."""

from __future__ import annotations

from collections import deque
from typing import Protocol

import numpy as np

from host.camera.source import StereoFrame, StereoSource
from host.sim.faults import Event
from host.sim.renderer import Renderer
from host.sim.world import Box, World


class Board(Protocol):
    """A simulated robot board (native core, simavr ELF, simavr Uno): its clock and motors."""

    def advance(self, ms: float) -> None: ...

    def motors(self) -> tuple[int, int]: ...


class SimSource(StereoSource):
    """Frames at fps; between frames the world and the board advance in 1 ms steps, the robot
    driven by the duties the firmware applies, latency_ms later. The first reference_frames
    frames show the scene without the robot (the reference phase). The right view is captured
    skew_ms after the left; a dropped frame never arrives (the next one comes a period later).
    Captures keep the camera's own schedule: time the host spends waiting on the link (which
    runs the same clock, host.emulator.lockstep) does not shift it, and a capture the host was
    too busy to take is overwritten by the next."""

    def __init__(self, world: World, board: Board, fps: float = 30.0,
                 reference_frames: int = 5, renderer: Renderer | None = None,
                 events: tuple[Event, ...] = (), latency_ms: float = 0.0, seed: int = 0) -> None:
        self.world, self.board, self.fps = world, board, fps
        self.renderer = renderer or Renderer(world, seed=world.seed)
        self.reference_frames = reference_frames
        self.events = sorted(events, key=lambda e: e.t_s)
        self.latency_ms = latency_ms
        self.rng = np.random.default_rng(seed + 104729)
        self.index = 0
        self.now_ms = 0
        self.dropped = 0
        self._due_ms = 0  # the left capture of the frame being read
        self._pending: deque[tuple[int, tuple[int, int]]] = deque()
        self._applied = (0, 0)
        self._occluded_until = -1.0
        self.log: list[str] = []  # what happened in the scene, with times

    @property
    def t(self) -> float:
        return self.now_ms / 1000

    def clock(self) -> float:
        return self.t

    def run_ms(self, ms: int) -> None:
        """Advance the world and the board by ms, one millisecond at a time."""
        for _ in range(ms):
            self._apply_events()
            self._pending.append((self.now_ms + int(round(self.latency_ms)), self.board.motors()))
            while self._pending and self._pending[0][0] <= self.now_ms:
                self._applied = self._pending.popleft()[1]
            self.world.step(0.001, *self._applied)
            self.board.advance(1)
            self.now_ms += 1

    def _apply_events(self) -> None:
        w, r = self.world, self.world.robot
        if r.occlusion and self.t >= self._occluded_until:
            r.occlusion = 0.0
        while self.events and self.events[0].t_s <= self.t:
            e = self.events.pop(0)
            boxes = list(w.boxes)
            if e.kind == "move" and e.index < len(boxes):
                b = boxes[e.index]
                boxes[e.index] = Box(e.z_m, b.x0_m, b.x1_m, b.height_m)
            elif e.kind == "appear" and e.box is not None:
                boxes.append(Box(*e.box))
            elif e.kind == "vanish" and e.index < len(boxes):
                boxes.pop(e.index)
            elif e.kind == "occlude":
                r.occlusion, self._occluded_until = e.fraction, e.t_s + e.duration_s
            w.boxes = tuple(boxes)
            self.log.append(f"{self.t:.3f} s {e.kind}")

    def _read(self) -> StereoFrame | None:
        period = int(round(1000 / self.fps))
        cam = self.renderer.camera
        skew = int(round(cam.skew_ms))
        if self.index:
            self._due_ms += period
            while self._due_ms < self.now_ms:
                self._due_ms += period
            self.run_ms(self._due_ms - self.now_ms)
            while cam.drop and self.rng.random() < cam.drop:
                self.dropped += 1
                self._due_ms += period
                self.run_ms(period)
        else:
            self._due_ms = self.now_ms
        with_robot = self.index >= self.reference_frames
        vel = self.renderer.image_velocity()
        blur = (vel[0] * cam.exposure_ms / 1000, vel[1] * cam.exposure_ms / 1000)
        left, _ = self.renderer.view(0, with_robot, blur)
        t_left = self.t
        self.run_ms(skew)
        vel = self.renderer.image_velocity()
        blur = (vel[0] * cam.exposure_ms / 1000, vel[1] * cam.exposure_ms / 1000)
        right, _ = self.renderer.view(1, with_robot, blur)
        self.index += 1
        return StereoFrame(left, right, t_left, self.t)
