"""A recorded ROS 2 bag (MCAP) as a stereo source: its left and right sensor_msgs/Image pairs
with their header stamps (seconds since the first pair), and the calibration its
sensor_msgs/CameraInfo holds; at the recorded pace (or speed times it, 0 = as fast as it can
be read), on a clock of its own.

The file is read from the start in the order it was written, so a recording whose run was
killed (no summary, a chunk cut off) replays up to its last complete chunk and says so.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from host.camera.source import CameraError, StereoFrame, StereoSource

if TYPE_CHECKING:
    from host.camera.calib_files import Calibration

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
PREFETCH = 200  # messages read at open to find both CameraInfos


def _side(topic: str) -> str | None:
    name = topic.lower()
    return "left" if "left" in name else "right" if "right" in name else None


class BagSource(StereoSource):
    """Pairs of a bag: the k-th left image with the k-th right one (topics of type
    sensor_msgs/Image naming left and right). calibration: from the first CameraInfo of each
    side (None if the bag has none)."""

    def __init__(self, path: Path, speed: float = 1.0) -> None:
        try:
            from mcap.reader import NonSeekingReader
            from rosbags.typesys import Stores, get_typestore
        except ImportError as e:
            raise CameraError(f"replay of a .mcap needs pip install 'stereo-servo[record]' "
                              f"({e.name} is missing)") from None
        if not path.is_file():
            raise CameraError(f"{path}: no such recording")
        self.path, self.speed = path, speed
        self._store = get_typestore(Stores.ROS2_HUMBLE)
        self._file = path.open("rb")
        try:
            self._reader = NonSeekingReader(self._file)
            self._messages = self._reader.iter_messages(log_time_order=False)
        except Exception as e:  # noqa: BLE001 (the mcap library's own errors: one line)
            self._file.close()
            raise CameraError(f"{path}: not an MCAP recording ({type(e).__name__})") from None
        self.truncated = False  # the file ends in the middle of a record (a killed run)
        self.frames = 0
        self.topics: dict[str, str] = {}  # side -> image topic
        self._pending: deque[tuple[str, Any]] = deque()  # read ahead at open
        self._images: dict[str, deque[Any]] = {"left": deque(), "right": deque()}
        self._infos: dict[str | None, Any] = {}
        self._ns0: int | None = None  # the first pair's left stamp (ns)
        self._t0: tuple[float, float] | None = None  # (first frame's stamp, wall time then)
        self._last: tuple[float, float] | None = None  # (last frame's stamp, wall time then)
        self.calibration = self._prefetch()

    # ------------------------------------------------------------------ reading

    def _next(self) -> tuple[str, Any] | None:
        """(topic, decoded message) of the next image or CameraInfo, None at the end."""
        return self._pending.popleft() if self._pending else self._read_message()

    def _read_message(self) -> tuple[str, Any] | None:
        from mcap.exceptions import InvalidMagic, McapError

        while True:
            try:
                schema, channel, message = next(self._messages)
            except StopIteration:
                return None
            except InvalidMagic:
                raise CameraError(f"{self.path}: not an MCAP file") from None
            except (McapError, EOFError, ValueError):
                self.truncated = True  # cut off: what was read is all there is
                return None
            if schema is None or schema.name not in (IMAGE, CAMERA_INFO):
                continue
            if _side(channel.topic) is None:
                continue
            if schema.name == CAMERA_INFO and _side(channel.topic) in self._infos:
                continue  # the calibration is the first one; later ones are not decoded
            try:
                return channel.topic, self._store.deserialize_cdr(message.data, schema.name)
            except Exception as e:  # noqa: BLE001
                raise CameraError(f"{self.path}: a {schema.name} on {channel.topic} does not "
                                  f"decode ({type(e).__name__})") from None

    def _prefetch(self) -> Calibration | None:
        """Read until both CameraInfos are known (or PREFETCH messages): the calibration."""
        for _ in range(PREFETCH):
            item = self._read_message()
            if item is None:
                break
            self._pending.append(item)
            topic, msg = item
            if msg.__msgtype__ == CAMERA_INFO:
                self._infos.setdefault(_side(topic), msg)
            if len(self._infos) == 2:
                break
        if len(self._infos) < 2:
            return None
        from host.camera.calib_files import from_camera_info
        from host.record.messages import info_fields

        left, right = (info_fields(self._infos[s]) for s in ("left", "right"))
        size = (left["width"], left["height"])
        if size != (right["width"], right["height"]):
            raise CameraError(f"{self.path}: the left and right CameraInfo differ in size")
        return from_camera_info(size, left, right, f"{self.path}: the right CameraInfo")

    def _pair(self) -> tuple[Any, Any] | None:
        while not (self._images["left"] and self._images["right"]):
            item = self._next()
            if item is None:
                return None
            topic, msg = item
            if msg.__msgtype__ != IMAGE:
                continue
            side = _side(topic)
            assert side is not None
            known = self.topics.setdefault(side, topic)
            if known == topic:
                self._images[side].append(msg)
        return self._images["left"].popleft(), self._images["right"].popleft()

    def _read(self) -> StereoFrame | None:
        from host.record.messages import decode_image

        pair = self._pair()
        if pair is None:
            if not self.frames:
                raise CameraError(f"{self.path}: no left and right sensor_msgs/Image pairs"
                                  + (" (the file is cut off)" if self.truncated else ""))
            return None
        left, right = pair
        ns_left, ns_right = _ns(left.header.stamp), _ns(right.header.stamp)
        if self._ns0 is None:
            self._ns0 = ns_left
        # seconds since the first pair, from whole ns (epoch seconds in a float lose digits)
        t_left, t_right = (ns_left - self._ns0) * 1e-9, (ns_right - self._ns0) * 1e-9
        self._pace(t_left)
        self.frames += 1
        return StereoFrame(decode_image(left), decode_image(right), t_left, t_right)

    def _pace(self, t: float) -> None:
        now = time.monotonic()
        if self._t0 is None:
            self._t0 = (t, now)
        elif self.speed > 0:
            due = self._t0[1] + (t - self._t0[0]) / self.speed
            if due > now:
                time.sleep(due - now)
                now = due
        self._last = (t, now)

    def clock(self) -> float:
        """The recording's time now: the last pair's stamp plus the time since it was read
        (scaled by speed), so a pair is as late to the servo as it was to the recorder."""
        if self._last is None:
            return 0.0
        return self._last[0] + (time.monotonic() - self._last[1]) * (self.speed or 1.0)

    def describe(self) -> dict[str, Any]:
        return {"camera": f"replay:{self.path}", "kind": "bag", "recorded_from": None}

    def ended(self) -> str:
        """How the recording ended, for the run's last line."""
        cut = ("; the file is cut off (the run that recorded it did not close it): replayed "
               "up to its last complete chunk" if self.truncated else "")
        return f"the recording ended after {self.frames} pairs{cut}"

    def close(self) -> None:
        self._file.close()

    def __iter__(self) -> Iterator[StereoFrame]:
        while (frame := self.read()) is not None:
            yield frame


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def is_bag(path: Path) -> bool:
    return path.suffix.lower() == ".mcap"
