"""The live view in a real browser: `host servo --sim --view` runs, headless Chromium opens the
page, the pictures, overlays and plots update, and STOP stops the emulated robot and ends the
run with that reason. Inside a loopback-only network namespace (unshare -n)."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from host.link.protocol_gen import SCHEMA_HASH

HERE = Path(__file__).parent


def _skip_reason() -> str | None:
    if shutil.which("chromium") is None:
        return "no chromium (Debian's package; tools/browser-deps.sh installs it as root)"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "no playwright (pip install -e '.[test]')"
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "no unshare/ip to make a loopback-only network namespace"
    r = subprocess.run(["unshare", "-n", "true"], capture_output=True, text=True)
    if r.returncode != 0:
        return f"unshare -n is not permitted here: {r.stderr.strip()}"
    return None


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> tuple[dict, Path]:
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    out = tmp_path_factory.mktemp("view")
    driver = f"ip link set lo up && exec {sys.executable} {HERE / 'browser_run.py'} {out}"
    r = subprocess.run(["unshare", "-n", "--", "bash", "-c", driver], capture_output=True,
                       text=True, timeout=240, cwd=HERE.parent.parent)
    result_file = out / "result.json"
    assert result_file.exists(), r.stderr[-3000:]
    result = json.loads(result_file.read_text())
    assert r.returncode == 0, r.stderr[-3000:] + result["stderr"]
    return result, out


def test_page_shows_pictures_and_overlays(run):
    result, out = run
    first, later = result["samples"][0], result["samples"][-1]
    assert first["left_loaded"] == 320 and first["disparity_loaded"] == 320
    assert later["target"].startswith("target ") and " px" in later["target"]
    assert later["target"].endswith(" m")
    assert later["robot"] is not None and later["hash"] == f"0x{SCHEMA_HASH:08X}"
    assert later["rtt"].endswith(" ms")
    assert (out / "view.png").stat().st_size > 20_000


def test_overlays_and_plots_update(run):
    result, _ = run
    samples = result["samples"]
    assert samples[-1]["updates"] > samples[1]["updates"] >= samples[0]["updates"] >= 1
    assert samples[-1]["seq"] > samples[1]["seq"]
    robots = {s["robot"] for s in samples[1:] if s["robot"]}
    assert len(robots) >= 2  # the robot drives: its disparity and depth change on the page
    assert samples[-1]["depth_last_t"] > samples[1]["depth_last_t"]
    assert samples[-1]["duty_last_t"] > samples[1]["duty_last_t"]
    assert samples[-1]["depth_points"] > samples[1]["depth_points"]


def test_stop_stops_the_robot_and_ends_the_run(run):
    result, out = run
    assert result["returncode"] == 0, result["stderr"]
    assert "stopped (STOP pressed in the view)" in result["stderr"]
    assert "the robot reports duty 0 0 after STOP" in result["stderr"]  # STATUS from the emulator
    rows = list(csv.DictReader((out / "run.csv").open()))
    assert rows[-1]["phase"] == "stop" and (rows[-1]["left"], rows[-1]["right"]) == ("0", "0")
    assert any(r["phase"] == "drive" for r in rows)
    after = result["after_stop"]
    assert after["phase"] == "stop" and after["reason"].startswith("STOP pressed in the view")
    assert not after["stop_enabled"]
