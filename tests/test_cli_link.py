"""A failed handshake says what arrived: nothing, garbled frames, frames of another spec, or a
robot of another schema hash."""

from __future__ import annotations

import os
import threading
import time
import tty
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.cli import main
from host.emulator.emulator import Emulator, Faults, PtyService
from host.link.client import LinkError, RobotLink
from host.link.frame import encode_frame


class FarEnd:
    """The other end of a pseudo-terminal: the port's path, and a thread that can keep
    writing the same bytes every 10 ms until the test ends."""

    def __init__(self) -> None:
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.port = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def repeat(self, chunk: bytes) -> None:
        def run() -> None:
            while not self._stop.is_set():
                os.write(self.master, chunk)
                time.sleep(0.01)

        self._thread = threading.Thread(target=run, daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread:
            self._thread.join()
        os.close(self.master)
        os.close(self._slave)


@pytest.fixture()
def far_end() -> Iterator[FarEnd]:
    end = FarEnd()
    yield end
    end.close()


def _handshake_error(port: str, seconds: float = 0.4) -> str:
    with pytest.raises(LinkError) as e:
        RobotLink(port, handshake_s=seconds).open()
    return str(e.value)


def test_silence_is_reported_as_nothing(far_end: FarEnd) -> None:
    assert "nothing arrived" in _handshake_error(far_end.port)


def test_noise_is_reported_as_garbled(far_end: FarEnd) -> None:
    far_end.repeat(bytes(range(0, 256, 7)) + b"\xa5\x02\x00")
    msg = _handshake_error(far_end.port)
    assert "only garbled frames arrived" in msg and "baud" in msg


def test_frames_of_another_spec_are_reported(far_end: FarEnd) -> None:
    far_end.repeat(encode_frame(1, 0x7E, b"\x01\x02"))  # an id this spec does not have
    msg = _handshake_error(far_end.port)
    assert "cannot read: a robot built from another protocol spec?" in msg


def test_an_emulator_garbling_every_frame_is_not_called_silent() -> None:
    with PtyService(Emulator(Faults(corrupt=0.5, seed=1))) as service:
        assert "only garbled frames arrived" in _handshake_error(service.path, 0.8)


def test_a_robot_of_another_schema_hash_is_named() -> None:
    with PtyService(Emulator()) as service:
        with pytest.raises(LinkError, match="protocol mismatch: .* spec 0x[0-9A-F]{8}, this "
                                            "host from 0x00000001"):
            RobotLink(service.path, expected_hash=1).open()


def test_host_servo_on_a_garbling_port_says_so_in_one_line(far_end: FarEnd, tmp_path: Path,
                                                           capsys) -> None:
    grey = np.zeros((60, 80), np.uint8)
    for name in ("left_000.png", "right_000.png"):
        cv2.imwrite(str(tmp_path / name), grey)
    far_end.repeat(bytes(range(0, 256, 7)))
    assert main(["servo", "--camera", f"replay:{tmp_path}", "--port", far_end.port]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("host servo: error: no answer from a robot")
    assert "only garbled frames arrived" in err


def test_a_line_that_echoes_is_named() -> None:
    with pytest.raises(LinkError, match="the line echoes"):
        RobotLink("loop://", handshake_s=0.4).open()
