"""The servo loop: frames in, disparity, target and marker, control law, command out.

    reference phase: several frames of the scene without the robot -> the nearest object's
                     disparity is the target
    noise phase:     the robot stands while noise_frames frames measure the marker's disparity
                     noise; a tolerance below the depth noise this gives at the target is widened
                     to it, and the servo says so (notes)
    robot phase:     each frame -> the marker's disparity, cross-checked by block matching over
                     the marker with the search range set around it (min-disp / num-disp follow
                     the marker, so near range is not cut off) -> depth (m) -> Controller ->
                     SET_DRIVE or STOP over the link
    every remeasure_s the target is measured again outside the robot's own image region (on a
    whole map matched a band of rows per frame, StripMap): it follows the object when it moves,
    retargets when a nearer object appears, and the run stops ("target vanished") when nothing is
    left where it was.

Time comes from the frames' capture timestamps: a frame whose capture follows the previous one by
more than stale_s, or that arrives stale_s later than frames usually do, is stale; a pair whose
two captures differ by more than max_skew_s is unusable, and a smaller skew is corrected with the
marker's measured image speed. Any exception leaves through the link's context manager, which
sends STOP.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from host.camera.calibration import Geometry
from host.camera.source import CameraError, StereoFrame, StereoSource
from host.errors import HostError
from host.servo.controller import Command, ControlConfig, Controller, Observation
from host.servo.marker import MarkerPair, block_disparity, find_marker
from host.servo.perception import (
    Floor,
    StripMap,
    Target,
    match_exposure,
    nearest_object,
    reference_target,
    without_floor,
)
from host.servo.snapshot import Observer, Snapshot, link_stats
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams


@dataclass
class LogRow:
    t: float  # s, capture time of the frame (left sensor)
    phase: str
    reason: str  # why the robot is stopped when it is ("" while it moves or holds)
    target_m: float
    depth_m: float  # the marker's depth, NaN when not seen
    error_m: float
    target_px: float
    robot_px: float  # NaN when the marker was not seen
    block_px: float  # block-matching disparity over the marker (cross-check), NaN if none
    left: int
    right: int
    loop_hz: float
    latency_ms: float  # frame arrival to command acknowledged, wall time
    skew_ms: float  # right capture minus left capture
    truth_depth_m: float = math.nan  # simulation only


@dataclass
class Step:
    """Everything one step saw and decided: for logs, plots and live views."""

    frame: StereoFrame  # the rectified pair
    disparity: np.ndarray | None  # the disparity computed this step (band or map), if any
    disparity_rows: tuple[int, int]  # the rows of the frame that disparity covers
    target: Target
    marker: MarkerPair | None
    row: LogRow


class Servo:
    def __init__(self, source: StereoSource, link, params: MatcherParams, geometry: Geometry,
                 control: ControlConfig = ControlConfig(), marker: str = "disc",
                 reference_frames: int = 5, min_area: int | None = None, stale_s: float = 0.3,
                 clock: Callable[[], float] = time.monotonic, full_map: bool = False,
                 max_mismatch_px: float = 1.5, marker_radius_m: float | None = 0.03,
                 max_skew_s: float = 0.045, remeasure_s: float = 1.0, noise_frames: int = 8,
                 robot_half_width_m: float = 0.12, robot_below_marker_m: float = 0.22) -> None:
        self.source, self.link, self.params = source, link, params
        self.geometry, self.control, self.marker = geometry, control, marker
        self.reference_frames, self.stale_s, self.clock = reference_frames, stale_s, clock
        self.min_area = min_area
        self.full_map = full_map
        self.max_mismatch_px = max_mismatch_px
        self.marker_radius_m = marker_radius_m  # the disc's radius on the card; None: unknown
        self.max_skew_s, self.remeasure_s, self.noise_frames = max_skew_s, remeasure_s, noise_frames
        self.robot_half_width_m, self.robot_below_marker_m = robot_half_width_m, \
            robot_below_marker_m
        self.last_pair: MarkerPair | None = None
        self.target: Target | None = None
        self.floor: Floor | None = None
        self.controller: Controller | None = None
        self.rows: list[LogRow] = []
        self.last: Step | None = None
        self.notes: list[str] = []  # what the servo decided and the user should know
        self.stop_reason = ""  # set when the run must end: by the servo itself, or request_stop
        self.mismatches = 0
        self.observers: list[Observer] = []  # called with a Snapshot after every frame
        self.requested_stop: str | None = None  # why the user stopped the run (request_stop)
        self._noise: list[float] = []
        self._measuring = noise_frames > 1
        self._target_history: list[float] = []
        self._remeasure_t: float | None = None
        self._strips: StripMap | None = None  # the re-measure's map, a band per frame
        self._doubt = (0, "")  # consecutive re-measures that disagree, and how
        self._prev: tuple[float, float, float] | None = None  # t_right, right u, skew-free d
        self._latency_floor: float | None = None
        self._last_capture: float | None = None
        self._width = 0

    def _frame(self) -> StereoFrame:
        frame = self.source.read()
        if frame is None:
            raise CameraError("the camera ended")
        return frame

    @staticmethod
    def _exposed(frame: StereoFrame) -> StereoFrame:
        """The pair with the right view brought to the left's exposure."""
        return StereoFrame(frame.left, match_exposure(frame.left, frame.right), frame.t_left,
                           frame.t_right)

    # ------------------------------------------------------------------ reference phase

    def request_stop(self, reason: str) -> None:
        """Stop the robot at the next frame (any thread may call this); that step's phase is
        "stop", and the caller's loop ends there."""
        self.requested_stop = self.stop_reason = reason

    def _notify(self, frame: StereoFrame, phase: str, reason: str, disp, y0: int,
                pair: MarkerPair | None, row, rtt_ms: float = math.nan) -> None:
        if self.observers:
            snap = Snapshot(self.clock(), phase, reason, frame.left, disp, y0, self.target, pair,
                            row, link_stats(self.link, rtt_ms), self.geometry)
            for observer in self.observers:
                observer(snap)

    def reference(self) -> Target:
        disps = []
        for _ in range(self.reference_frames):
            f = self._exposed(self._frame())
            disps.append(compute_disparity(f.left, f.right, self.params))
            self._notify(f, "reference", "measuring the scene", disps[-1], 0, None, None)
            self.link.stop()  # keeps the link alive while the robot waits
        h, w = disps[0].shape
        self.min_area = self.min_area or (w * h) // 100
        self._strips = StripMap(self.params, (h, w))
        self.target, self.floor = reference_target(disps, self.min_area)
        self._target_history = [self.target.disparity] * 2
        self.controller = Controller(self.geometry.depth_m(self.target.disparity), self.control)
        self._width = w
        self.controller.keep_out = self._extent(self.target)
        return self.target

    def _extent(self, target: Target) -> tuple[float, float]:
        """The object's lateral extent (m) at its depth, from its image region; a side cut by
        the image's edge reaches on beyond it."""
        g, d = self.geometry, target.disparity
        bx, _, bw, _ = target.bbox
        x0 = -math.inf if bx <= 0 else g.baseline_m * (bx - g.cx) / d
        x1 = math.inf if bx + bw >= self._width else g.baseline_m * (bx + bw - g.cx) / d
        return x0, x1

    @property
    def target_m(self) -> float:
        assert self.controller is not None
        return self.controller.target_m

    # --------------------------------------------------------------------- perception

    def _band_params(self, d: float) -> MatcherParams:
        """The matcher's search range around the marker's disparity d (16 px wide)."""
        return self.params.replace(min_disparity=max(0, int(d) - 8), num_disparities=16)

    def _robot_disparity(self, frame: StereoFrame, pair: MarkerPair
                         ) -> tuple[float, np.ndarray, tuple[int, int]]:
        """Block-matching disparity over the marker (a band of rows, or the whole map)."""
        params = self._band_params(pair.disparity)
        if self.full_map:
            disp = compute_disparity(frame.left, frame.right, params)
            return block_disparity(disp, pair.left), disp, (0, frame.left.shape[0])
        # only the window the ring's matches need: its rows, its columns and, to their left,
        # the search range in the right view
        r = pair.left.radius
        pad = 1.6 * r + self.params.block_size
        h, w = frame.left.shape[:2]
        y0, y1 = max(0, int(pair.left.v - pad)), min(h, int(pair.left.v + pad) + 1)
        reach = params.min_disparity + params.num_disparities
        x0, x1 = max(0, int(pair.left.u - pad) - reach), min(w, int(pair.left.u + pad) + 1)
        band = compute_disparity(frame.left[y0:y1, x0:x1], frame.right[y0:y1, x0:x1], params)
        shifted = type(pair.left)(pair.left.u - x0, pair.left.v - y0, r, pair.left.aspect)
        full = np.full((y1 - y0, w), np.nan, np.float32)
        full[:, x0:x1] = band
        return block_disparity(band, shifted), full, (y0, y1)

    def _timing(self, frame: StereoFrame) -> str:
        """Why the frame is unusable by its capture times ("stale", "skew"), or ""."""
        now = self.clock()
        latency = now - frame.t_left
        if self._latency_floor is None or latency < self._latency_floor:
            self._latency_floor = latency
        gap = frame.t_left - self._last_capture if self._last_capture is not None else 0.0
        self._last_capture = frame.t_left
        if gap > self.stale_s or latency - self._latency_floor > self.stale_s:
            return "stale"
        if abs(frame.t_right - frame.t_left) > self.max_skew_s:
            return "skew"
        return ""

    def _skew_corrected(self, frame: StereoFrame, pair: MarkerPair) -> float:
        """The pair's disparity as if the right sensor had captured with the left: the right
        centre moved back by its measured image speed times the skew."""
        d = pair.disparity
        skew = frame.t_right - frame.t_left
        if self._prev is not None and skew and frame.t_right > self._prev[0]:
            speed = (pair.right.u - self._prev[1]) / (frame.t_right - self._prev[0])
            if frame.t_right - self._prev[0] < 3 * self.stale_s:
                d += speed * skew
        self._prev = (frame.t_right, pair.right.u, d)
        return d

    # ---------------------------------------------------------------------- the target

    def _robot_region(self, pair: MarkerPair, shape: tuple[int, ...]) -> tuple[int, ...]:
        """Image box (x0, y0, x1, y1) the robot may cover, from its marker."""
        ppm = pair.disparity / self.geometry.baseline_m
        h, w = shape[:2]
        u, v, r = pair.left.u, pair.left.v, pair.left.radius
        half = self.robot_half_width_m * ppm
        return (max(0, int(u - half)), max(0, int(v - 2 * r)), min(w, int(u + half) + 1),
                min(h, int(v + self.robot_below_marker_m * ppm) + 1))

    def _remeasure(self, disp: np.ndarray) -> None:
        """Measure the nearest object again on the whole map disp (the robot's region NaN);
        follow it."""
        assert self.target is not None and self.controller is not None
        disp = without_floor(disp, self.floor)
        old = self.target
        bx, by, bw, bh = old.bbox
        there = disp[by:by + bh, bx:bx + bw]
        there = there[np.isfinite(there)]
        if there.size < self.min_area // 4:
            return  # the robot hides the object: nothing to learn
        try:
            found: Target | None = nearest_object(disp, self.min_area, near=old.disparity)
        except HostError:
            found = None
        overlap = found is not None and min(bx + bw, found.bbox[0] + found.bbox[2]) - max(
            bx, found.bbox[0]) > 0.3 * min(bw, found.bbox[2])
        if found is not None and overlap:
            self._doubt = (0, "")
            self._target_history.append(found.disparity)
            median = float(np.median(self._target_history[-3:]))
            self.target = Target(median, found.area, found.bbox, found.spread)
        else:
            # gone means seen through: most of the object's area now shows what lies behind
            # it; a region hidden by something nearer (or masked as the robot) is not gone
            behind = int(np.count_nonzero(there < old.disparity - max(1.0, 0.1 * old.disparity)))
            if behind >= old.area // 2:
                kind = "vanished"
            elif found is not None and found.disparity > old.disparity:
                kind = "appeared"
            else:
                return  # hidden, or nothing clear: nothing to learn
            n = self._doubt[0] + 1 if self._doubt[1] == kind else 1
            self._doubt = (n, kind)
            if n < 2:
                return
            if kind == "vanished":
                self.stop_reason = "target vanished"
                return
            assert found is not None
            self.notes.append(f"a nearer object appeared at {found.disparity:.2f} px: "
                              f"retargeting")
            self.target = found
            self._target_history = [found.disparity] * 2
            self.controller.keep_out = self._extent(found)
        self.controller.target_m = self.geometry.depth_m(self.target.disparity)

    # ---------------------------------------------------------------------- noise phase

    def _noise_phase(self, disparity: float) -> bool:
        """Collect the standing robot's disparities; at the end widen a tolerance below the
        depth noise at the target. True while the phase goes on."""
        self._noise.append(disparity)
        if len(self._noise) < self.noise_frames:
            return True
        assert self.controller is not None
        cfg = self.controller.cfg
        sd = float(np.std(self._noise, ddof=1))
        z = self.controller.target_m
        sigma_z = z * z * sd / (self.geometry.focal_px * self.geometry.baseline_m)
        # the controller decides on a line fitted through fit_frames: its end point has about
        # 2 / sqrt(n) of one frame's noise; the band must hold two of those
        floor = 2 * 2 * sigma_z / math.sqrt(cfg.fit_frames)
        if cfg.tolerance_m < floor:
            self.notes.append(f"tolerance {cfg.tolerance_m * 100:.1f} cm is below the depth "
                              f"noise at the target ({sigma_z * 100:.2f} cm a frame at "
                              f"{z:.2f} m): widened to {floor * 100:.1f} cm")
            self.controller.cfg = cfg.__class__(**{**cfg.__dict__, "tolerance_m": floor})
        return False

    @property
    def tolerance_m(self) -> float:
        assert self.controller is not None
        return self.controller.cfg.tolerance_m

    # ----------------------------------------------------------------------------- step

    def step(self, truth_depth_m: float = math.nan) -> LogRow:
        """One frame of the robot phase: perceive, decide, command, log."""
        assert self.controller is not None and self.target is not None
        assert self._strips is not None
        last = self.rows[-1] if self.rows else None
        frame = self._frame()
        t_wall = time.perf_counter()
        frame = self._exposed(frame)
        invalid = self._timing(frame)
        pair = find_marker(frame.left, frame.right, self.marker, self.marker_radius_m,
                           self.geometry.baseline_m, self.last_pair)
        robot = block = math.nan
        lateral = None
        disp, rows = None, (0, 0)
        if pair is not None:
            block, disp, rows = self._robot_disparity(frame, pair)
            if math.isfinite(block) and abs(block - pair.disparity) > self.max_mismatch_px:
                self.mismatches += 1  # two blobs that are not the marker's two views
                pair = None
            else:
                self.last_pair = pair
                robot = self._skew_corrected(frame, pair)
                lateral = self.geometry.baseline_m * (pair.left.u - self.geometry.cx) / robot
        due = self._remeasure_t is None or frame.t_left - self._remeasure_t >= self.remeasure_s
        if due:
            self._remeasure_t = frame.t_left
        if due or self._strips.busy:  # a band of the re-measure's map each frame, then the map
            # the robot must be left out of the scene: with its marker unseen this frame, the
            # last place it was seen (it stops when the marker is lost); never seen: skip
            robot_at = pair or self.last_pair
            if self.controller.phase == "turn" or robot_at is None:
                self._strips.reset()
            else:
                hide = self._robot_region(robot_at, frame.left.shape)
                whole = self._strips.add(frame.left, frame.right, hide)
                if whole is not None:
                    self._remeasure(whole)
        seen = pair is not None and not invalid
        stop_reason = self.stop_reason  # read once: a STOP requested meanwhile acts next frame
        if stop_reason:
            cmd = Command(0, 0, "stop", None)
        elif seen and self._measuring:
            self._measuring = self._noise_phase(robot)
            cmd = Command(0, 0, "measure", None)
        else:
            depth = self.geometry.depth_m(robot) if seen else None
            aspect = pair.left.aspect if pair is not None else 1.0
            cmd = self.controller.update(Observation(frame.t_left, depth, lateral, aspect,
                                                     invalid))
            if self.controller.fault:  # it cannot go on: the run ends here
                self.stop_reason = stop_reason = self.controller.fault
        t_send = time.perf_counter()
        self._send(cmd)
        rtt_ms = (time.perf_counter() - t_send) * 1000
        hz = (1.0 / (frame.t_left - last.t) if last is not None and frame.t_left > last.t
              else math.nan)
        reason = stop_reason or (invalid if invalid else
                                      "marker not seen" if cmd.is_stop and pair is None else "")
        depth_m = self.geometry.depth_m(robot) if math.isfinite(robot) else math.nan
        row = LogRow(frame.t_left, cmd.phase, reason, self.target_m, depth_m,
                     math.nan if cmd.error_m is None else cmd.error_m, self.target.disparity,
                     robot, block, cmd.left, cmd.right, hz,
                     (time.perf_counter() - t_wall) * 1000,
                     (frame.t_right - frame.t_left) * 1000, truth_depth_m)
        self.rows.append(row)
        self.last = Step(frame, disp, rows, self.target, pair, row)
        self._notify(frame, cmd.phase, reason, disp, rows[0], pair, row, rtt_ms)
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

    def outcome(self) -> tuple[str, str]:
        """("held", "") when the last step held at the target with the marker in view, else
        ("stopped", the reason)."""
        if not self.rows:
            return "stopped", "no frame"
        last = self.rows[-1]
        if last.phase == "hold" and math.isfinite(last.depth_m):
            return "held", ""
        if not any(math.isfinite(r.robot_px) for r in self.rows):
            return "stopped", "the marker was never seen"
        return "stopped", last.reason or f"ended in phase {last.phase}"
