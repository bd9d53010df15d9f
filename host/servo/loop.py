"""The servo loop: frames in, disparity, target and marker, control law, command out.

    reference phase: several frames of the scene without the robot -> the nearest object's
                     disparity is the target
    robot phase:     each frame -> the marker's disparity (cross-checked by block matching over
                     the marker: a pair that disagrees by more than max_mismatch_px is not the
                     marker) -> Controller -> SET_DRIVE or STOP over the link

Any exception leaves through the link's context manager, which sends STOP.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from host.camera.calibration import Geometry
from host.camera.source import CameraError, StereoSource
from host.servo.controller import Command, ControlConfig, Controller, Observation
from host.servo.marker import block_disparity, find_marker
from host.servo.perception import Target, reference_target
from host.servo.snapshot import Observer, Snapshot, link_stats
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams


@dataclass
class LogRow:
    t: float  # s, the loop's clock
    phase: str
    target_px: float
    robot_px: float  # NaN when the marker was not seen
    block_px: float  # block-matching disparity over the marker (cross-check), NaN if none
    error_px: float
    left: int
    right: int
    loop_hz: float
    latency_ms: float  # frame arrival to command acknowledged, wall time
    truth_depth_m: float = math.nan  # simulation only


class Servo:
    def __init__(self, source: StereoSource, link, params: MatcherParams, geometry: Geometry,
                 control: ControlConfig = ControlConfig(), marker: str = "disc",
                 reference_frames: int = 5, min_area: int | None = None, stale_s: float = 0.5,
                 clock: Callable[[], float] = time.monotonic, full_map: bool = False,
                 max_mismatch_px: float = 1.5, marker_radius_m: float | None = 0.03,
                 tolerance_m: float | None = None) -> None:
        self.source, self.link, self.params = source, link, params
        self.geometry, self.control, self.marker = geometry, control, marker
        self.reference_frames, self.stale_s, self.clock = reference_frames, stale_s, clock
        self.min_area = min_area
        self.full_map = full_map
        self.max_mismatch_px = max_mismatch_px
        self.marker_radius_m = marker_radius_m  # the disc's radius on the card; None: unknown
        self.tolerance_m = tolerance_m  # hold band in depth; None: control.tolerance_px as is
        self.last_pair = None
        self._map: tuple = (None, 0)  # the disparity this step computed, and its first row
        self.target: Target | None = None
        self.controller: Controller | None = None
        self.rows: list[LogRow] = []
        self.mismatches = 0
        self.observers: list[Observer] = []  # called with a Snapshot after every frame
        self.stop_reason: str | None = None  # set by request_stop; the robot stays stopped

    def request_stop(self, reason: str) -> None:
        """Stop the robot at the next frame (any thread may call this); that step's phase is
        "stopped", and the caller's loop ends there."""
        self.stop_reason = reason

    def _notify(self, frame, phase: str, reason: str, disp, y0: int, pair, row,
                rtt_ms: float = math.nan) -> None:
        if self.observers:
            snap = Snapshot(self.clock(), phase, reason, frame.left, disp, y0, self.target, pair,
                            row, link_stats(self.link, rtt_ms), self.geometry)
            for observer in self.observers:
                observer(snap)

    def _frame(self):
        frame = self.source.read()
        if frame is None:
            raise CameraError("the camera ended")
        return frame

    def reference(self) -> Target:
        disps = []
        for _ in range(self.reference_frames):
            f = self._frame()
            disps.append(compute_disparity(f.left, f.right, self.params))
            self.link.stop()  # keeps the link alive while the robot waits
            self._notify(f, "reference", "measuring the scene", disps[-1], 0, None, None)
        h, w = disps[0].shape
        self.target, _ = reference_target(disps, self.min_area or (w * h) // 100)
        if self.tolerance_m is not None:
            tol = self.tolerance_m * self.geometry.px_per_m(self.target.disparity)
            self.control = dataclasses.replace(self.control, tolerance_px=tol)
        self.controller = Controller(self.target.disparity, self.control)
        return self.target

    def _robot_disparity(self, frame, pair) -> float:
        """Block-matching disparity over the marker (a band of rows, or the whole map)."""
        if self.full_map:
            self._map = (compute_disparity(frame.left, frame.right, self.params), 0)
            return block_disparity(self._map[0], pair.left)
        r = pair.left.radius
        pad = 2 * r + self.params.block_size
        y0 = max(0, int(pair.left.v - pad))
        y1 = min(frame.left.shape[0], int(pair.left.v + pad) + 1)
        band = compute_disparity(frame.left[y0:y1], frame.right[y0:y1], self.params)
        self._map = (band, y0)
        shifted = type(pair.left)(pair.left.u, pair.left.v - y0, r)
        return block_disparity(band, shifted)

    def step(self, truth_depth_m: float = math.nan) -> LogRow:
        """One frame of the robot phase: perceive, decide, command, log."""
        assert self.controller is not None and self.target is not None
        stop_reason = self.stop_reason  # read once: a STOP pressed meanwhile acts next frame
        last = self.rows[-1].t if self.rows else None
        frame = self._frame()
        t_wall = time.perf_counter()
        now = self.clock()
        pair = find_marker(frame.left, frame.right, self.marker, self.marker_radius_m,
                           self.geometry.baseline_m, self.last_pair)
        self._map = (None, 0)
        robot = block = math.nan
        lateral = None
        if pair is not None:
            block = self._robot_disparity(frame, pair)
            if math.isfinite(block) and abs(block - pair.disparity) > self.max_mismatch_px:
                self.mismatches += 1  # two blobs that are not the marker's two views
                pair = None
            else:
                self.last_pair = pair
                robot = pair.disparity
                lateral = self.geometry.baseline_m * (pair.left.u - self.geometry.cx) / robot
        stale = last is not None and now - last > self.stale_s
        obs = Observation(now, None if (pair is None or stale) else robot, lateral)
        cmd = self.controller.update(obs)
        if stale:
            cmd = Command(0, 0, "stale", cmd.error)
        if stop_reason is not None:
            cmd = Command(0, 0, "stopped", cmd.error)
        t_send = time.perf_counter()
        self._send(cmd)
        rtt_ms = (time.perf_counter() - t_send) * 1000
        hz = 1.0 / (now - last) if last is not None and now > last else math.nan
        row = LogRow(now, cmd.phase, self.target.disparity, robot, block,
                     math.nan if cmd.error is None else cmd.error, cmd.left, cmd.right, hz,
                     (time.perf_counter() - t_wall) * 1000, truth_depth_m)
        self.rows.append(row)
        self._notify(frame, cmd.phase, stop_reason or _why_stopped(cmd), *self._map, pair, row,
                     rtt_ms)
        return row

    def _send(self, cmd: Command) -> None:
        if cmd.is_stop:
            self.link.stop()
        else:
            self.link.drive(cmd.left, cmd.right)

    def held_for(self, seconds: float) -> bool:
        """Whether the robot has been holding at the target for the last `seconds`."""
        if not self.rows or self.rows[-1].phase != "hold":
            return False
        t_end = self.rows[-1].t
        for row in reversed(self.rows):
            if row.phase != "hold":
                return False
            if t_end - row.t >= seconds:
                return True
        return False


def _why_stopped(cmd: Command) -> str:
    """Why a command holds the robot still, in a few words ("" when it may move)."""
    if cmd.phase == "stale":
        return "no frame for too long"
    if cmd.phase == "lost":
        return "marker lost"
    if cmd.phase == "hold":
        return "marker not seen" if cmd.error is None else "at the target"
    return ""
