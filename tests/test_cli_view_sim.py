"""host view --camera sim: the simulated world on the page, as host servo --sim sees it (the
robot's marker found), with nothing driven; the options that make no sense for it refused."""

from __future__ import annotations

import asyncio
import json

import aiohttp
import pytest

from host.cli import main

from .view.running import host_view


def test_view_shows_the_simulated_world() -> None:
    with host_view("--camera", "sim", "--duration", "60") as url:
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


def test_view_sim_refuses_a_calibration(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["view", "--camera", "sim", "--calib", str(tmp_path / "c.yml")]) == 2
    assert "--camera sim is the simulated camera" in capsys.readouterr().err
