"""host tune shows a progress bar on stderr when stderr is a terminal, and none otherwise."""

from __future__ import annotations

import fcntl
import os
import pty
import struct
import subprocess
import sys
import termios

ARGV = [sys.executable, "-m", "host", "tune", "--method", "grid", "--block-sizes", "5:7"]


def test_the_bar_shows_on_a_terminal() -> None:
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 30, 100, 0, 0))
    proc = subprocess.Popen(ARGV, stdout=subprocess.PIPE, stderr=slave, text=True)
    os.close(slave)
    seen = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the terminal closed: the command has ended
            break
        if not chunk:
            break
        seen += chunk
    out, _ = proc.communicate(timeout=120)
    os.close(master)
    assert proc.returncode == 0
    text = seen.decode(errors="replace")
    assert "grid on block-size" in text and "0/2" in text and "2/2" in text, text
    assert "2/2" not in out  # the bar is on stderr, the result on stdout


def test_no_bar_when_stderr_is_not_a_terminal(capsys) -> None:
    from host.cli import main

    assert main(ARGV[3:]) == 0
    out, err = capsys.readouterr()
    assert err == "" and out.startswith("grid on block-size")
