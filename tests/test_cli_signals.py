"""host servo ended by SIGTERM or SIGHUP does what Ctrl-C does: STOP reaches the robot, the
log is kept, and the exit status is 128+n."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from host.link import protocol_gen as gen
from host.link.frame import FrameDecoder


def _messages_received(record: Path) -> list[int]:
    """Message ids of the frames the emulator received from the host, in order."""
    return [f.id for f in FrameDecoder().feed(record.read_bytes())]


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_stops_the_robot_and_keeps_the_log(tmp_path: Path, signum: int) -> None:
    record, log, plot = tmp_path / "received.bin", tmp_path / "run.csv", tmp_path / "run.png"
    env = os.environ | {"HOST_EMULATOR_RECORD": str(record)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "host", "servo", "--sim", "--border", "clip",
         "--num-disparities", "48", "--settle", "0", "--duration", "120", "--log", str(log),
         "--plot", str(plot)],
        stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
    try:
        assert proc.stderr is not None
        first = proc.stderr.readline()  # printed once the reference phase is over
        assert first.startswith("target:"), first
        time.sleep(1.0)  # the robot is driving now
        proc.send_signal(signum)
        rest = proc.stderr.read()
        status = proc.wait(timeout=60)
    finally:
        proc.kill()
    assert status == 128 + signum, rest
    assert rest.splitlines() == [f"host servo: interrupted ({signal.Signals(signum).name})"]
    ids = _messages_received(record)
    set_drive, stop = gen.SetDrive.ID, gen.Stop.ID
    assert set_drive in ids, "the robot was never driven before the signal"
    last_drive = len(ids) - 1 - ids[::-1].index(set_drive)
    assert stop in ids[last_drive + 1:], "no STOP after the last SET_DRIVE"
    rows = log.read_text().splitlines()
    assert rows[0].startswith("t,phase") and len(rows) > 2
    assert plot.read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_ends_the_emulator_with_128_plus_n(tmp_path: Path, signum: int) -> None:
    proc = subprocess.Popen([sys.executable, "-m", "host", "emulate"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert proc.stdout is not None and proc.stdout.readline().startswith("/dev/pts/")
        time.sleep(0.5)
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 128 + signum, err
    name = "" if signum == signal.SIGINT else f" ({signal.Signals(signum).name})"
    assert err.splitlines()[-1] == f"host emulate: interrupted{name}"


def _run_with_a_ctrl_c_in_the_plot(tmp_path: Path, monkeypatch, during_run: bool) -> int:
    """host servo --sim --log --plot, a Ctrl-C arriving as the plot starts (and, during_run,
    another that ended the run): the exit status."""
    import dataclasses

    import host.commands.servo as servo_cmd
    from host.cli import main

    real_plot, real_run = servo_cmd.plot_run, servo_cmd.run_servo

    def plot(*a, **kw):
        os.kill(os.getpid(), signal.SIGINT)  # handled here, before the plot is written
        real_plot(*a, **kw)

    def run(servo, rules, *a, **kw):
        real_run(servo, dataclasses.replace(rules, duration_s=0.5, settle_s=0), *a, **kw)
        raise KeyboardInterrupt  # the first Ctrl-C, during the run

    monkeypatch.setattr(servo_cmd, "plot_run", plot)
    if during_run:
        monkeypatch.setattr(servo_cmd, "run_servo", run)
    return main(["servo", "--sim", "--border", "clip", "--num-disparities", "48",
                 "--duration", "0.5", "--settle", "0", "--log", str(tmp_path / "run.csv"),
                 "--plot", str(tmp_path / "run.png")])


@pytest.mark.parametrize("during_run", [False, True])
def test_a_ctrl_c_while_the_plot_is_written_keeps_it_whole(tmp_path: Path, monkeypatch, capsys,
                                                           during_run: bool) -> None:
    code = _run_with_a_ctrl_c_in_the_plot(tmp_path, monkeypatch, during_run)
    assert code == 130
    assert capsys.readouterr().err.splitlines()[-1] == "host servo: interrupted"
    png = (tmp_path / "run.png").read_bytes()
    assert png.startswith(b"\x89PNG") and png.endswith(b"IEND\xaeB`\x82")
    assert (tmp_path / "run.csv").read_text().startswith("t,phase")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv", "run.png"]
