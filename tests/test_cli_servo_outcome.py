"""host servo's exit status tells how the run ended: held (0), or not reached (3) with the
reason: the marker never seen, or a safe stop at the end."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import cv2
import pytest

from host.cli import main
from host.commands.servo_outcome import NOT_REACHED, outcome
from host.servo.loop import LogRow, run_outcome
from host.servo.phase import Phase


def _row(t: float, phase: str, robot_px: float = math.nan, reason: str = "") -> LogRow:
    depth = 25.0 / robot_px
    return LogRow(t, phase, reason, 1.25, depth, depth - 1.25, 20.0, robot_px, robot_px, 0, 0,
                  30.0, 1.0, 0.0)


class _Run:
    """What outcome() reads of a finished Servo: its log rows, the stop asked for, the target."""

    def __init__(self, rows: list[LogRow], requested_stop: str | None = None) -> None:
        self.rows, self.requested_stop, self.target_m = rows, requested_stop, 1.25

    def outcome(self) -> tuple[str, str]:
        return run_outcome(self.rows)


@pytest.mark.parametrize("rows, stop, status, words", [
    ([_row(0, Phase.HOLD), _row(1, Phase.LOST, reason="marker lost")], None, NOT_REACHED,
     "never seen in 2 frames"),
    ([_row(0, Phase.DRIVE, 18.0), _row(1, Phase.LOST, reason="marker lost")], None, NOT_REACHED,
     "safe stop after 1.0 s: marker lost"),
    ([_row(0, Phase.DRIVE, 18.0), _row(1, Phase.STALE, reason="stale")], None, NOT_REACHED,
     "stale"),
    ([_row(0, Phase.DRIVE, 18.0), _row(1, Phase.STOP, 19.0, "target vanished")], None, NOT_REACHED,
     "target vanished"),
    ([_row(0, Phase.DRIVE, 18.0), _row(1, Phase.HOLD, 20.1)], None, 0, "held at 1.244 m"),
    ([_row(0, Phase.DRIVE, 18.0), _row(1, Phase.DRIVE, 19.0)], None, 0,
     "stopped while in phase drive"),
    ([_row(0, Phase.DRIVE, 18.0), _row(1, Phase.STOP, 19.0, "pressed")], "pressed", 0,
     "stopped (pressed)"),
    ([], None, NOT_REACHED, "before the robot phase"),
])
def test_outcome_of_a_run(rows: list[LogRow], stop: str | None, status: int, words: str) -> None:
    got, message = outcome(_Run(rows, stop))  # type: ignore[arg-type]
    assert got == status and words in message and "nan" not in message


def test_a_replay_without_the_marker_exits_3_with_the_reason(tmp_path: Path, capsys) -> None:
    from host.sim.renderer import Renderer
    from host.sim.world import World

    renderer = Renderer(World.for_size(320, 240))
    for i in range(8):  # five reference frames, then three in which no robot appears
        frame = renderer.frame(with_robot=False)
        cv2.imwrite(str(tmp_path / f"left_{i:03d}.png"), frame.left)
        cv2.imwrite(str(tmp_path / f"right_{i:03d}.png"), frame.right)
    log = tmp_path / "run.csv"
    with warnings.catch_warnings(record=True) as caught:  # e.g. numpy's "All-NaN slice"
        warnings.simplefilter("always")
        assert main(["servo", "--camera", f"replay:{tmp_path}", "--port", "emulator",
                     "--num-disparities", "48", "--log", str(log)]) == NOT_REACHED
    assert [str(w.message) for w in caught if w.category is RuntimeWarning] == []
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == ("host servo: not reached: the marker was never seen in 3 "
                                    "frames (check --marker and that the robot's marker faces "
                                    "the cameras)")
    assert "nan" not in err
    assert len(log.read_text().splitlines()) == 4
