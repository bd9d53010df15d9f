"""host view --camera sim: the simulated world on the page, as host servo --sim sees it (the
robot's marker found), with nothing driven; the options that make no sense for it refused."""

from __future__ import annotations

import asyncio
import json
import re
import subprocess
import sys

import aiohttp
import pytest

from host.cli import main


def test_view_shows_the_simulated_world() -> None:
    proc = subprocess.Popen([sys.executable, "-m", "host", "view", "--camera", "sim",
                             "--duration", "60"], stderr=subprocess.PIPE, text=True)
    try:
        line = ""
        while not line.startswith("live view: "):
            line = proc.stderr.readline()  # type: ignore[union-attr]
            assert line, "host view ended without printing its address"
        url = re.search(r"http://(\S+)/", line)[1]  # type: ignore[index]

        async def updates(n: int) -> list[dict]:
            """Up to n states, until one shows the robot's marker."""
            states: list[dict] = []
            async with aiohttp.ClientSession() as s, s.ws_connect(f"ws://{url}/updates") as ws:
                while len(states) < n and (not states or not states[-1]["overlay"]["marker"]):
                    await ws.send_str("next")
                    states.append(json.loads((await ws.receive(timeout=60)).data))
                    for _ in range(2):  # the left image and the disparity
                        await ws.receive(timeout=10)
            return states

        states = asyncio.run(updates(60))
        assert all(s["phase"] == "view" and s["can_stop"] is False for s in states)
        # the first frames without the robot, as the servo's reference phase sees them; then
        # the simulated robot at its start
        assert states[-1]["overlay"]["marker"] is not None, len(states)
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_view_sim_refuses_a_calibration(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["view", "--camera", "sim", "--calib", str(tmp_path / "c.yml")]) == 2
    assert "--camera sim is the simulated camera" in capsys.readouterr().err
