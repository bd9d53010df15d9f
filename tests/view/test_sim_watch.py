"""Watching the simulation: with --view, host servo --sim runs in real time, waits for a page
when asked (--view-wait), and keeps the page up after the run, saying it has ended, until
Ctrl-C, which then ends the command with the run's own status; host view says when a replay
has ended."""

from __future__ import annotations

import asyncio
import json
import queue
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import aiohttp
import cv2

from host.sim.renderer import Renderer
from host.sim.world import World


class Lines:
    """A process's stderr, line by line, read on a thread."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.q: queue.Queue[tuple[float, str]] = queue.Queue()
        self.seen: list[tuple[float, str]] = []
        threading.Thread(target=self._read, args=(proc,), daemon=True).start()

    def _read(self, proc: subprocess.Popen) -> None:
        for line in proc.stderr:  # type: ignore[union-attr]
            self.q.put((time.monotonic(), line))

    def wait_for(self, start: str, timeout: float = 120) -> tuple[float, str]:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                t, line = self.q.get(timeout=0.1)
            except queue.Empty:
                continue
            self.seen.append((t, line))
            if line.startswith(start):
                return t, line
        raise AssertionError(f"no line starting {start!r} in {[x for _, x in self.seen]}")


async def _one_update(url: str) -> dict:
    async with aiohttp.ClientSession() as s, s.ws_connect(f"ws://{url}/updates") as ws:
        await ws.send_str("next")
        state = json.loads((await ws.receive(timeout=60)).data)
        for _ in range(2):
            await ws.receive(timeout=10)
        return state


def _servo(*extra: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "host", "servo", "--sim", "--view",
                             "--settle", "0", "--border", "clip", "--num-disparities", "48",
                             *extra],
                            stderr=subprocess.PIPE, text=True)


def test_a_watched_simulation_runs_in_real_time_and_stays_up(tmp_path: Path) -> None:
    proc = _servo("--duration", "3")
    try:
        lines = Lines(proc)
        url = re.search(r"http://(\S+)/", lines.wait_for("live view: http")[1])[1]  # type: ignore[index]
        t_start, _ = lines.wait_for("target: ")
        t_end, _ = lines.wait_for("live view: the run has ended")
        assert t_end - t_start >= 2.7  # 3 s of simulated time took (at least) 3 s
        state = asyncio.run(_one_update(url))
        assert state["phase"] == "ended" and "stopped while in phase" in state["reason"]
        assert proc.poll() is None  # still up
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0  # the run's own status, not an interrupt's
    finally:
        proc.kill()
        proc.wait()


def test_view_wait_starts_once_a_page_is_open() -> None:
    proc = _servo("--duration", "0.5", "--speed", "0", "--view-wait")
    try:
        lines = Lines(proc)
        url = re.search(r"http://(\S+)/", lines.wait_for("live view: http")[1])[1]  # type: ignore[index]
        lines.wait_for("live view: waiting for a page")
        time.sleep(2)
        assert not any(line.startswith("target: ") for line in _drain(lines))
        asyncio.run(_one_update(url))
        lines.wait_for("target: ")
        lines.wait_for("live view: the run has ended")
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0
    finally:
        proc.kill()
        proc.wait()


def _drain(lines: Lines) -> list[str]:
    while True:
        try:
            lines.seen.append(lines.q.get_nowait())
        except queue.Empty:
            return [x for _, x in lines.seen]


def test_host_view_says_when_a_replay_has_ended(tmp_path: Path) -> None:
    renderer = Renderer(World())
    for i in range(2):
        pair = renderer.frame(with_robot=True)
        cv2.imwrite(str(tmp_path / f"left_{i:03d}.png"), pair.left)
        cv2.imwrite(str(tmp_path / f"right_{i:03d}.png"), pair.right)
    proc = subprocess.Popen([sys.executable, "-m", "host", "view", "--camera",
                             f"replay:{tmp_path}", "--border", "clip", "--num-disparities", "48",
                             "--duration", "120"], stderr=subprocess.PIPE, text=True)
    try:
        lines = Lines(proc)
        url = re.search(r"http://(\S+)/", lines.wait_for("live view: http")[1])[1]  # type: ignore[index]
        lines.wait_for("host view: the camera ended")
        state = asyncio.run(_one_update(url))
        assert state["phase"] == "ended" and "the camera ended" in state["reason"]
        assert state["samples"] and state["samples"][-1][2] is not None  # the marker's depth
    finally:
        proc.kill()
        proc.wait()
