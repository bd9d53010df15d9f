"""A recorded simulated run, opened with readers this project did not write: rosbags (its
rosbag2 reader and CDR deserializer) and mcap's reader with mcap-ros2-support's decoder. Every
topic's type and count, the stamps, a decoded image, the disparity and the phases are checked
against what the run itself saw."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")
pytest.importorskip("mcap_ros2")

from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from rosbags.rosbag2 import Reader  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

from host.record.messages import TOPICS  # noqa: E402
from tests.record.conftest import STEPS  # noqa: E402


def _rosbags(path: Path) -> dict[str, list]:
    store = get_typestore(Stores.ROS2_HUMBLE)
    out: dict[str, list] = {}
    with Reader(path) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == TOPICS
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, store.deserialize_cdr(raw, conn.msgtype)))
    return out


def _mcap(path: Path) -> dict[str, list]:
    out: dict[str, list] = {}
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            assert schema.encoding == "ros2msg" and channel.message_encoding == "cdr"
            assert schema.name == TOPICS[channel.topic]
            out.setdefault(channel.topic, []).append((message.log_time, decoded))
    return out


def _ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def _pixels(msg) -> np.ndarray:
    data = np.frombuffer(bytes(msg.data), np.uint8)
    channels = {"bgr8": 3, "mono8": 1}[msg.encoding]
    return data.reshape(msg.height, msg.width, channels).squeeze()


@pytest.mark.parametrize("read", [_rosbags, _mcap], ids=["rosbags", "mcap"])
def test_every_topic_decodes_as_the_run_saw_it(run, read):
    path, rec, seen, _ = run
    topics = read(path)
    pairs = [frame for frame, _ in seen]
    snaps = [snap for _, snap in seen]
    assert len(pairs) == STEPS + 5  # five reference frames, then the steps
    for side in ("left", "right"):
        images = topics[f"/stereo/{side}/image_raw"]
        infos = topics[f"/stereo/{side}/camera_info"]
        assert len(images) == len(infos) == len(pairs)
        assert pairs[0].t_right - pairs[0].t_left == pytest.approx(0.008)
        for (t, msg), (_, info), frame in zip(images, infos, pairs):
            want = rec.ns(getattr(frame, f"t_{side}"))
            assert t == _ns(msg.header.stamp) == _ns(info.header.stamp) == want
        k = np.asarray(infos[0][1].k).reshape(3, 3)
        g = snaps[0].geometry
        assert k[0, 0] == pytest.approx(g.focal_px) and k[0, 2] == pytest.approx(g.cx)
        p = np.asarray(infos[0][1].p).reshape(3, 4)
        assert p[0, 3] == pytest.approx(0 if side == "left" else -g.focal_px * g.baseline_m)
    # a decoded image equals the pair the run read (raw), bit for bit
    for i in (0, len(pairs) // 2, -1):
        for side in ("left", "right"):
            got = _pixels(topics[f"/stereo/{side}/image_raw"][i][1])
            assert np.array_equal(got, getattr(pairs[i], side))
    # one disparity image per map the run computed, with its rows and invalid pixels
    maps = [s for s in snaps if s.disparity is not None]
    disps = topics["/stereo/disparity"]
    assert len(disps) == len(maps) > STEPS // 2
    for (_, msg), snap in zip(disps, maps):
        assert msg.valid_window.y_offset == snap.disparity_y0
        assert msg.valid_window.height == snap.disparity.shape[0]
        assert msg.f == pytest.approx(snap.geometry.focal_px)
        assert msg.t == pytest.approx(snap.geometry.baseline_m)
    _, msg = disps[-1]
    snap = maps[-1]
    img = np.frombuffer(bytes(msg.image.data), np.float32).reshape(msg.image.height,
                                                                    msg.image.width)
    y0, band = snap.disparity_y0, snap.disparity
    rows = img[y0:y0 + band.shape[0], :band.shape[1]]
    valid = np.isfinite(band)
    assert np.array_equal(rows[valid], band[valid])
    assert np.all(rows[~valid] < msg.min_disparity) and np.all(img[:y0] < msg.min_disparity)
    # the phases, stop reasons and commands, step by step
    servo = [next(s for s in d.status if s.name == "servo") for _, d in topics["/diagnostics"]
             if any(s.name == "servo" for s in d.status)]
    assert [s.message for s in servo] == [
        snap.phase + (f": {snap.reason}" if snap.reason else "") for snap in snaps]
    drives = [next(s for s in d.status if s.name == "drive") for _, d in topics["/diagnostics"]
              if any(s.name == "drive" for s in d.status)]
    assert [s.message for s in drives] == [f"{s.row.left} {s.row.right}" for s in snaps
                                           if s.row is not None]
    # the marker where the run saw it, the target at its depth
    markers = [s for s in snaps if s.marker_pair is not None]
    assert len(topics["/servo/marker"]) == len(markers) > 0
    z = topics["/servo/marker"][-1][1].point.z
    assert z == pytest.approx(snap.geometry.depth_m(markers[-1].marker_pair.disparity))
    target = topics["/servo/target"][-1][1].point.z
    assert target == pytest.approx(snaps[-1].geometry.depth_m(snaps[-1].target.disparity))
    assert math.isfinite(target)


def test_the_recorder_says_what_it_dropped(run):
    path, rec, _, _ = run
    final = [d for _, d in _mcap(path)["/diagnostics"]
             if any(s.name == "recorder" for s in d.status)][-1]
    status = next(s for s in final.status if s.name == "recorder")
    values = {v.key: v.value for v in status.values}
    assert status.message == "nothing dropped (final)"
    assert values["frame dropped"] == "0" and int(values["frame queued"]) == STEPS + 5


def test_a_killed_run_leaves_a_file_that_opens_to_its_last_chunk(tmp_path):
    """SIGKILL in the middle of a run: every chunk written before it reads and decodes
    (mcap's streaming reader: the file has no summary, so it is read from the start)."""
    import os
    import signal
    import subprocess
    import sys
    import time

    from mcap.exceptions import EndOfFile
    from mcap.reader import NonSeekingReader

    path = tmp_path / "killed.mcap"
    proc = subprocess.Popen([sys.executable, "-m", "host", "servo", "--sim", "--settle", "0",
                             "--duration", "60", "--record", str(path)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while (not path.exists() or path.stat().st_size < 12 << 20) and \
                time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert proc.poll() is None, "the run ended before it was killed"
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.kill()
        proc.wait()
    images, ended = 0, False
    with path.open("rb") as f:
        reader = NonSeekingReader(f, decoder_factories=[DecoderFactory()])
        try:
            for _, channel, _, msg in reader.iter_decoded_messages(log_time_order=False):
                if channel.topic == "/stereo/left/image_raw":
                    assert (msg.width, msg.height, msg.encoding) == (320, 240, "mono8")
                    assert len(msg.data) == msg.step * msg.height
                    images += 1
        except EndOfFile:
            ended = True  # the chunk being filled when the run was killed
    assert images >= 12  # three chunks of 4 MB hold at least this many pairs
    assert ended  # cut off where the run was killed, not closed
    # readers that need the summary refuse it; host bag --repair makes a closed copy they open
    with pytest.raises(Exception):  # noqa: B017 (rosbags' own error: the end magic is missing)
        Reader(path).open()
    fixed = tmp_path / "fixed.mcap"
    r = subprocess.run([sys.executable, "-m", "host", "bag", str(path), "--repair", str(fixed)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "the file is cut off" in r.stdout
    topics = _rosbags(fixed)
    assert len(topics["/stereo/left/image_raw"]) == images
    assert not (tmp_path / "fixed.mcap.part").exists()


def test_a_recorder_that_falls_behind_drops_counts_and_says_so(tmp_path):
    """The loop never waits: with the queue full, items are dropped, counted, and the file's
    diagnostics say how many."""
    import threading

    from host.record import messages as m
    from host.record.writer import Recorder

    gate = threading.Event()
    rec = Recorder(tmp_path / "slow.mcap", queue_items=2)
    img = np.zeros((4, 4), np.uint8)

    def build(i=0):
        gate.wait(10)  # the worker is stuck on the first item meanwhile
        return [("/stereo/left/image_raw", m.image(img, 1000 + i, m.LEFT_FRAME), 1000 + i)]

    for i in range(10):
        rec.put("frame", lambda i=i: build(i))  # returns at once, full queue or not
    gate.set()
    rec.close()
    assert sum(rec.dropped.values()) == 10 - rec.queued["frame"] > 0
    topics = _mcap(tmp_path / "slow.mcap")
    assert len(topics["/stereo/left/image_raw"]) == rec.queued["frame"]
    final = topics["/diagnostics"][-1][1].status[0]
    values = {v.key: v.value for v in final.values}
    assert final.level == m.WARN and final.message.startswith(f"{rec.dropped['frame']} items")
    assert values["frame dropped"] == str(rec.dropped["frame"])
