"""The servo's observer for the page: keeps the latest snapshot (on the loop's thread, at no
cost) and encodes it for the page on a worker thread, only as often as a page asks for it.

A snapshot that a newer one replaces before it was encoded, while a page watches, is dropped
and counted; the loop never waits for the view.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import threading
import time
from collections import deque
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from host.servo.phase import Phase
from host.servo.snapshot import Snapshot
from host.view import render


@dataclass(frozen=True)
class Update:
    """One encoded update for the page: a JSON-able state and the pictures it names."""

    seq: int  # the snapshot's number
    state: dict[str, Any]
    images: tuple[bytes, ...]  # left image with the page's overlays drawn on top; disparity


class ViewFeed:
    """Observer (call it with a Snapshot) and source of Updates for the page's connections.

    history_s: seconds of depth and duty samples kept for the plots; max_fps: most updates a
    second encoded for the pages; quality: JPEG quality of both pictures.
    """

    def __init__(self, history_s: float = 20.0, max_fps: float = 15.0, quality: int = 80,
                 can_stop: bool = True) -> None:
        self.history_s, self.max_fps, self.quality = history_s, max_fps, quality
        self.can_stop = can_stop
        self.snapshots = 0  # received from the loop
        self.encoded = 0
        self.dropped = 0  # replaced unencoded while a page was watching
        self._cond = threading.Condition()
        self._latest: Snapshot | None = None
        self._seq = 0
        self._encoded_seq = 0
        self._full_map: np.ndarray | None = None
        self._range: tuple[float, float] | None = None
        self._watchers = 0  # pages connected
        self._waiting = 0  # pages waiting for an update
        self._update: Update | None = None
        self._times: deque[float] = deque()
        self._samples: deque[tuple[float, float | None, float | None, int | None, int | None]] \
            = deque()
        self._closed = False
        self._worker = threading.Thread(target=self._run, name="view-encoder", daemon=True)
        self._worker.start()

    # ------------------------------------------------------------------ the loop's thread

    def __call__(self, snap: Snapshot) -> None:
        """Take a snapshot: a few assignments and a sample for the plots, nothing more."""
        with self._cond:
            if self._watchers and self._latest is not None and self._seq > self._encoded_seq:
                self.dropped += 1
            self._latest = snap
            self._seq += 1
            self.snapshots += 1
            disp = snap.disparity
            if disp is not None and snap.disparity_y0 == 0 and disp.shape == snap.left.shape[:2]:
                self._full_map = disp
            if snap.row is not None or snap.phase in (Phase.VIEW, Phase.ENDED):
                self._sample(snap)
            self._cond.notify_all()

    def _sample(self, snap: Snapshot) -> None:
        """A plot sample: the servo's row; in view mode (no robot driven) the nearest object's
        and the marker's depth as seen, and no duty."""
        row, g = snap.row, snap.geometry
        if row is not None:
            target_px, robot_px = row.target_px, row.robot_px
            duty: tuple[int | None, int | None] = (int(row.left), int(row.right))
        else:
            target_px = snap.target.disparity if snap.target is not None else math.nan
            robot_px = snap.marker_pair.disparity if snap.marker_pair is not None else math.nan
            duty = (None, None)
        target = g.depth_m(target_px) if target_px > 0 else None  # NaN > 0 is False
        robot = g.depth_m(robot_px) if robot_px > 0 else None
        self._times.append(snap.t)
        self._samples.append((snap.t, target, robot, *duty))
        while self._times and self._times[0] < snap.t - self.history_s:
            self._times.popleft()
            self._samples.popleft()

    # ------------------------------------------------------------------ the pages' side

    def watch(self, on: bool) -> None:
        """A page connects (True) or goes away (False)."""
        with self._cond:
            self._watchers += 1 if on else -1

    def samples_since(self, t: float) -> list[list[Any]]:
        """Plot samples [t, target m, robot m, left duty, right duty] newer than t (s)."""
        with self._cond:
            k = bisect.bisect_right(self._times, t)
            return [list(s) for s in list(self._samples)[k:]]

    def wait_update(self, after: int, timeout_s: float) -> Update | None:
        """The first update newer than seq `after`, or None after timeout_s."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            self._waiting += 1
            self._cond.notify_all()
            try:
                while not self._closed and (self._update is None or self._update.seq <= after):
                    left = deadline - time.monotonic()
                    if left <= 0:
                        return None
                    self._cond.wait(left)
                return self._update if self._update and self._update.seq > after else None
            finally:
                self._waiting -= 1

    def end(self, reason: str) -> None:
        """The run is over: the last picture again, its phase "ended" with reason (the page
        says so while it stays up)."""
        with self._cond:
            snap = self._latest
        if snap is not None:
            self(dataclasses.replace(snap, phase=Phase.ENDED, reason=reason))

    @property
    def latest_seq(self) -> int:
        """The number of the newest snapshot."""
        return self._seq

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        self._worker.join(timeout=2)

    # ------------------------------------------------------------------ the worker thread

    def _run(self) -> None:
        last = 0.0
        while True:
            with self._cond:
                while not self._closed and not (self._waiting and self._seq > self._encoded_seq):
                    self._cond.wait()
                if self._closed:
                    return
            pause = 1.0 / self.max_fps - (time.monotonic() - last)
            if pause > 0:
                time.sleep(pause)  # at most max_fps; newer snapshots replace this one meanwhile
            with self._cond:
                snap, seq, full = self._latest, self._seq, self._full_map
                self._encoded_seq = seq
            last = time.monotonic()
            assert snap is not None
            update = self._encode(snap, seq, full)
            with self._cond:
                self._update = update
                self.encoded += 1
                self._cond.notify_all()

    def _encode(self, snap: Snapshot, seq: int, full: np.ndarray | None) -> Update:
        shape = snap.left.shape[:2]
        disp = render.compose_map(full, snap.disparity, snap.disparity_y0, shape)
        if self._range is None and full is not None:
            self._range = render.disparity_range(full)
        lo, hi = self._range or render.disparity_range(disp)
        images = (render.encode_jpeg(snap.left, self.quality),
                  render.encode_jpeg(render.colour_disparity(disp, lo, hi), self.quality))
        state = {
            "seq": seq, "t": round(snap.t, 3), "phase": snap.phase, "reason": snap.reason,
            "size": [shape[1], shape[0]], "can_stop": self.can_stop,
            "overlay": render.overlay(snap),
            "colour_bar": {"lo": lo, "hi": hi, "stops": render.colour_stops(),
                           "ticks": render.colour_ticks(lo, hi, snap.geometry)},
            "band": None if snap.disparity is None or snap.disparity_y0 == 0 and full is
            snap.disparity else [snap.disparity_y0, snap.disparity.shape[0]],
            "link": None if snap.link is None else _finite(asdict(snap.link)),
            "loop_hz": None if snap.row is None else _finite({"v": snap.row.loop_hz})["v"],
            "history_s": self.history_s,
            "feed": {"snapshots": self.snapshots, "encoded": self.encoded + 1,
                     "dropped": self.dropped},
        }
        return Update(seq, state, images)


def _finite(d: dict[str, Any]) -> dict[str, Any]:
    """NaN and infinity as None (JSON has neither)."""
    return {k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in d.items()}
