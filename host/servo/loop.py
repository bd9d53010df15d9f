"""The servo loop: frames in, disparity, target and marker, control law, command out.

    reference phase: several frames of the scene without the robot -> the nearest object's
                     disparity is the target (TargetTracker keeps it true during the run)
    acquisition:     find the marker (spinning in place if it is not in view), measure its
                     disparity noise standing, and learn by a short probe move which way the
                     robot faces (Acquisition); a tolerance below the depth noise at the target
                     is widened to it, and the servo says so (notes)
    robot phase:     each frame -> marker candidates -> the first the Estimator's gate admits
                     (where the robot can be, given its commands) and block matching over it
                     confirms -> depth (m) -> Controller -> SET_DRIVE or STOP over the link;
                     the Estimator also checks that the depth moves the way the robot is driven
    every remeasure_s the target is measured again outside the robot's own image region (on a
    whole map matched a band of rows per frame, StripMap); a depth older than target_age_s (a
    turn, a search, a wait skip them) is measured again, the robot standing, before it drives.

Each piece is a state machine of its own (FrameTiming, Estimator, Acquisition, TargetTracker,
Controller, Recovery, Progress); step() composes them, and each step has one Phase (phase.py).
Time comes from the frames' capture timestamps. Any exception leaves through the link's context
manager, which sends STOP.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np

from host.camera.geometry import Geometry
from host.camera.source import CameraError, StereoFrame, StereoSource
from host.errors import HostError
from host.link.client import RobotLink, RobotReset
from host.servo.acquire import NOT_MOVED, AcquireConfig, Acquisition
from host.servo.align import aligned_disparity
from host.servo.clearance import (
    Heading,
    depth_noise_m,
    facing_shown,
    in_the_way,
    motion_heading,
    run_fault,
    unshown_duties,
)
from host.servo.controller import (
    DRIFTED,
    INTO_FIXED,
    LINE_BLOCKED,
    PUSHED,
    TURN_BLOCKED,
    Command,
    ControlConfig,
    Controller,
    Observation,
)
from host.servo.deflicker import deflickered
from host.servo.estimator import AGAINST, OUTSIDE, STILL, Estimator, EstimatorConfig, Sighting
from host.servo.inputs import FrozenSensors, camera_moved, floor_shift_px, views_agree
from host.servo.marker import RING_RATIO, MarkerPair, block_disparity, cut_views, marker_candidates
from host.servo.perception import (
    BIAS_LIMIT_PX,
    ColumnBias,
    Floor,
    StripMap,
    Target,
    bias_shrunk,
    camera_height,
    corrected_right,
    fit_floor,
    fixed_cells,
    fixed_in_path,
    floor_column_bias,
    in_view,
    lane_obstacle,
    lane_window,
    lens_shaped,
    match_exposure,
    match_window,
    median_map,
    nearest_object,
    object_extent,
    reference_target,
    stopping_distance_m,
    without_floor,
)
from host.servo.phase import Phase
from host.servo.progress import Progress, ProgressConfig
from host.servo.recovery import (
    BESIDE,
    DONE,
    GIVE_UP,
    LANE,
    LOST,
    MOVED,
    RESET,
    RESUME,
    TARGET,
    BackOff,
    BackOffConfig,
    Recovery,
    away_by_heading,
    lane_steer,
    servo_bounds,
    settled_on,
)
from host.servo.recovery import OUTSIDE as OUTSIDE_KIND
from host.servo.refind import FOUND, WHOLE, LostCard, Refind, RefindConfig
from host.servo.rereference import (
    RereferenceLimits,
    fill_hidden,
    floor_follows_picture,
    nearest_agreeing,
    other_depth,
    refit_floor,
    rereference_fault,
    target_shift_rows,
)
from host.servo.rig import reference_image, vertical_shift_px
from host.servo.robot_model import REACT_S, WHEELBASE_M
from host.servo.snapshot import Observer, Snapshot, link_stats
from host.servo.timing import FrameTiming, TimingConfig
from host.servo.tracker import TargetTracker, TrackerConfig, with_replaced, with_target
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams

AGAINST_REASON = "the depth moves against the commanded direction"
STILL_REASON = "the marker did not move while the robot drove"
MAX_FLIPS = 2  # heading corrections in a run before "against" ends it
REREFERENCE_TRIES = 3  # re-references (of reference_frames each) before a moved camera stops
BACK_OFF_S = 15.0  # a back-off (recovery.BackOff) needs this long before the run's deadline:
# its ~0.3 m at ~8 cm/s, the re-acquisition (a measure, maybe a turn), the approach and a
# hold; later the stop stands as named (seed 13 trial 175 backed off at 32 s of 45 and
# was still looking for its card at the limit: "did not settle")
LATE_S = 0.5  # a wait still on this near the run's deadline ends the run, named (a few frames
# before the run driver's own check)


def marker_band(params: MatcherParams, d: float) -> MatcherParams:
    """The matcher's search range around a marker's disparity d (16 px wide): what the servo
    matches over the marker when it does not match the whole map."""
    return params.replace(min_disparity=max(0, int(d) - 8), num_disparities=16)


def marker_disparity(left: np.ndarray, right: np.ndarray, params: MatcherParams,
                     pair: MarkerPair, whole: bool = False
                     ) -> tuple[float, np.ndarray, tuple[int, int]]:
    """Block-matching disparity over the marker, in its band of disparities (marker_band):
    matched on only the window the ring's matches need (or, whole, on the whole map). Returns
    the disparity (px, NaN: none), the map of the rows matched (full width, NaN outside the
    window) and those rows (y0, y1)."""
    band_params = marker_band(params, pair.disparity)
    if whole:
        disp = compute_disparity(left, right, band_params)
        return block_disparity(disp, pair.left), disp, (0, left.shape[0])
    # only the window the ring's matches need: its rows, its columns and, to their left,
    # the search range in the right view
    r = pair.left.radius
    pad = 1.6 * r + params.block_size
    h, w = left.shape[:2]
    y0, y1 = max(0, int(pair.left.v - pad)), min(h, int(pair.left.v + pad) + 1)
    reach = band_params.min_disparity + band_params.num_disparities
    x0, x1 = max(0, int(pair.left.u - pad) - reach), min(w, int(pair.left.u + pad) + 1)
    band = compute_disparity(left[y0:y1, x0:x1], right[y0:y1, x0:x1], band_params)
    shifted = type(pair.left)(pair.left.u - x0, pair.left.v - y0, r, pair.left.aspect)
    full = np.full((y1 - y0, w), np.nan, np.float32)
    full[:, x0:x1] = band
    return block_disparity(band, shifted), full, (y0, y1)


@dataclass(frozen=True)
class ServoConfig:
    marker_kind: str = "disc"  # or "aruco"
    marker_radius_m: float | None = 0.03  # the disc's radius on the card; None: unknown
    reference_frames: int = 5
    min_area: int | None = None  # px; None: 1% of the image
    full_map: bool = False  # cross-check the marker on the whole map (tests)
    max_mismatch_px: float = 1.5  # block matching against the marker's centres
    cut_mismatch_px: float = 0.35  # the same where the two views' discs differ (cut_views)
    remeasure_s: float = 1.0
    target_age_s: float = 2.0  # the target's depth older than this (no re-measure: a turn, a
    # search skip them; driving, one comes every remeasure_s plus a map's frames) is measured
    # again before the robot drives on it (TargetTracker.aged), re-measures back to back
    remeasure_stand_s: float = 4.0  # standing this long for it without one: the run ends
    robot_half_width_m: float = 0.12  # the image region left out of the re-measure
    robot_below_marker_m: float = 0.22
    lane_margin_m: float = 0.05  # watched beyond the stopping distance
    lane_stop_s: float = 3.0  # an object in the lane this long ends the run (recover=False)
    recover: bool = True  # wait out and recover from what passes (host/servo/recovery.py)
    rereference: bool = True  # and re-reference after the camera moved (checked against
    # the old reference moved by the picture's shift: rereference.py)
    moved_rows: float = 0.005  # of the focal length (0.3 degrees of pitch): the camera moved
    camera_height_m: float = 0.25  # only where the reference shows no floor (a note says so):
    # otherwise measured by the floor fit (perception.camera_height)
    acquire_tries: int = 3  # look-alikes that do not move, left out one after the other
    lane_width_px: int = 320  # the lane is watched on frames scaled down to about this width
    ring_ratio: float = RING_RATIO  # the marker's light ring, in disc radii (as printed)
    react_s: float = REACT_S  # a command's reaction and the wheels' run-down (the view's check)
    wheelbase_m: float = WHEELBASE_M  # the wheels' track: a duty difference bends the path
    # a drive while the heading is unknown (a spin forgot it) is slowed to spun_duty where the
    # body on the controller's facing within spun_spread_deg meets a fixed object's cell within
    # the check's stopping distance and the chord that shows the heading (Servo._slow_unshown)
    spun_duty: int = 300
    spun_spread_deg: float = 40.0
    fixed_check: bool = True  # every motion against every other fixed object, in the plane
    # (Servo._fixed_fault); False: the check before it (a drive's path along the depth axis)
    timing: TimingConfig = field(default_factory=TimingConfig)
    estimator: EstimatorConfig = field(default_factory=EstimatorConfig)
    acquire: AcquireConfig = field(default_factory=AcquireConfig)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    progress: ProgressConfig = field(default_factory=ProgressConfig)
    refind: RefindConfig = field(default_factory=RefindConfig)
    back_off: BackOffConfig = field(default_factory=BackOffConfig)  # recovery.BackOff


@dataclass
class LogRow:
    t: float  # s, capture time of the frame (left sensor)
    phase: Phase
    reason: str  # why the robot is stopped when it is ("" while it moves or holds)
    target_m: float
    depth_m: float  # the marker's depth, NaN when not seen (or not admitted)
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
    marker_pair: MarkerPair | None
    row: LogRow


@dataclass
class _Seen:
    """The marker in one frame, as perception and the gate left it."""

    pair: MarkerPair | None = None  # admitted and confirmed
    disparity: float = math.nan  # px, skew-free
    block: float = math.nan  # px, the cross-check
    disp: np.ndarray | None = None
    rows: tuple[int, int] = (0, 0)
    rejected: str = ""  # why the best candidate was not used


class Servo:
    def __init__(self, source: StereoSource, link: RobotLink, params: MatcherParams,
                 geometry: Geometry, control: ControlConfig = ControlConfig(),
                 config: ServoConfig | None = None,
                 clock: Callable[[], float] = time.monotonic, **overrides: Any) -> None:
        """overrides: fields of ServoConfig (marker_kind=, marker_radius_m=, full_map= ...)."""
        self.cfg = dataclasses.replace(config or ServoConfig(), **overrides)
        self.source, self.link, self.params = source, link, params
        # the controller's look-ahead models this servo's check: its reaction, speed and track
        control = dataclasses.replace(control, check_react_s=self.cfg.react_s,
                                      max_speed_mps=self.cfg.estimator.max_speed_mps,
                                      wheelbase_m=self.cfg.wheelbase_m)
        self.geometry, self.control, self.clock = geometry, control, clock
        self.timing = FrameTiming(self.cfg.timing)
        self.frozen = FrozenSensors()
        self.reference_map: np.ndarray | None = None  # the scene without the robot, px
        self._lane_scale = 1  # the lane's frames are this many times smaller
        self._lane_geometry = geometry
        self._lane_reference: np.ndarray | None = None
        self._reference_image: np.ndarray | None = None
        # the target's latest picture (grey) and the robot's region in it, from the last
        # re-measure that found the camera where it was: what a re-reference looks for
        self._target_picture: tuple[np.ndarray, tuple[int, int, int, int] | None] | None = None
        self.estimator = Estimator(geometry, self.cfg.estimator)
        self.acquisition = Acquisition(self.cfg.acquire)
        self.tracker: TargetTracker | None = None
        self.controller: Controller | None = None
        self.floor: Floor | None = None
        # the disparity the calibration adds by column, measured on the reference's floor
        # (perception.floor_column_bias): every frame's right view is corrected by it
        self.column_bias: ColumnBias | None = None
        self.camera_height_m = self.cfg.camera_height_m  # from the floor fit (reference)
        self.last_pair: MarkerPair | None = None  # the last admitted sighting
        self.rows: list[LogRow] = []
        self.last: Step | None = None
        self.notes: list[str] = []  # what the servo decided and the user should know
        self.stop_reason = ""  # set when the run must end: by the servo itself, or request_stop
        self.mismatches = 0  # candidates block matching refused
        self.cuts = 0  # candidates refused as a disc cut by something nearer (cut_views)
        self.observers: list[Observer] = []  # called with a Snapshot after every frame
        self.requested_stop: str | None = None  # why the user stopped the run (request_stop)
        self.flips = 0  # heading corrections by the motion check
        self._strips: StripMap | None = None  # the re-measure's map, a band per frame
        self._remeasure_t: float | None = None
        self._measured_t: float | None = None  # the target's depth last measured (frame time)
        self._stand_since: float | None = None  # standing for a re-measure since
        self._spin_stand_since: float | None = None  # a spin held for a re-measure since
        self._drift_since: float | None = None  # standing on a rate learnt driven since
        self._cmd = Command(0, 0, Phase.WAIT, None)  # the command in force
        self._statics: list[tuple[float, float, float]] = []  # where non-moving look-alikes
        # stand: (u, v) px in the left image, depth (m)
        self.heading = Heading()  # the robot's heading from its travel (clearance.py)
        self._probe_at: tuple[int, float, float] | None = None  # (acquisition, z, x) at its probe
        # where the robot could be when the marker was seen only outside the gate (z, x, reach
        # in m): the re-acquisition's probe does not drive on a sighting beyond it unshown
        self._outside_zone: tuple[float, float, float] | None = None
        self._still_since: float | None = None  # standing since (the drift check)
        self._pause_why = ""  # the probe's refusal it stands on (Acquisition.pause)
        self._width = 0
        self.recovery = Recovery(servo_bounds(self.cfg.recover, self.cfg.rereference,
                                              self.cfg.lane_stop_s))
        self._reref: list[np.ndarray] = []  # the re-reference's maps so far (robot left out)
        self._reref_fails = 0  # re-references that failed, in this wait
        self._shifted: list[float] = []  # the picture's shift at the re-measures running
        # that found it moved without the floor following (issue 23, seed 17's 604)
        self._reref_found: Target | None = None  # the nearest object the last try found
        self._targets_before: list[Target] = []  # the targets a nearer object replaced
        self.progress = Progress(self.cfg.progress)  # no progress for long: the run ends
        self.refind: Refind | None = None  # the card lost while driving, looked for (refind.py)
        self.lost_card = LostCard(self.cfg.refind)  # the refind's bookkeeping (refind.py)
        self.backoff: BackOff | None = None  # backing off the object's side (recovery.py)
        self.deadline: float | None = None  # on clock(): the run driver ends the run then
        # (servo_run.Rules.limit_s); a wait still on just before it ends it, named (_too_late)

    @property
    def strips(self) -> StripMap | None:
        """The re-measure's map, matched a band per frame (None before the reference)."""
        return self._strips

    @property
    def stale_s(self) -> float:
        return self.cfg.timing.stale_s

    @property
    def target(self) -> Target | None:
        return self.tracker.target if self.tracker else None

    @property
    def target_m(self) -> float:
        assert self.controller is not None
        return self.controller.target_m

    @property
    def tolerance_m(self) -> float:
        assert self.controller is not None
        return self.controller.cfg.tolerance_m

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

    def _unbiased(self, frame: StereoFrame) -> StereoFrame:
        """The pair with the reference's column bias taken out of its right view (as it
        is when none was found)."""
        if self.column_bias is None:
            return frame
        return StereoFrame(frame.left, corrected_right(frame.right, self.column_bias),
                           frame.t_left, frame.t_right)

    # ------------------------------------------------------- the user's stop and the observers

    def request_stop(self, reason: str) -> None:
        """Stop the robot at the next frame (any thread may call this); that step's phase is
        "stop", and the caller's loop ends there."""
        self.requested_stop = self.stop_reason = reason

    def _notify(self, frame: StereoFrame, phase: Phase, reason: str, disp: np.ndarray | None,
                y0: int, pair: MarkerPair | None, row: LogRow | None,
                rtt_ms: float = math.nan) -> None:
        """Hand each observer this step's Snapshot (they return at once: snapshot.py)."""
        if self.observers:
            snap = Snapshot(self.clock(), phase, reason, frame.left, disp, y0, self.target, pair,
                            row, link_stats(self.link, rtt_ms), self.geometry)
            for observer in self.observers:
                observer(snap)

    # ------------------------------------------------------------------ reference phase

    def reference(self) -> Target:
        disps, frames = [], []
        for i in range(self.cfg.reference_frames):
            f = self._exposed(self._frame())
            if i == 0:
                self._reference_image = reference_image(f.left)
            frames.append(f)
            disps.append(compute_disparity(f.left, f.right, self.params))
            self._notify(f, Phase.REFERENCE, "measuring the scene", disps[-1], 0, None, None)
            self.link.stop()  # the robot stands while it waits
        h, w = disps[0].shape
        min_area = self.cfg.min_area or (w * h) // 100
        self._strips = StripMap(self.params, (h, w))
        self._width = w
        target, self.floor = reference_target(disps, min_area)
        bias = floor_column_bias(median_map(disps), self.floor)
        if bias is not None and abs(bias.largest) >= BIAS_LIMIT_PX and lens_shaped(bias):
            # the calibration is off at the picture's edge: the reference again on corrected
            # views, kept only if the floor's leftover measured on them shrank (issue 23)
            self.column_bias = bias
            fixed = [self._unbiased(g) for g in frames]
            fixed_disps = [compute_disparity(g.left, g.right, self.params) for g in fixed]
            fixed_target, fixed_floor = reference_target(fixed_disps, min_area)
            if bias_shrunk(bias, floor_column_bias(median_map(fixed_disps), fixed_floor)):
                self.notes.append(bias.describe())
                disps, f = fixed_disps, fixed[-1]
                target, self.floor = fixed_target, fixed_floor
            else:
                self.column_bias = None
                self.notes.append(f"the floor reads {bias.largest:+.2f} px of column bias, "
                                  "not corrected: the corrected views' leftover did not shrink")
        self._measure_height(self.floor)
        self.reference_map = median_map(disps)
        k = self._lane_scale = max(1, w // self.cfg.lane_width_px)
        g = self.geometry
        self._lane_geometry = Geometry(g.focal_px / k, g.baseline_m, (g.cx + 0.5) / k - 0.5,
                                       (g.cy + 0.5) / k - 0.5)
        self._lane_reference = self._lane_map(self.reference_map)
        self.tracker = TargetTracker(target, min_area, self.cfg.tracker)
        clean = without_floor(self.reference_map, self.floor)
        # the face's two views aligned: the map's median is pixel-locked (align.py)
        self.controller = Controller(self.geometry.depth_m(aligned_disparity(
            f.left, f.right, clean, target.bbox, target.disparity)), self.control)
        self.controller.keep_out = self._extent(object_extent(clean, target))
        self.controller.fixed = fixed_cells(self.reference_map, self.geometry,
                                            camera_height_m=self.camera_height_m,
                                            cell_m=self.control.cell_m)
        return target

    def _measure_height(self, floor: Floor | None) -> None:
        """The camera's height above the floor from the floor fit (the lane's and the fixed
        objects' heights are measured from it), or, with no floor in the picture, the
        configured one, with a note."""
        if floor is None:
            self.notes.append(f"no floor in the reference: the camera's height taken as "
                              f"{self.cfg.camera_height_m:.3f} m")
            self.camera_height_m = self.cfg.camera_height_m
        else:
            self.camera_height_m = camera_height(floor, self.geometry.baseline_m)

    def _lane_map(self, reference: np.ndarray) -> np.ndarray:
        """A reference map at the lane's scale (its disparities scaled with it)."""
        k = self._lane_scale
        h, w = reference.shape
        return reference if k == 1 else cv2.resize(
            reference, (w // k, h // k), interpolation=cv2.INTER_NEAREST) / k

    def _extent(self, target: Target) -> tuple[float, float]:
        """The object's lateral extent (m) at its depth, from its image region; a side cut by
        the image's edge reaches on beyond it."""
        g, d = self.geometry, target.disparity
        bx, _, bw, _ = target.bbox
        x0 = -math.inf if bx <= 0 else g.baseline_m * (bx - g.cx) / d
        x1 = math.inf if bx + bw >= self._width else g.baseline_m * (bx + bw - g.cx) / d
        return x0, x1

    # --------------------------------------------------------------------- perception

    @staticmethod
    def _sighting(t: float, pair: MarkerPair) -> Sighting:
        b = pair.left
        return Sighting(t, pair.disparity, b.u, 2 * b.radius / (1 + min(1.0, b.aspect)))

    def _static(self, pair: MarkerPair, depth: bool = False) -> bool:
        """Whether the pair is where a marker that did not move with the robot was seen; with
        depth, also at its depth, within two of the robot's half widths: the robot's body
        would overlap the look-alike's (so with an estimate too: the estimate kept through a
        loss may have a gate wide enough to reach it, seed 11's trial 907)."""
        body = 2 * self.control.half_width_m
        z = self.geometry.depth_m(pair.disparity) if depth and pair.disparity > 0 else math.inf
        return any(abs(pair.left.u - u) + abs(pair.left.v - v) < 3 * pair.left.radius + 4
                   and (not depth or abs(z - zs) < body) for u, v, zs in self._statics)

    def _see(self, frame: StereoFrame) -> _Seen:
        """The marker: the best candidate the estimator's gate admits and block matching over
        it confirms. Candidates near the last sighting first; all of them refused, the whole
        image is searched (the robot may be elsewhere, and a look-alike near). The rows lit
        unevenly (mains flicker on rolling shutters): searched on the pair with each row's
        light factor taken out (deflicker.py), through the same checks, and on the pair as it
        came only if none is admitted there."""
        flat = None
        if self._reference_image is not None:
            flat = deflickered(frame, self._reference_image)
        seen = self._search(flat) if flat is not None else _Seen()
        if seen.pair is None:
            again = self._search(frame)
            if again.pair is not None or not seen.rejected:
                seen = again
        return seen

    def _search(self, frame: StereoFrame) -> _Seen:
        """_see's search on one version of the pair."""
        seen = _Seen()
        cfg, g = self.cfg, self.geometry
        for whole in (False, True):
            if whole and (self.last_pair is None or not seen.rejected):
                break
            candidates = marker_candidates(frame.left, frame.right, cfg.marker_kind,
                                           cfg.marker_radius_m, g.baseline_m, self.last_pair,
                                           whole=whole)
            checked = 0
            for pair in candidates:
                if self._static(pair, depth=self.estimator.state is not None):
                    continue  # shown not to move with the robot: not its marker
                why = self.estimator.gate(self._sighting(frame.t_left, pair))
                if why:
                    seen.rejected = seen.rejected or why
                    continue
                if checked == 2:
                    break  # at most two cross-checks a frame
                checked += 1
                block, disp, rows = marker_disparity(frame.left, frame.right, self.params,
                                                     pair, whole=cfg.full_map)
                seen.block, seen.disp, seen.rows = block, disp, rows
                if math.isfinite(block) and abs(block - pair.disparity) > cfg.max_mismatch_px:
                    self.mismatches += 1  # two blobs that are not the marker's two views
                    seen.rejected = seen.rejected or "its block matching disagrees"
                    continue
                cut = cut_views(pair)
                if cut and not abs(block - pair.disparity) <= cfg.cut_mismatch_px:
                    # a disc cut by a nearer edge, differently in each view: its centroids
                    # do not give the card's disparity, and block matching does not confirm it
                    self.cuts += 1
                    seen.rejected = seen.rejected or f"{cut}: cut by something nearer"
                    continue
                seen.pair, seen.rejected = pair, ""
                return seen
        return seen

    # ---------------------------------------------------------------------- the target

    def _robot_region(self, pair: MarkerPair, shape: tuple[int, ...]
                      ) -> tuple[int, int, int, int]:
        """Image box (x0, y0, x1, y1) the robot may cover, from its marker."""
        ppm = pair.disparity / self.geometry.baseline_m
        h, w = shape[:2]
        u, v, r = pair.left.u, pair.left.v, pair.left.radius
        half = self.cfg.robot_half_width_m * ppm
        return (max(0, int(u - half)), max(0, int(v - 2 * r)), min(w, int(u + half) + 1),
                min(h, int(v + self.cfg.robot_below_marker_m * ppm) + 1))

    def _remeasure_band(self, frame: StereoFrame, pair: MarkerPair | None) -> None:
        """Every remeasure_s, a band of the re-measure's map each frame, then the map to the
        tracker. The robot is left out of the scene: with its marker unseen this frame, where
        it was last seen (it stops when the marker is lost); never seen, or spinning: skip."""
        assert self._strips is not None and self.controller is not None
        due = self._remeasure_t is None or frame.t_left - self._remeasure_t >= \
            self.cfg.remeasure_s or not self.tracker_confirmed
        if due:
            self._remeasure_t = frame.t_left
        if not (due or self._strips.busy):
            return
        robot_at = pair or self.last_pair
        if self._cmd.phase in (Phase.TURN, Phase.SEARCH, Phase.FIND) or robot_at is None:
            self._strips.reset()
            return
        hide = self._robot_region(robot_at, frame.left.shape)
        whole = self._strips.add(frame.left, frame.right, hide)
        if whole is not None:
            self._remeasure(whole, frame, hide)

    def _remeasure(self, disp: np.ndarray, frame: StereoFrame,
                   hide: tuple[int, int, int, int] | None = None) -> None:
        """The tracker's measure on the whole map disp (the robot's region NaN); first, that
        the camera has not moved since the reference (the floor fit would no longer remove
        the floor, and its rows pass for the object): the floor off its line and the picture
        shifted, the run stops."""
        assert self.tracker is not None and self.controller is not None
        moved = camera_moved(disp, self.floor, reference=self.reference_map)
        if self._reference_image is not None:  # the picture's shift, measured once a frame
            dy = vertical_shift_px(self._reference_image, frame.left)
            limit = self.cfg.moved_rows * self.geometry.focal_px
            if moved and abs(dy) >= limit and self.floor is not None and floor_follows_picture(
                    floor_shift_px(disp, self.floor, reference=self.reference_map), dy,
                    self.floor):  # and the picture itself moved, as far as the floor: an
                # object put down over the floor's rows shifts their disparity too
                self._reref, self._reref_fails, self._reref_found = [], 0, None
                self._recover(frame.t_left, MOVED, f"{moved} (the picture moved {dy:+.1f} rows)")
                return
            if abs(dy) >= limit and self._cmd.phase != Phase.STALE:
                # the picture moved but the floor's rows do not say so (the object covers
                # most of them: seed 17's 604, a box's bottom edge knocked 12.5 rows down over
                # the reference's floor rows read -2.0 px for -3.0): no target from this map (its
                # floor is the old fit's: a floor strip would pass for the object), and the
                # same shift at the next re-measure is a moved camera, not a walker's frame
                self._shifted.append(dy)
                if len(self._shifted) >= 2 and abs(self._shifted[-1] - self._shifted[-2]) <= \
                        RereferenceLimits().horizon_rows:
                    self._shifted = []
                    self._reref, self._reref_fails, self._reref_found = [], 0, None
                    self._recover(frame.t_left, MOVED, (
                        f"the picture moved {dy:+.1f} rows at two re-measures running (the "
                        f"floor's rows, {moved or 'on their fit'}, covered): the camera moved"))
                return
            self._shifted = []
            if abs(dy) < limit:
                # the target's picture while the camera is where it was (a moved camera that
                # the floor did not show yet must not give the picture the knock is measured
                # against)
                self._target_picture = (reference_image(frame.left), hide)
        clean = without_floor(disp, self.floor)
        before = self.tracker.target
        target = self.tracker.update(clean, lambda t: views_agree(
            frame.left, frame.right, t.bbox, t.disparity))
        if self.tracker.measured:
            self._measured_t = frame.t_left
            if not (self.tracker.retargeted or self._targets_before):
                self._lane_follows(clean, target)  # the reference's object only: a box
                # that replaced it is new in the lane, and its wait may see it taken away
        if self.tracker.stop_reason:
            if self._back_to_target(clean, frame):  # a nearer object that came and went
                return
            self.stop_reason = self.tracker.stop_reason
        if self.tracker.retargeted:
            self._targets_before.append(before)
            self.notes.append(f"a nearer object appeared at {target.disparity:.2f} px: "
                              f"retargeting")
            self.controller.keep_out = self._extent(object_extent(clean, target))
            self.controller.kept = with_replaced(  # the replaced one, if it stands: fixed
                self.controller.kept, clean, object_extent(clean, before),
                self._horizon_geometry(), camera_height_m=self.camera_height_m,
                cell_m=self.control.cell_m)
        self.controller.target_m = self.geometry.depth_m(aligned_disparity(
            frame.left, frame.right, clean, target.bbox, target.disparity, hide=hide))
        self.controller.readings_m = tuple(  # a move not yet in the median (seed 16 #507)
            self.geometry.depth_m(d) for d in self.tracker.history)

    def _horizon_geometry(self) -> Geometry:
        """The full-size geometry with its horizon where the lane's is (a re-reference after
        a knock moves it): the fixed objects' cells of a map taken since."""
        return dataclasses.replace(
            self.geometry, cy=(self._lane_geometry.cy + 0.5) * self._lane_scale - 0.5)

    def _lane_follows(self, clean: np.ndarray, target: Target) -> None:
        """The lane's reference with the target where the re-measure found it (tracker's
        with_target): a target that moved is not a new object in the lane."""
        assert self.reference_map is not None and self.controller is not None
        if self.controller.keep_out is None:
            return
        self._lane_reference = self._lane_map(with_target(
            self.reference_map, object_extent(clean, target), self.controller.keep_out,
            self.geometry.baseline_m, self.geometry.cx, self.params.block_size // 2 + 1))

    @property
    def tracker_confirmed(self) -> bool:
        """The target's depth is not an aged one waiting for a re-measure."""
        return self.tracker is None or self.tracker.confirmed

    def _measured_first(self, t: float, cmd: Command, invalid: str) -> tuple[Command, str]:
        """A drive on a target depth older than target_age_s: the robot stands (phase
        "wait") while the re-measure runs back to back, until the tracker has confirmed or
        replaced the depth (TargetTracker.aged); standing remeasure_stand_s without that, the
        run ends, named. The controller learns that it stood (its creep floor must not rise)."""
        assert self.tracker is not None and self.controller is not None
        if self._measured_t is None:
            self._measured_t = t  # the reference has just measured it
        age = t - self._measured_t
        if age > self.cfg.target_age_s:
            self.tracker.aged()
        if self.tracker.confirmed or cmd.is_stop or cmd.phase not in (Phase.DRIVE, Phase.CREEP):
            self._stand_since = None
            return cmd, invalid
        if self._stand_since is None:
            self._stand_since = t
        if t - self._stand_since > self.cfg.remeasure_stand_s:
            self.stop_reason = self.stop_reason or (
                f"the target's depth could not be measured again in "
                f"{self.cfg.remeasure_stand_s:.0f} s standing (last measured {age:.1f} s ago)")
            self.controller.phase = Phase.STOP
            return Command(0, 0, Phase.STOP, cmd.error_m), invalid
        self.controller.phase = Phase.WAIT
        return Command(0, 0, Phase.WAIT, cmd.error_m), invalid or (
            f"re-measuring the target: its depth is {age:.1f} s old")

    # ---------------------------------------------------------------------- the lane

    def _lane_blocked(self, frame: StereoFrame, cmd: Command | None = None,
                      direction: int | None = None) -> str:
        """An object in the lane ahead of the robot within its stopping distance at its speed
        (and lane_margin_m), the way the control law will move it (toward the target's
        depth; direction, +1 away from the camera or -1 toward it: that way instead, a
        back-off's), outside the robot's own image region: why the robot must stop, or "".
        Moving away from the camera, what the robot hides is seen only beside or above it."""
        est, c = self.estimator, self.controller
        if est.state is None or c is None or self.reference_map is None:
            return ""
        z, x = est.state.z, est.state.x
        direction = direction or (1 if z < c.target_m else -1)
        # the faster of the command in force and the one to be sent (standing, the stretch
        # the next drive would need)
        duty = max(abs(c_.left + c_.right) / 2 for c_ in (self._cmd, cmd or self._cmd))
        speed = max(abs(est.state.vz), est.cfg.max_speed_mps * duty / 1000)
        reach = stopping_distance_m(speed) + self.cfg.lane_margin_m
        k = self._lane_scale
        g = self._lane_geometry
        left, right = frame.left, frame.right
        if k > 1:  # the lane at 320x240 or so: an obstacle is large, the match costs k^3 less
            size = (left.shape[1] // k, left.shape[0] // k)
            left = cv2.resize(left, size, interpolation=cv2.INTER_AREA)
            right = cv2.resize(right, size, interpolation=cv2.INTER_AREA)
        h, w = left.shape[:2]
        window = lane_window(g, (w, h), z, x, direction, reach,
                             camera_height_m=self.camera_height_m)
        if window is None:
            return ""
        disp = match_window(left, right, self.params, window)
        if self.last_pair is not None:  # the robot's own body (its texture mismatches)
            x0, y0, x1, y1 = self._robot_region(self.last_pair, frame.left.shape)
            disp[y0 // k:-(-y1 // k), x0 // k:-(-x1 // k)] = np.nan
        found = lane_obstacle(disp, g, z, x, direction, reach, self._lane_reference,
                              camera_height_m=self.camera_height_m)
        if found is None:
            return ""
        return f"an object in the lane {found.ahead_m:.2f} m ahead"

    def _measure_before_spin(self, t: float, cmd: Command) -> str:
        """The search spin after a turn refused only
        because the object's depth is older than target_age_s (_spin_fault: it may have
        moved beside the robot unseen, so the spin must clear its extent at any depth): the
        robot stands instead while the re-measure runs (it skips spins: TargetTracker.aged,
        back to back), up to remeasure_stand_s; then the spin is checked on the fresh depth
        (a real sweep into the object still ends the run), or, not measured by then, the
        aged check ends it as before (seed 14: 12 such stops, the robot 0.3-1.8 m behind the
        object's believed depth). Why it stands, or "" (the checks go on as they were)."""
        est, c, tr = self.estimator, self.controller, self.tracker
        spin = not cmd.is_stop and cmd.phase in (Phase.SEARCH, Phase.FIND)  # (FIND's clock
        # runs on while it stands: seed 17 #524 #612, 0.24-1 m off the face's depth, issue 23)
        s = est.state
        if not spin or s is None or c is None or tr is None or self._measured_t is None:
            self._spin_stand_since = None
            return ""
        age = t - self._measured_t
        if age <= self.cfg.target_age_s or not c.sweeps(s.z, s.x, aged=True) \
                or self._fixed_fault(t, cmd):
            self._spin_stand_since = None  # fresh, clear anyway, or refused whatever its depth
            return ""
        if self._spin_stand_since is None:
            self._spin_stand_since = t
        if t - self._spin_stand_since > self.cfg.remeasure_stand_s:
            return ""  # not measured again standing: the aged check ends the run
        tr.aged()
        if cmd.phase == Phase.SEARCH:
            c.phase = Phase.WAIT
        return f"re-measuring the target before the spin: its depth is {age:.1f} s old"

    def _spin_fault(self, t: float, cmd: Command) -> str:
        """Standing or spinning: a spin that sweeps the body into another fixed object, or a
        sideways drift while standing (a push, a slope) that brings it onto one (_fixed_fault);
        where the robot was last known to be beside the object, a spin to find the card (the
        acquisition's, the search after a turn) that sweeps its body into the object
        (controller.sweeps; the turn's own check is the controller's), or, the card unseen,
        the sideways drift it last had bringing it onto the object (controller.closing): why
        the run ends, or ""."""
        est, c = self.estimator, self.controller
        if est.state is None or c is None:
            return ""
        fixed = self._fixed_fault(t, cmd)
        s = est.state
        spin = not cmd.is_stop and (cmd.phase in (Phase.FIND, Phase.SEARCH) or cmd.phase
                                    == Phase.PROBE and cmd.left * cmd.right < 0)  # spin test
        # the object's depth older than target_age_s (no re-measure while spinning): it may
        # have moved beside the robot unseen, so the spin must clear its extent at any depth
        aged = self._measured_t is not None and t - self._measured_t > self.cfg.target_age_s
        if not fixed and spin and aged and c.sweeps(s.z, s.x, aged=True):
            return TURN_BLOCKED
        if fixed or abs(s.z - c.target_m) >= c.cfg.block_m:
            return fixed
        if spin and c.sweeps(s.z, s.x):
            return TURN_BLOCKED
        # unseen for a few frames (seen, the controller's hold watches the drift itself)
        if t - s.t > 0.1 and c.closing(s.x + s.vx * (t - s.t), s.vx, seen=False):
            return DRIFTED
        return ""

    def _drift_stand(self, t: float, cmd: Command, fault: str) -> tuple[Command, str, str]:
        """The card unseen, the sideways rate the robot last had brings the body onto the
        object within unseen_horizon_s (_spin_fault's DRIFTED), but that rate was learnt
        while the robot was driven (Estimator.rate_stood: a drive's curve, a spin's swinging
        card, run on over the stop; seed 17: 5 of its 7 false "drifting unseen" stops, the
        true push the other way or half of it): the robot stands (the controller's drive,
        creep or search spin not sent) until the card shows the rate standing, and the same
        check then decides on that rate (unseen_horizon_s, the card seen or not: the stop it
        would have been, deferred; a rate not yet shown releases nothing). The run ends as
        before, the rate not yet shown standing: every frame of the stand, once the rate it
        has would bring the body, moved on at that rate, within block_margin_m of the object
        within push_horizon_s (the lead the seen hold's check gives a push it has fitted: a
        true push at that rate ends the run before it could touch); for a command that cannot
        wait (a turn round, the acquisition's moves, a back-off) or the estimate dropped; after
        unseen_horizon_s - push_horizon_s of standing (the longest that check lets a rate
        toward the object stand). Seen away from the object's depth, the check is not on and
        the stand ends. fault: this frame's check of the command. The command to send, why it
        stands, and the fault."""
        est, c = self.estimator, self.controller
        s = est.state
        if c is None or s is not None and abs(s.z - c.target_m) >= c.cfg.block_m:
            self._drift_since = None  # seen away from the object's depth: the check is not on
            return cmd, "", fault
        if s is None:  # the estimate dropped (a re-acquisition) before the rate was shown
            self._drift_since = None
            return cmd, "", fault or DRIFTED
        x = s.x + s.vx * max(0.0, t - s.t)
        if est.rate_stood:  # the rate shown standing decides, as the check does
            self._drift_since = None
            return cmd, "", (fault or DRIFTED) if c.closing(x, s.vx, seen=False) else fault
        waits = cmd.is_stop or (self.acquisition.done and self.backoff is None and
                                cmd.phase in (Phase.DRIVE, Phase.CREEP, Phase.SEARCH))
        spent = self._drift_since is not None and \
            t - self._drift_since >= c.cfg.unseen_horizon_s - c.cfg.push_horizon_s
        if not waits or spent or c.closing(x, s.vx, seen=True):  # the stop, as it was
            self._drift_since = None
            return cmd, "", fault or DRIFTED
        if self._drift_since is None:
            self._drift_since = t
        if not cmd.is_stop:
            c.phase = Phase.WAIT
            cmd = Command(0, 0, Phase.WAIT, cmd.error_m)
        return cmd, (f"standing: {DRIFTED} on a rate learnt driven ({s.vx * 100:+.1f} cm/s): "
                     "waiting for the card to show it standing"), ""

    def _fixed_fault(self, t: float, cmd: Command) -> str:
        """Whether the command would take the robot's body into a fixed object of the
        reference that is not the target (controller.obstacles: a body standing where the
        robot is seen, or stood for the reference, is no obstacle), in the floor plane at the
        estimated heading: a drive or a reversed leg within its stopping distance at the
        current speed (its reaction and run-down, and block_margin_m), a probe within the
        move that ends it and its run-down at the current speed, the body a rectangle turned
        by the heading on the arc the wheels' duties make (clearance.run_fault); a spin in
        place within its circle; standing (settled), a drift that closes within
        push_horizon_s (clearance.in_the_way). The heading is the one travelled
        (self.heading, within its spread); not known or too uncertain at the robot's range,
        the controller's facing (clearance.motion_heading), for a drive or a reversed leg the
        other way too until the travel shows that facing (clearance.facing_shown); a sighting
        that puts the body inside a fixed object (a disc on a wall) is no robot's, and its
        probe is not stopped by that object. Why the run ends, or ""."""
        est, c = self.estimator, self.controller
        if est.state is None or c is None or not self.cfg.fixed_check:
            return ""
        s, cfg = est.state, c.cfg
        cells = c.obstacles(s.z, s.x)
        if not len(cells):
            return ""
        if cmd.left * cmd.right < 0:  # a spin in place sweeps the whole circle
            hit = in_the_way(cells, s.z, s.x, None, 0.0,
                             cfg.turn_radius_m + cfg.block_margin_m + cfg.cell_m / 2)
            return "" if hit is None else INTO_FIXED.format("turn")
        speed = math.hypot(s.vz, s.vx)
        if cmd.is_stop:
            if self._still_since is None or t - self._still_since < 1.0 or speed < 0.005:
                return ""  # moving on from the last command (the wheels' run-down), or still
            hit = in_the_way(cells, s.z, s.x, math.atan2(s.vx, s.vz),
                             speed * cfg.push_horizon_s, cfg.half_width_m + cfg.block_margin_m
                             + cfg.cell_m / 2, math.radians(15))
            return "" if hit is None else INTO_FIXED.format("drift while standing")
        duty = abs(cmd.left + cmd.right) / 2
        speed = max(speed, est.cfg.max_speed_mps * duty / 1000)
        # the stop acts within its reaction and run-down; the cells are where the reference
        # put them (not a view's first sight), so block_margin_m, not the lane's margin_m
        travel = stopping_distance_m(speed, margin_m=cfg.block_margin_m)
        h, spread = motion_heading(self.heading, c.facing_away)
        if cmd.phase == Phase.PROBE:  # it ends once moved probe_m: that and its run-down
            travel = self.cfg.acquire.probe_m + speed * self.cfg.react_s + cfg.block_margin_m
            def under(pts: np.ndarray) -> bool:  # a body cannot stand on these cells
                inside = cfg.half_width_m - cfg.cell_m / 2
                return bool((np.hypot(pts[:, 0] - s.z, pts[:, 1] - s.x) < inside).any())
            if under(cells):
                return ""  # a body cannot stand there: a disc on that object, not the robot's
                # card (the probe finds it out, as it does not move)
            # no line check watches a probe beside the object: its face's cells are in the
            # way too, and its heading, not yet travelled, is within the card's turn either
            # way (seed 18 #98: turned 28 degrees after its find spin, 9 cm before the face
            # and 14 cm from its side, the probe's 6 cm ran the body's corner into the side)
            own = c.own()  # (a sighting inside it is a disc on it: not stopped by it)
            if len(own) and not under(own):
                cells = np.concatenate([cells, own])
            if self.heading.value is None:
                spread = max(spread, c.turn_bound())
        back = cmd.left + cmd.right < 0
        body = c.swept_body()
        hit = run_fault(cells, s.z, s.x, cmd.left, cmd.right, h, spread, travel, body,
                        self.cfg.wheelbase_m)
        what = "probe" if cmd.phase == Phase.PROBE else "reversed leg" if back else "drive"
        # the probe, its facing not yet shown, may run either way on either leg: its first
        # leg, if the facing is wrong, goes the other way until its move shows that (seed 13
        # #157 backed 8 cm toward the wall unchecked); its second (far away, the first leg's
        # move within the noise) runs back through the start and as far beyond it. So it is
        # checked the other way too, within its own travel (it is stopped, as here, the frame
        # it comes within that): acquire.py, Acquisition.either_way
        either = cmd.phase == Phase.PROBE and self.acquisition.either_way
        if hit is None and (cmd.phase != Phase.PROBE or either) and not facing_shown(
                self.heading, c.facing_away):
            # facing the other way, it runs on until its travel shows the way (Heading.way),
            # then stops within the same stopping distance
            g = self.geometry
            show = 0.0 if either else self.heading.way_sigmas * depth_noise_m(
                s.z, est.sigma_px, g.focal_px, g.baseline_m)
            hit = run_fault(cells, s.z, s.x, cmd.left, cmd.right, h + math.pi, spread,
                            travel + show, body, self.cfg.wheelbase_m)
            if hit is not None:  # a facing the travel has not shown: it may be the other
                return (f"{INTO_FIXED.format(what)} if it faces the other way (its facing "
                        f"not yet shown by its travel; {hit:.2f} m on)")
        if hit is None:
            return ""
        return f"{INTO_FIXED.format(what)} ({hit:.2f} m on)"

    def _slow_unshown(self, cmd: Command) -> Command:
        """A drive whose heading a spin forgot, slowed to spun_duty near a fixed object
        (clearance.unshown_duties): the check (_fixed_fault) then fires, once the travel
        shows the heading, within the slower run's stopping distance."""
        est, c = self.estimator, self.controller
        s = est.state
        if s is None or c is None or not self.cfg.fixed_check or self.heading.value is not None:
            return cmd
        duty = abs(cmd.left + cmd.right) / 2
        speed = max(math.hypot(s.vz, s.vx), est.cfg.max_speed_mps * duty / 1000)
        g = self.geometry
        left, right = unshown_duties(
            self.heading, c.obstacles(s.z, s.x), s.z, s.x, cmd.left, cmd.right, c.facing_away,
            stopping_distance_m(speed, margin_m=c.cfg.block_margin_m),
            depth_noise_m(s.z, est.sigma_px, g.focal_px, g.baseline_m), c.swept_body(),
            self.cfg.wheelbase_m, math.radians(self.cfg.spun_spread_deg), self.cfg.spun_duty,
            c.floor)
        if (left, right) == (cmd.left, cmd.right):
            return cmd
        return Command(left, right, cmd.phase, cmd.error_m)

    def _path_fault(self, frame: StereoFrame, cmd: Command) -> str:
        """Why the command must not be sent and the run ends, or "": the marker's ring would
        leave the picture before a stop acts (the robot at the picture's edge, or near the
        camera; a probe may go either way), a probe within block_m of the object's depth with
        the body across the object's edge (the drive's LINE_BLOCKED), or, driving toward the
        target, a fixed object of
        the reference stands where the body goes within its stopping distance (the lane
        steers clear of them, this is the backstop)."""
        est, c = self.estimator, self.controller
        if est.state is None or c is None:
            return ""
        z, x = est.state.z, est.state.x
        # the way it goes in depth: a back-off's own (recovery.BackOff.way), not the drive's
        b = self.backoff
        toward = (b.way < 0) if b is not None and b.way is not None else (
            cmd.phase == Phase.PROBE or c.target_m < z)
        pair = self.last_pair
        if pair is not None:
            h, w = frame.left.shape[:2]
            run = abs(est.state.vz) * self.cfg.react_s + 0.02
            scale = z / max(z - run, 0.2) if toward else 1.0
            g = self.geometry
            if not in_view(pair.left.u, pair.left.v, pair.left.radius * self.cfg.ring_ratio,
                           (w, h), scale, g.cx, g.cy):
                return "the marker would leave the view: the robot is at the picture's edge"
        if cmd.phase == Phase.PROBE and abs(z - c.target_m) < c.cfg.block_m \
                and c.overlaps(x, c.cfg.block_margin_m):
            # the drive's rule (controller: within block_m of the object's depth, the body
            # across its edge): the probe, its way in depth not yet known, would close on it
            return LINE_BLOCKED
        if not self.cfg.fixed_check and cmd.phase != Phase.PROBE:  # the check before #23's
            duty = abs(cmd.left + cmd.right) / 2
            speed = max(abs(est.state.vz), est.cfg.max_speed_mps * duty / 1000)
            reach = stopping_distance_m(speed) + self.cfg.lane_margin_m
            cfg = c.cfg
            ahead = fixed_in_path(c.others(), z, x, -1 if c.target_m < z else 1, reach,
                                  cfg.half_width_m + cfg.block_margin_m / 2, cfg.cell_m)
            if ahead is not None:
                return f"a fixed object stands in the robot's path {ahead:.2f} m ahead"
        return self._fixed_fault(frame.t_left, cmd)

    # -------------------------------------------------------------------- acquisition

    def _widen_tolerance(self, sd: float) -> None:
        """Widen a tolerance below the depth noise at the target (sd: px a frame)."""
        assert self.controller is not None
        cfg = self.controller.cfg
        z = self.controller.target_m
        sigma_z = z * z * sd / (self.geometry.focal_px * self.geometry.baseline_m)
        # the controller decides on a line fitted through fit_frames: its end point has about
        # 2 / sqrt(n) of one frame's noise; the band must hold two of those
        floor = 2 * 2 * sigma_z / math.sqrt(cfg.fit_frames)
        if cfg.tolerance_m < floor:
            self.notes.append(f"tolerance {cfg.tolerance_m * 100:.1f} cm is below the depth "
                              f"noise at the target ({sigma_z * 100:.2f} cm a frame at "
                              f"{z:.2f} m): widened to {floor * 100:.1f} cm")
            self.controller.cfg = dataclasses.replace(cfg, tolerance_m=floor)

    def _acquire(self, t: float, position: tuple[float, float] | None, d: float) -> Command:
        """A frame of the acquisition: find, measure, probe."""
        acq = self.acquisition
        before = acq.phase
        noise_m = 0.0
        if position is not None:
            noise_m = self.estimator.sigma_px * position[0] ** 2 / (
                self.geometry.focal_px * self.geometry.baseline_m)
            if acq.phase == Phase.MEASURE:  # probe the way the robot must go if it faces away
                assert self.controller is not None
                acq.direction = 1 if position[0] < self.controller.target_m else -1
        aspect = self.last_pair.left.aspect if position is not None and self.last_pair else None
        order = acq.update(t, position, None if position is None else d, noise_m, aspect)
        far = self._beyond_zone(position) if before == Phase.MEASURE else ""
        if far and acq.phase == Phase.PROBE and not acq.refused(far):
            self.stop_reason = far  # no spin test can show it: the run stops, named
        if acq.fault == NOT_MOVED and self.last_pair is not None \
                and len(self._statics) < self.cfg.acquire_tries - 1:
            # what was taken for the marker did not move with the robot (another robot, a
            # disc on the wall): acquire again, leaving it out
            self._statics.append((self.last_pair.left.u, self.last_pair.left.v,
                                  self.geometry.depth_m(self.last_pair.disparity)))
            left_out = (f"the marker seen at ({self.last_pair.left.u:.0f}, "
                        f"{self.last_pair.left.v:.0f}) px did not move with the robot")
            self.notes.append(f"{left_out}: looking for another")
            self.estimator.forget()
            self.last_pair = None
            # its search failing says so, not "never seen" (seed 13: 8 of the 14 "never
            # seen" had been seen, and left out here): acquire.py, Acquisition.again
            self.acquisition = Acquisition(self.cfg.acquire, again=f"{left_out}, left out")
            return Command(0, 0, Phase.FIND, None)
        if acq.fault:
            self.stop_reason = acq.fault
        if before == Phase.MEASURE and acq.phase != Phase.MEASURE:
            sd = acq.noise_px()
            self.estimator.sigma_px = max(0.05, sd)
            self._widen_tolerance(sd)
        if acq.done:
            self._outside_zone = None  # the sighting went with the robot (or stood the test)
            assert self.controller is not None and acq.facing_away is not None
            self.controller.facing_away = acq.facing_away
            if acq.probes:  # its move showed the facing beyond the depth noise (acquire.py)
                self.heading.way = 1 if acq.facing_away else -1
            if not acq.facing_away and acq.probes:
                self.notes.append("the probe move showed that the robot faces the camera")
        return Command(order.left, order.right, order.phase, None)

    def _outside_gate(self, t: float) -> None:
        """The marker seen only outside the gate too long at t: found again through the gate,
        from scratch (a wait, recovery.py), the probe kept off a sighting still beyond where
        the robot could be (_beyond_zone)."""
        if self._recover(t, OUTSIDE_KIND, f"{OUTSIDE} ({self.estimator.why})"):
            self.recovery.update(t, True)
            zone = self._where_robot_can_be(t)
            self._reacquire(probe=True, why="the marker was seen only outside the gate")
            self._outside_zone = zone

    def _where_robot_can_be(self, t: float) -> tuple[float, float, float] | None:
        """Where the estimate held the robot could be at t (z, x, reach in m: the gate's own,
        its noise with it), or None without an estimate."""
        est = self.estimator
        if est.state is None:
            return None
        z, x = est.predicted(t)
        g = self.geometry
        noise = est.cfg.sigmas * est.sigma_px * z * z / (g.focal_px * g.baseline_m)
        return z, x, est.reach_m(t) + noise

    def _beyond_zone(self, position: tuple[float, float] | None) -> str:
        """Why the probe must not drive on this sighting yet ("" if it may): a re-acquisition
        after the marker was seen only outside the gate, the sighting still beyond where the
        robot could be then (the gate's refusal stands until the card turns with the robot).
        Seed 16's trial 943: a look-alike at 1.40 m, x +0.38, refused by the gate for 0.23 m
        beyond the robot's 0.18 m reach, was measured from scratch and probed; the probe drove
        the unseen robot, turned 230 degrees by a turn spun blind through a frozen sensor,
        11 cm toward it, and the search spin that followed touched it."""
        zone = self._outside_zone
        if zone is None or position is None:
            return ""
        jump = math.hypot(position[0] - zone[0], position[1] - zone[1])
        if jump <= zone[2]:
            return ""
        return (f"the marker found again after it was seen only outside the gate is {jump:.2f} "
                f"m from where the robot could be (within {zone[2]:.2f} m): it is not probed "
                "unless the card turns with the robot")

    # ---------------------------------------------------------------------- the motion

    def _check_motion(self, t: float, admitted: bool) -> None:
        """The depth against the command in force since the last frame: against it, the
        robot faces the other way (the controller turns it round); driven without moving,
        the run stops."""
        assert self.controller is not None
        c = self.controller
        kind = self.estimator.motion(t, self._cmd.left, self._cmd.right, c.facing_away,
                                     admitted)
        if kind == AGAINST:
            self._turn_round("the depth moved against the commanded direction")
        elif kind == STILL:
            self.stop_reason = STILL_REASON

    def _turn_round(self, why: str) -> bool:
        """The depth moved against the commanded direction (why): the robot faces the other way
        (the controller turns it round), or, past MAX_FLIPS such corrections, the run stops
        (False)."""
        assert self.controller is not None
        c = self.controller
        self.flips += 1
        if self.flips > MAX_FLIPS:
            self.stop_reason = AGAINST_REASON
            return False
        c.facing_away = not c.facing_away
        c.history.clear()
        self.notes.append(f"{why}: the robot faces the other way")
        return True

    # ----------------------------------------------------------------------------- step

    def step(self, truth_depth_m: float = math.nan) -> LogRow:
        """One frame of the robot phase: perceive, decide, command, log."""
        assert self.controller is not None and self.tracker is not None
        last = self.rows[-1] if self.rows else None
        frame = self._frame()
        t_wall = time.perf_counter()
        frozen = self.frozen.update(frame)
        frame = self._unbiased(self._exposed(frame))
        t = frame.t_left
        # the command in force up to this frame (a stop's run-down spent before any check)
        self.estimator.commanded(t, self._cmd.left, self._cmd.right)
        invalid = self.timing.check(self.clock(), t, frame.t_right) or frozen
        seen = self._see(frame)
        pair = seen.pair
        position = None
        if pair is not None:
            self.last_pair = pair
            seen.disparity = self.timing.skew_free(t, frame.t_right, pair.disparity,
                                                   pair.right.u)
            sighting = dataclasses.replace(self._sighting(t, pair), disparity=seen.disparity)
            if not invalid:
                self.estimator.accept(sighting)
                position = self.estimator.position(sighting)
        elif seen.rejected:
            self.estimator.reject(t, seen.rejected)
        waiting = self._waiting(frame, pair) if self.recovery.kind in (MOVED, RESET) else ""
        if waiting:  # the robot stands while a recovery is under way (recovery.py)
            cmd = Command(0, 0, Phase.RECOVER, None)
            invalid = invalid or waiting
        else:
            self._remeasure_band(frame, pair)
            if self.estimator.outside_too_long(t) and not self.stop_reason:
                self._outside_gate(t)
            cmd = self._decide(t, pair, position, seen.disparity, invalid)
            cmd, invalid = self._measured_first(t, cmd, invalid)
            cmd, invalid = self._watch_lane(frame, t, cmd, invalid)
        if self._stalled(t, cmd, bool(waiting)):  # STOP now: the run ends with this step
            cmd = Command(0, 0, Phase.STOP, cmd.error_m)
        t_send = time.perf_counter()
        self._send(cmd, t)
        rtt_ms = (time.perf_counter() - t_send) * 1000
        self._cmd = cmd
        self.estimator.commanded(t, cmd.left, cmd.right)
        hz = 1.0 / (t - last.t) if last is not None and t > last.t else math.nan
        reason = self.stop_reason or invalid or (
            ("marker not seen" if not seen.rejected else f"marker refused: {seen.rejected}")
            if cmd.is_stop and pair is None else "")
        depth_m = self.geometry.depth_m(seen.disparity) if position is not None else math.nan
        assert self.target is not None
        row = LogRow(t, cmd.phase, reason, self.target_m, depth_m,
                     math.nan if cmd.error_m is None else cmd.error_m, self.target.disparity,
                     seen.disparity if position is not None else math.nan, seen.block,
                     cmd.left, cmd.right, hz, (time.perf_counter() - t_wall) * 1000,
                     (frame.t_right - t) * 1000, truth_depth_m)
        self.rows.append(row)
        self.last = Step(frame, seen.disp, seen.rows, self.target, pair, row)
        self._notify(frame, cmd.phase, reason, seen.disp, seen.rows[0], pair, row, rtt_ms)
        return row

    def _decide(self, t: float, pair: MarkerPair | None,
                position: tuple[float, float] | None, d: float, invalid: str) -> Command:
        """This frame's command from the acquisition or the controller."""
        assert self.controller is not None
        if self.stop_reason:  # read once: a STOP requested meanwhile acts next frame
            return Command(0, 0, Phase.STOP, None)
        if not self.acquisition.done:
            if invalid:  # the measure or probe begins again after it (acquire.py)
                self.acquisition.interrupted(t)
                return Command(0, 0, Phase.STALE, None)
            cmd = self._acquire(t, position, d)
            return Command(0, 0, Phase.STOP, None) if self.stop_reason else cmd
        self._check_motion(t, position is not None)
        if self._must_stop():  # the motion check may have ended the run
            return Command(0, 0, Phase.STOP, None)
        depth, lateral = position if position is not None else (None, None)
        aspect = pair.left.aspect if pair is not None else 1.0
        if self.backoff is not None:
            # its sightings bound the body's turn for the back-off's gap (controller.reach_m)
            self.controller.saw(depth, lateral, aspect)
            return self._backing_off(t, depth, lateral)
        cmd = self.controller.update(Observation(t, depth, lateral, aspect, invalid))
        if self.controller.fault:  # it cannot go on as it was: back off, or the run ends
            if depth is not None and self._back_off(t, self.controller.fault):
                return Command(0, 0, Phase.RECOVER, None)
            self.stop_reason = self.stop_reason or self.controller.fault
            return cmd
        return self._refind_step(t, None if position is None else aspect,
                                 None if position is None else position[0], cmd)

    def _back_off(self, t: float, fault: str) -> bool:
        """The body near the object's side (the controller's PUSHED or LINE_BLOCKED): a
        wait (kind "beside", recovery.py) in which the target is measured again and the robot
        backs off out of the object's depth (recovery.BackOff), the card seen this frame
        (unseen, the push's drift is a guess and the run ends as before), BACK_OFF_S or
        more before the run's deadline; False when the run ends (no recovery, too late, or
        the fourth time in this run: stop_reason set)."""
        late = self.deadline is not None and self.clock() > self.deadline - BACK_OFF_S
        if not self.cfg.recover or fault not in (PUSHED, LINE_BLOCKED) or late or \
                self.estimator.state is None or not self._recover(t, BESIDE, fault):
            return False
        assert self.tracker is not None and self.controller is not None
        self.tracker.aged()  # measured again (confirmed or replaced) before it moves
        self.backoff = BackOff(self.controller.cfg.block_m, self.cfg.back_off)
        return True

    def _backing_off(self, t: float, depth: float | None, lateral: float | None) -> Command:
        """A frame of the back-off (_back_off): its command; done, the robot re-acquired with
        its heading and estimate kept (the controller anew plans its lane clear of the
        object); no safe way back, or the wait's bound spent, the run ends named."""
        b, c, rec = self.backoff, self.controller, self.recovery
        assert b is not None and c is not None
        if rec.kind != BESIDE:  # another wait took over (a reset, a moved camera): its own
            self.backoff = None  # way back re-acquires the robot
            return Command(0, 0, Phase.RECOVER, None)
        gap, pushed = None, 0.0
        if lateral is not None and c.keep_out is not None:
            x0, x1 = c.keep_out  # the body's clearance across from the object's extent
            gap = max(lateral - x1, x0 - lateral) - c.cfg.half_width_m
            fit = c.drift()  # the push fitted while it stood beside the object, toward its side
            if fit is not None and not x0 <= lateral <= x1:
                toward = -fit[2] if lateral > x1 else fit[2]
                pushed = max(0.0, toward) * c.cfg.push_horizon_s
        steer, lane, st = 0.0, c.lane(depth), self.estimator.state
        if lateral is not None and lane is not None and st is not None and b.way is not None:
            steer = lane_steer(b.way, lateral, lane, st.vx, c.cfg.steer_gain,
                               c.cfg.steer_damping)
        settled = settled_on(lateral, lane, 0.0 if st is None else st.vx, b.cfg)
        left, right = b.update(t, depth, gap, c.target_m, self.tracker_confirmed, c.facing_away,
                               c.trim, pushed, c.floor, steer, settled,
                               c.reach_m() - c.cfg.half_width_m,  # turned as the card shows
                               # its first way: the one its line takes away from the side
                               away_by_heading(self.heading.value, self.heading.spread,
                                               lateral, c.keep_out, b.cfg))
        if b.outcome == DONE:
            rec.update(t, True)
            self.backoff = None
            self._reacquire(probe=False, why=f"{c.fault}: backed off", keep_estimate=True)
            return Command(0, 0, Phase.RECOVER, None)
        if b.outcome:
            rec.give_up(b.outcome)
        elif rec.update(t, False) != GIVE_UP:
            moving = left or right
            return Command(left, right, Phase.DRIVE if moving else Phase.RECOVER, None)
        self.backoff = None
        self.stop_reason = self.stop_reason or rec.fault
        return Command(0, 0, Phase.STOP, None)

    def _refind_step(self, t: float, aspect: float | None, depth: float | None,
                     cmd: Command) -> Command:
        """The card lost while driving (the controller says "lost"): rather than stand until
        the run's limit, the robot spins back against the turn its drive made, until the card
        is square to the camera again, or it is looked for in the whole view through the
        acquisition (refind.py); a wait recovery.py bounds (kind "lost"). aspect, depth: the
        card's this frame, None when no sighting was admitted. Returns the command to send.
        Each loss also checks the heading over the drives since the last
        (LostCard.drove_against): a far robot's depth is too noisy for the motion check within
        one short drive. And a drive that would turn the card farther from square when it is
        already turned (LostCard.keep_in_view) is driven straight instead."""
        c = self.controller
        assert c is not None
        lc = self.lost_card
        lc.update(t, self._cmd, cmd, aspect, depth, c.target_m, c.facing_away)
        rec = self.recovery
        if self.refind is not None and rec.kind != LOST:
            self.refind = None  # another wait took over (the robot stands in it)
        if self.refind is None:
            if not lc.lost_while_driving(t) or not self.cfg.recover or rec.active:
                return lc.keep_in_view(aspect, cmd)  # a card missing a few frames (far,
                # small) is waited for
            reason = "the marker was lost while driving"
            if lc.drove_against() and not self._turn_round(
                    "over the drives before the marker was lost the depth moved against the "
                    "commanded direction"):
                return Command(0, 0, Phase.STOP, None)
            if not self._recover(t, LOST, reason):
                return Command(0, 0, Phase.STOP, None)
            self.refind = Refind(t, lc.turned(), self.cfg.refind)
        left, right = self.refind.update(t, aspect)
        outcome = self.refind.outcome
        if outcome == FOUND:
            rec.update(t, True)
            self.refind = None
            self.notes.append("the card lost while driving was found again")
            return lc.keep_in_view(aspect, cmd)  # the controller's own, on this sighting
        if outcome == WHOLE:
            rec.update(t, True)
            self.refind = None
            self._reacquire(probe=True, why="the marker was lost while driving",
                            keep_estimate=True)
            return Command(0, 0, Phase.FIND, None)
        return Command(left, right, Phase.SEARCH, None)

    def _stalled(self, t: float, cmd: Command, waiting: bool) -> bool:
        """Whether the run ends with this step, for no progress for long (progress.py) or a
        wait still on at the run's deadline (_too_late), named in stop_reason and the notes;
        what the servo did since its last progress is noted when that was the cause (a wait
        at the deadline is its own account)."""
        stalled = self.progress.update(t, cmd.phase, cmd.error_m, self.target_m,
                                       waiting=waiting or self.recovery.active)
        late = "" if stalled else self._too_late()
        if not (stalled or late) or self.stop_reason:
            return False
        self.stop_reason = stalled or late
        self.notes.append(f"{stalled}: {self.progress.detail()}" if stalled else late)
        return True

    def _too_late(self) -> str:
        """A wait (recovery.py) still on LATE_S before the run's deadline: the run ends as the
        stop the wait would have ended in, named, rather than at the deadline neither held nor
        stopped (a wait's bound, up to 20 s, may reach past it: seed 12's trial 482 waited on
        the lane from 28.5 s); "" otherwise."""
        rec = self.recovery
        if self.deadline is None or not rec.active or self.clock() < self.deadline - LATE_S:
            return ""
        return f"{rec.reason}: still waiting ({rec.kind}) when the run's time ran out"

    def _must_stop(self) -> bool:
        return bool(self.stop_reason)

    def _send(self, cmd: Command, t: float = math.nan) -> None:
        """The command over the link. A reset the link learns of (it has said HELLO again,
        re-applied its configuration and sent STOP) is waited out, then re-acquired."""
        try:
            if cmd.is_stop:
                self.link.stop()
            else:
                self.link.drive(cmd.left, cmd.right)
        except RobotReset as e:
            if not self._recover(t, RESET, str(e)):
                raise

    # ------------------------------------------------------------------- recovery hooks

    def _recover(self, t: float, kind: str, reason: str) -> bool:
        """Wait out the condition `kind` (recovery.py); False when the run must end instead
        (stop_reason set)."""
        was = self.recovery.kind
        if self.recovery.begin(t, kind, reason):
            if was != kind:
                self.notes.append(f"{reason}: the robot waits ({kind})")
            return True
        self.stop_reason = self.stop_reason or self.recovery.fault
        return False

    def _waiting(self, frame: StereoFrame, pair: MarkerPair | None) -> str:
        """A frame of a wait that takes over the step (moved, reset): the reason the robot
        stands, or "" when the wait has just ended (the step goes on as usual)."""
        rec, t = self.recovery, frame.t_left
        kind = rec.kind
        # a reset: the link has re-handshaken; STOP answered each frame since
        clear = self._rereference_frame(frame, pair) if kind == MOVED else True
        reason = rec.reason
        verdict = rec.update(t, clear)
        if verdict == RESUME:  # a moved camera moved no robot: its estimate goes on
            self._reacquire(probe=kind == RESET, why=reason, keep_estimate=kind == MOVED)
            return ""
        if rec.fault:  # the wait outlasted its bound: the step decides the stop that ends
            self.stop_reason = self.stop_reason or rec.fault  # the run (its phase "stop")
            return ""
        return f"waiting ({kind}): {reason}"

    def _reacquire(self, probe: bool, why: str, keep_estimate: bool = False) -> None:
        """Back the safe way: the estimator started afresh from sightings it gates (or, with
        keep_estimate, going on: its gate keeps the robot where it stood), the acquisition
        again (with a probe move where the heading may have changed), the controller's state
        anew but for what it learnt of the object and the wheels. An acquisition the wait cut
        short had not yet shown the marker to be the robot's (nor its heading): nothing of it
        is kept, and it starts again with its probe."""
        assert self.controller is not None
        old = self.controller
        proven = self.acquisition.done
        self._outside_zone = None  # the outside-the-gate recovery sets its own after this
        if not (keep_estimate and proven):
            self.estimator.forget()
        self.acquisition = Acquisition(self.cfg.acquire,
                                       facing_away=None if probe or not proven
                                       else old.facing_away,
                                       again=why,
                                       spent_s=0.0 if proven else self.acquisition.driven_s(),
                                       one_way=(0.0, 0) if proven
                                       else self.acquisition.one_way)
        c = Controller(old.target_m, self.control)
        c.cfg, c.keep_out, c.trim, c.facing_away = old.cfg, old.keep_out, old.trim, \
            old.facing_away
        c.fixed, c.kept = old.fixed, old.kept
        c.turns = list(old.turns)  # the body's turn as the card showed it (reach_m)
        c.pushed_mps = old.pushed_mps  # a push measured in this run widens the lane back
        self.controller = c
        self._cmd = Command(0, 0, Phase.WAIT, None)
        # the drives, turns and losses before it belong to a heading the probe sets afresh
        self.lost_card, self.refind = LostCard(self.cfg.refind), None
        self.notes.append(f"recovered ({why}): re-acquiring the robot")

    def _rereference_frame(self, frame: StereoFrame, pair: MarkerPair | None) -> bool:
        """A frame of the re-reference after the camera moved: its whole map with the
        robot's region left out; with reference_frames of them, the floor, reference map and
        target again (True), or not yet / not possible (False: tried again, REREFERENCE_TRIES
        times in all). Only frames where the estimator's gate admitted the marker count: the
        robot's region is left out where it stands now (the picture moved: where it was seen
        before the knock is rows off), and it is the robot the estimator followed (a pitch
        changes neither the marker's disparity nor its column). Unseen (the robot stands in
        the wait: a knock that came in a turn left its card edge-on, and seed 18 #2 waited the
        whole 10 s for a sighting), the region of its last admitted sighting, with that region
        moved by the picture's shift (the sighting may have come before the knock or after)."""
        if self.estimator.state is None:
            return False
        if pair is not None:
            box = self._robot_region(pair, frame.left.shape)
        elif self.last_pair is not None and self._reference_image is not None:
            box = self._robot_region(self.last_pair, frame.left.shape)
            dy = round(vertical_shift_px(self._reference_image, frame.left))
            h = frame.left.shape[0]
            box = (box[0], max(0, min(box[1], box[1] + dy)), box[2],
                   min(h, max(box[3], box[3] + dy)))
        else:
            return False
        disp = compute_disparity(frame.left, frame.right, self.params)
        x0, y0, x1, y1 = box
        disp[y0:y1, x0:x1] = np.nan
        self._reref.append(disp)
        if len(self._reref) < self.cfg.reference_frames:
            return False
        maps, self._reref = self._reref, []
        why = self._rereference(maps, frame, box)
        if why:
            self._reref_fails += 1
            if self._reref_fails >= REREFERENCE_TRIES:
                self.recovery.give_up(f"re-referencing failed: {why}")
            else:
                self.notes.append(f"re-referencing failed: {why}; trying again")
        return not why

    def _rereference(self, maps: list[np.ndarray], frame: StereoFrame,
                     robot: tuple[int, int, int, int]) -> str:
        """The reference again from maps (the robot's region, robot, NaN): "" when done, else
        why not. A pitch moves the whole picture by the rows phase correlation measures and
        changes no depth: the robot's region is filled from the old reference moved by them,
        the floor refitted with its slope, and what is found must be the old reference moved
        by them (rereference.rereference_fault: the floor's horizon, the target's place,
        disparity and two views). Heights above the floor (the lane, the fixed objects) are
        then measured from the moved horizon."""
        assert self.tracker is not None and self.controller is not None
        assert self.reference_map is not None and self._reference_image is not None
        old = self.tracker.target
        dy = vertical_shift_px(self._reference_image, frame.left)
        reference = fill_hidden(median_map(maps), self.reference_map, robot, dy)
        floor = refit_floor(reference, self.floor) if self.floor else fit_floor(reference)
        if floor is None:
            return "no floor in the rows the robot leaves free"
        try:  # a region whose two views disagree (flicker) is no object: passed over
            target, agree = nearest_agreeing(
                without_floor(reference, floor), self.tracker.min_area,
                lambda t: views_agree(frame.left, frame.right, t.bbox, t.disparity))
        except HostError as e:
            self._reref_found = None
            return str(e)
        earlier, self._reref_found = self._reref_found, target  # two tries running: a
        # target moved in depth meanwhile (rereference.target_moved)
        # the target's picture as the last re-measure saw it (the target may have moved since
        # the reference phase, the robot stand in front of it), else the reference's
        picture, hide = self._target_picture or (self._reference_image, None)
        rows = target_shift_rows(picture, frame.left, old.bbox, int(abs(dy)) + 4, hide=hide)
        why = rereference_fault(self.floor, floor, dy, old, target, agree,
                                moved_rows=self.cfg.moved_rows * self.geometry.focal_px,
                                target_rows=rows, last=self.tracker.history[-1],
                                earlier=earlier)
        if why:
            return why
        k, lane = self._lane_scale, self._lane_geometry
        lane = dataclasses.replace(lane, cy=lane.cy + dy / k)  # the horizon moved
        self.floor, self.reference_map, self._lane_geometry = floor, reference, lane
        self._measure_height(floor)  # a knock may have changed it too
        self._reference_image = reference_image(frame.left)
        self._target_picture = (self._reference_image, robot)
        self._lane_reference = self._lane_map(reference)
        moved = other_depth(old, target, self.tracker.history[-1])
        self.tracker = TargetTracker(target, self.tracker.min_area, self.cfg.tracker)
        if moved:  # taken as the target moved in depth (rereference.target_moved): it may be
            # an object in front of it after all, the target kept to go back to when it goes
            self._targets_before.append(old)
        else:
            self._targets_before.clear()
        self.controller.target_m = self.geometry.depth_m(target.disparity)
        self.controller.keep_out = self._extent(
            object_extent(without_floor(reference, floor), target))
        self.controller.fixed = fixed_cells(
            reference, self._horizon_geometry(), camera_height_m=self.camera_height_m,
            cell_m=self.control.cell_m)
        assert self._strips is not None
        self._strips.reset()
        self._remeasure_t = None
        self._measured_t = frame.t_left
        self.notes.append(f"re-referenced after the camera moved {dy:+.1f} rows: target at "
                          f"{target.disparity:.2f} px" + (
                              f" (moved from {old.disparity:.2f} px, found so twice)"
                              if earlier is not None and abs(target.disparity - old.disparity)
                              > 0.5 else ""))
        return ""

    def _back_to_target(self, clean: np.ndarray, frame: StereoFrame) -> bool:
        """The target vanished, and it was a nearer object that had replaced one (a box put
        down in front of the robot and taken away again): back to the object it replaced
        when the map finds it where it was, agreeing in both views (True), else False."""
        assert self.tracker is not None and self.controller is not None
        if not self._targets_before:
            return False
        old = self._targets_before[-1]
        try:
            found = nearest_object(clean, self.tracker.min_area, near=old.disparity)
        except HostError:
            return False
        if abs(found.disparity - old.disparity) > max(1.0, 0.1 * old.disparity) or not \
                views_agree(frame.left, frame.right, found.bbox, found.disparity) >= 0.6:
            return False
        reason = f"{self.tracker.stop_reason}: the nearer object went away"
        if not self._recover(frame.t_left, TARGET, reason):
            return False
        self.recovery.update(frame.t_left, True)
        self._targets_before.pop()
        self.tracker = TargetTracker(found, self.tracker.min_area, self.cfg.tracker)
        self._measured_t = frame.t_left
        self.controller.target_m = self.geometry.depth_m(found.disparity)
        self.controller.keep_out = self._extent(object_extent(clean, found))
        self.notes.append(f"back to the target it replaced, at {found.disparity:.2f} px")
        return True

    def _watch_lane(self, frame: StereoFrame, t: float, cmd: Command, invalid: str
                    ) -> tuple[Command, str]:
        """The lane ahead, every frame the robot is to move: blocked, it stands (phase
        "obstacle") and waits (recovery.py's lane bound) until the lane has been clear a
        while; the controller learns that it stood (its creep floor must not rise)."""
        assert self.controller is not None
        self._track_heading(t, cmd)
        moving = not cmd.is_stop and cmd.phase in (Phase.DRIVE, Phase.CREEP, Phase.PROBE)
        stand = "" if moving else self._measure_before_spin(t, cmd)
        if stand:  # the spin waits, standing, for the object's depth measured again (the
            # standing checks still watch it: a drift onto a fixed object or the object)
            cmd, invalid = Command(0, 0, Phase.WAIT, cmd.error_m), invalid or stand
        if moving and cmd.phase in (Phase.DRIVE, Phase.CREEP) and self.backoff is None:
            cmd = self._slow_unshown(cmd)
        fault = self._path_fault(frame, cmd) if moving else self._spin_fault(frame.t_left, cmd)
        if moving and cmd.left * cmd.right < 0:  # the probe's spin test: a spin, checked as
            fault = fault or self._spin_fault(frame.t_left, cmd)  # one (sweeps, aged depth)
        if fault == DRIFTED or not fault and self._drift_since is not None:
            # on a rate learnt driven, it stands for the card to show the rate standing
            cmd, stand, fault = self._drift_stand(frame.t_left, cmd, fault)
            moving, invalid = moving and not cmd.is_stop, invalid or stand
        if self.acquisition.paused_t is not None:
            stand, fault = self._probe_paused(frame, t, cmd, fault)
            if stand:
                return Command(0, 0, Phase.PROBE, cmd.error_m), invalid or stand
        elif fault.startswith(INTO_FIXED.format("probe")) and self.acquisition.pause(
                t, self._sighting_noise_m()):
            self._pause_why = fault  # it stands, and its move is checked again (acquire.py)
            return Command(0, 0, Phase.PROBE, cmd.error_m), invalid or f"standing: {fault}"
        if fault.startswith(INTO_FIXED.format("probe")) and self.acquisition.refused(fault):
            return Command(0, 0, Phase.PROBE, cmd.error_m), invalid  # a spin test first
        rec, b = self.recovery, self.backoff
        if not fault and moving and b is not None and b.way is not None:
            ahead = self._lane_blocked(frame, cmd, b.way)  # the lane the way it backs off
            if ahead:  # nothing to wait in: the back-off's wait is on (recovery.py)
                rec.give_up(f"no safe way back: {ahead} backing off")
                self.backoff = None
                fault = rec.fault
        if fault:  # nothing to wait for: the run ends here
            self.stop_reason = self.stop_reason or fault
            self.controller.phase = Phase.STOP
            return Command(0, 0, Phase.STOP, cmd.error_m), invalid
        blocked = self._lane_blocked(frame, cmd) if moving and b is None else ""
        if blocked:
            if rec.kind == LANE:
                rec.update(t, False)
                if rec.fault:
                    self.stop_reason = self.stop_reason or rec.fault
            else:
                self._recover(t, LANE, blocked)
        elif rec.kind == LANE:
            if rec.update(t, moving or cmd.phase == Phase.HOLD) == RESUME:
                return cmd, invalid
            if rec.fault:
                self.stop_reason = self.stop_reason or rec.fault
            blocked = f"waiting (lane): {rec.reason}"
        else:
            return cmd, invalid
        if not moving:
            return cmd, invalid or blocked
        self.controller.phase = Phase.OBSTACLE
        return Command(0, 0, Phase.OBSTACLE, cmd.error_m), invalid or blocked

    def _sighting_noise_m(self) -> float:
        """A sighting's depth noise where the robot is estimated (m): the measure's disparity
        noise, at least the acquisition's floor_px (far sightings err together), or 0.0
        without an estimate."""
        s, g = self.estimator.state, self.geometry
        if s is None:
            return 0.0
        sd = max(self.estimator.sigma_px, self.acquisition.cfg.floor_px)
        return depth_noise_m(s.z, sd, g.focal_px, g.baseline_m)

    def _probe_paused(self, frame: StereoFrame, t: float, cmd: Command, fault: str
                      ) -> tuple[str, str]:
        """A frame of the refused probe's stand (Acquisition.pause): once it has stood
        settle_s, its move is checked again, every check a probe frame has (_path_fault, both
        ways while its facing is unshown), at the probe's top duty, on the standing estimate;
        clear: it drives on from the next frame, each frame checked as ever; still refused at
        pause_s: the refusal stands (the spin test, or the run ends, as before). Why it stands
        this frame ("": it does not), and the fault to go on with."""
        acq = self.acquisition
        assert acq.paused_t is not None
        stood = t - acq.paused_t
        if fault or stood < acq.cfg.settle_s:  # a standing check's fault ends the run
            return ("" if fault else f"standing: {self._pause_why}"), fault
        duty = acq.cfg.max_probe_duty * acq.direction
        why = self._path_fault(frame, Command(duty, duty, Phase.PROBE, cmd.error_m))
        if not why:
            acq.resume()  # checked again and clear: it drives on from the next frame
            return f"standing: {self._pause_why}", ""
        if stood < acq.cfg.pause_s:
            return f"standing: {why}", ""
        acq.resume()
        return "", why  # the refusal stands

    def _track_heading(self, t: float, cmd: Command) -> None:
        """The heading from the travel under the command in force; how long the robot has
        stood; where it stood for the reference (controller.home: where the probe of the
        acquisition that found the robot began)."""
        s, c = self.estimator.state, self.controller
        assert c is not None
        if s is not None:
            g = self.geometry
            self.heading.update(t, s.z, s.x, self._cmd.left, self._cmd.right, depth_noise_m(
                s.z, self.estimator.sigma_px, g.focal_px, g.baseline_m))
        if c.turned_half is not None:  # a turn round witnessed half a turn (controller.py)
            self.heading.turned_round(c.turned_half)  # the way shown before it, reversed
        if not self._cmd.is_stop:
            self._still_since = None
        elif self._still_since is None:
            self._still_since = t
        if s is not None and cmd.phase == Phase.PROBE and (
                self._probe_at is None or self._probe_at[0] != id(self.acquisition)):
            self._probe_at = (id(self.acquisition), s.z, s.x)
        if c.home is None and self.acquisition.done and self._probe_at is not None \
                and self._probe_at[0] == id(self.acquisition):
            c.home = self._probe_at[1:]

    def held_for(self, seconds: float) -> bool:
        """Whether the robot has been holding at the target for the last `seconds`."""
        if not self.rows or self.rows[-1].phase != Phase.HOLD:
            return False
        t_end = self.rows[-1].t
        for row in reversed(self.rows):
            if row.phase != Phase.HOLD:
                return False
            if t_end - row.t >= seconds:
                return True
        return False

    def outcome(self) -> tuple[str, str]:
        """How the run ended, from its log (run_outcome)."""
        return run_outcome(self.rows)


def run_outcome(rows: list[LogRow]) -> tuple[str, str]:
    """("held", "") when a run's last step held at the target with the marker in view, else
    ("stopped", the reason)."""
    if not rows:
        return "stopped", "no frame"
    last = rows[-1]
    if last.phase == Phase.HOLD and math.isfinite(last.depth_m):
        return "held", ""
    if not any(math.isfinite(r.robot_px) for r in rows):
        return "stopped", "the marker was never seen"
    return "stopped", last.reason or f"ended in phase {last.phase}"
