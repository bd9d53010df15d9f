"""host view --camera: a recording on the page, with no STOP (nothing is driven); and --view
refuses a malformed address in one line."""

from __future__ import annotations

import asyncio
import json
import urllib.error
import urllib.request
from pathlib import Path

import aiohttp
import cv2
import numpy as np

from host.sim.renderer import Renderer
from host.sim.world import World

from ..in_process import host
from .running import host_view


def _recording(folder: Path, frames: int = 3) -> None:
    renderer = Renderer(World())
    for i in range(frames):
        pair = renderer.frame(with_robot=True)
        cv2.imwrite(str(folder / f"left_{i:03d}.png"), pair.left)
        cv2.imwrite(str(folder / f"right_{i:03d}.png"), pair.right)


def test_view_shows_a_recording_without_stop(tmp_path: Path) -> None:
    _recording(tmp_path)
    with host_view("--camera", f"replay:{tmp_path}", "--border", "clip", "--num-disparities", "48",
                   "--duration", "60") as url:
        async def one_update() -> tuple[dict, list[bytes]]:
            async with aiohttp.ClientSession() as s, s.ws_connect(f"ws://{url}/updates") as ws:
                await ws.send_str("next")
                state = json.loads((await ws.receive(timeout=60)).data)
                images = [(await ws.receive(timeout=10)).data for _ in range(2)]
                return state, images

        state, images = asyncio.run(one_update())
        assert state["phase"] == "view" and state["can_stop"] is False
        assert state["link"] is None and state["overlay"]["target"] is None
        assert state["overlay"]["marker"] is not None  # the robot's disc in both views
        disp = cv2.imdecode(np.frombuffer(images[1], np.uint8), cv2.IMREAD_COLOR)
        assert disp.shape == (240, 320, 3)
        req = urllib.request.Request(f"http://{url}/stop", method="POST")
        try:
            urllib.request.urlopen(req, timeout=5)
            status = 200
        except urllib.error.HTTPError as e:
            status = e.code
        assert status == 409  # no robot: STOP has nothing to act on


def test_bad_view_address_is_one_line(tmp_path: Path) -> None:
    r = host("servo", "--sim", "--view", "here:there")
    assert r.returncode == 2 and "--view must be [HOST:]PORT" in r.stderr
    assert r.stderr.count("\n") == 1
