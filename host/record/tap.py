"""What feeds a recording: a source wrapper that records every pair as captured (before
rectification, with its capture stamps and the CameraInfo that rectifies it), and the servo's
observer that records each step's disparity, marker, target, phase, drive and link health."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from host.camera.calib_files import Calibration, ideal_calibration
from host.camera.geometry import Geometry
from host.camera.source import StereoFrame, StereoSource
from host.camera.wrapper import WrappedSource
from host.link import protocol_gen as gen
from host.record import messages as m
from host.record.writer import Message, Recorder
from host.servo.loop import marker_band
from host.servo.phase import Phase
from host.servo.snapshot import Snapshot

Search = Callable[[Snapshot], tuple[float, float]]  # the disparity range a map was searched in


class RecordingSource(WrappedSource):
    """inner, its pairs recorded as they come (raw), then rectified as inner would have."""

    def __init__(self, inner: StereoSource, recorder: Recorder, geometry: Geometry) -> None:
        super().__init__(inner)
        self.recorder = recorder
        self.rectify, inner.rectify = inner.rectify, None
        self.calibration: Calibration | None = getattr(self.rectify, "calib", None)
        self._geometry = geometry
        self.last: StereoFrame | None = None  # the last pair read, raw

    def _read(self) -> StereoFrame | None:
        frame = self.inner.read()
        if frame is None:
            return None
        self.last = frame
        if self.calibration is None:
            h, w = frame.left.shape[:2]
            self.calibration = ideal_calibration(self._geometry, (w, h))
        calib, rec = self.calibration, self.recorder

        def build() -> list[Message]:
            ns_l, ns_r = rec.ns(frame.t_left), rec.ns(frame.t_right)
            return [("/stereo/left/image_raw", m.image(frame.left, ns_l, m.LEFT_FRAME), ns_l),
                    ("/stereo/left/camera_info", m.camera_info(calib, "left", ns_l), ns_l),
                    ("/stereo/right/image_raw", m.image(frame.right, ns_r, m.RIGHT_FRAME), ns_r),
                    ("/stereo/right/camera_info", m.camera_info(calib, "right", ns_r), ns_r)]

        rec.put("frame", build)
        return frame


def map_range(params: Any) -> Search:
    """The search range of a matcher's whole map."""
    def search(snap: Snapshot) -> tuple[float, float]:
        return float(params.min_disparity), float(params.min_disparity + params.num_disparities)
    return search


def servo_range(servo: Any) -> Search:
    """The servo's: its matcher's on the whole map, the band's round the marker otherwise."""
    whole = map_range(servo.params)

    def search(snap: Snapshot) -> tuple[float, float]:
        if snap.disparity_y0 == 0 and snap.disparity is not None and \
                snap.disparity.shape[0] == snap.left.shape[0] or snap.marker_pair is None:
            return whole(snap)
        p = marker_band(servo.params, snap.marker_pair.disparity)
        return float(p.min_disparity), float(p.min_disparity + p.num_disparities)
    return search


class StepRecorder:
    """Observer (Snapshot): queues each step's messages, stamped with its pair's capture time;
    with a link, asks the robot for its STATUS at most every status_s (one round trip on the
    loop's thread) and records it."""

    def __init__(self, recorder: Recorder, source: RecordingSource, search: Search,
                 link: Any = None, status_s: float = 1.0) -> None:
        self.recorder, self.source, self.search = recorder, source, search
        self.link, self.status_s = link, status_s
        self._status_t = -math.inf

    def __call__(self, snap: Snapshot) -> None:
        frame = self.source.last
        t = frame.t_left if frame is not None else snap.t
        rec = self.recorder
        self.recorder.put("step", lambda: step_messages(snap, rec.ns(t), self.search))
        if self.link is not None and getattr(self.link, "hello", None) is not None \
                and snap.t - self._status_t >= self.status_s:
            self._status_t = snap.t
            reply = self.link.status()
            if isinstance(reply, gen.Status):
                ns = rec.ns(t)
                rec.put("status", lambda: [("/diagnostics", m.diagnostics(
                    ns, [robot_status(reply)]), ns)])


def robot_status(s: Any) -> Any:
    """The robot's STATUS as a DiagnosticStatus: duty, link lost, reset cause, counters."""
    flags = [str(f.name).lower() for f in gen.StatusFlag if s.flags & f]
    try:
        cause = gen.ResetCause(s.reset_cause).name.lower()
    except ValueError:
        cause = f"code {s.reset_cause}"
    lost = bool(s.flags & gen.StatusFlag.LINK_LOST)
    values = {**dataclasses.asdict(s), "flags": " ".join(flags) or "none", "reset_cause": cause}
    return m.status("robot", m.WARN if lost else m.OK,
                    "link lost: motors stopped" if lost else f"duty {s.left} {s.right}", values)


def step_messages(snap: Snapshot, ns: int, search: Search) -> list[Message]:
    """The messages of one step (run on the recorder's worker)."""
    g, out = snap.geometry, []
    if snap.disparity is not None:
        out.append(("/stereo/disparity", m.disparity(snap.disparity, snap.disparity_y0,
                                                     snap.left.shape[:2], g, search(snap), ns),
                    ns))
    pair = snap.marker_pair
    if pair is not None and pair.disparity > 0:
        left = pair.left
        out.append(("/servo/marker", m.point(*m.at_disparity(g, left.u, left.v, pair.disparity),
                                             ns), ns))
        out.append(("/servo/overlay", m.image_marker(ns, 0, "circle", u=left.u, v=left.v,
                                                     radius=left.radius), ns))
    else:
        out.append(("/servo/overlay", m.image_marker(ns, 0, "delete"), ns))
    if snap.target is not None:
        x, y, w, h = snap.target.bbox
        d = snap.target.disparity
        if d > 0:
            out.append(("/servo/target", m.point(*m.at_disparity(g, x + w / 2, y + h / 2, d),
                                                 ns), ns))
        out.append(("/servo/overlay", m.image_marker(ns, 1, "box", x=x, y=y, w=w, h=h), ns))
    out.append(("/diagnostics", m.diagnostics(ns, step_statuses(snap)), ns))
    return out


def step_statuses(snap: Snapshot) -> list[Any]:
    """The servo's phase and stop reason, the drive command, the link's health."""
    row = snap.row
    level = m.WARN if snap.reason else m.OK
    values: dict[str, Any] = {"phase": snap.phase, "reason": snap.reason, "t": snap.t}
    if snap.target is not None:
        values["target_px"] = snap.target.disparity
    out = []
    if row is not None:
        values.update({k: getattr(row, k) for k in (
            "target_m", "depth_m", "error_m", "target_px", "robot_px", "block_px", "loop_hz",
            "latency_ms", "skew_ms", "truth_depth_m")})
        out.append(m.status("drive", m.OK, f"{row.left} {row.right}",
                            {"left": int(row.left), "right": int(row.right)}))
    text = snap.phase + (f": {snap.reason}" if snap.reason else "")
    out.insert(0, m.status("servo", m.ERROR if snap.phase == Phase.STOP else level, text, values))
    if snap.link is not None:
        link = dataclasses.asdict(snap.link)
        bad = snap.link.resets or not np.isfinite(snap.link.rtt_ms)
        out.append(m.status("link", m.WARN if snap.link.resets else m.OK,
                            "reset during the session" if snap.link.resets else
                            ("no command this step" if bad else f"rtt {snap.link.rtt_ms:.1f} ms"),
                            {**link, "schema_hash": f"0x{snap.link.schema_hash:08X}"}))
    return out
