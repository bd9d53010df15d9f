"""Drives the live view of a simulated servo run in headless Chromium, as a person would, and
writes what it saw to OUT/result.json (and OUT/view.png). Run inside a loopback-only network
namespace by test_browser.py:  python browser_run.py OUT"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

CHROMIUM = "/usr/bin/chromium"
# no sandbox as root; nothing in the background may reach for the network
FLAGS = ["--no-sandbox", "--disable-background-networking", "--disable-component-update",
         "--disable-default-apps", "--disable-sync", "--disable-domain-reliability",
         "--disable-client-side-phishing-detection", "--no-first-run", "--no-pings",
         "--metrics-recording-only", "--disable-features=MediaRouter,OptimizationHints"]


READ_DOM = """() => {
        const q = (id) => document.getElementById(id);
        const vis = (id) => q(id).getAttribute('visibility') === 'visible';
        const body = document.body.dataset;
        return {updates: +(body.updates || 0), seq: +(body.seq || 0),
                phase: q('phase').textContent, reason: q('reason').textContent,
                target: vis('target-box') ? q('target-label').textContent : null,
                robot: vis('marker-left') && vis('marker-right') ?
                       q('robot-label').textContent : null,
                marker_cx: vis('marker-left') ? +q('marker-left').getAttribute('cx') : null,
                depth_points: +q('depth-plot').dataset.points,
                depth_last_t: +(q('depth-plot').dataset.lastT || -1),
                duty_last_t: +(q('duty-plot').dataset.lastT || -1),
                rtt: q('link-rtt').textContent, hash: q('link-hash').textContent,
                page_rate: q('page-rate').textContent, bytes: q('page-bytes').textContent,
                left_loaded: q('left').naturalWidth,
                disparity_loaded: q('disparity').naturalWidth,
                stop_enabled: !q('stop').disabled};
    }"""


def read_dom(page) -> dict:
    return page.evaluate(READ_DOM)


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "host", "servo", "--sim", "--view", "127.0.0.1:0",
           "--settle", "0", "--duration", "600", "--border", "clip", "--num-disparities", "48",
           "--start-depth", "1.9", "--log", str(out / "run.csv")]
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)
    lines: list[str] = []
    url_found = threading.Event()

    def read() -> None:
        for line in proc.stderr:  # type: ignore[union-attr]
            lines.append(line)
            if line.startswith("live view: "):
                url_found.set()

    threading.Thread(target=read, daemon=True).start()
    result: dict = {"samples": []}
    try:
        if not url_found.wait(60):
            raise RuntimeError("host servo printed no live view address: " + "".join(lines))
        url = re.search(r"http://\S+", next(x for x in lines if x.startswith("live view")))[0]
        result["url"] = url
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(url)
            # images decode asynchronously after an update, and a later update starts decoding
            # anew (naturalWidth 0 until it is done): take the first sample in the same moment
            # that sees both pictures decoded, not in a second call after it
            first = page.wait_for_function(
                f"() => {{ const r = ({READ_DOM})(); return r.updates >= 1 && "
                "r.left_loaded > 0 && r.disparity_loaded > 0 ? r : null; }", timeout=30000)
            result["samples"].append(first.json_value())
            # on until the robot is seen and driven, and its depth has been plotted a while
            page.wait_for_function(
                "document.getElementById('phase').textContent !== 'reference' && "
                "document.getElementById('marker-left').getAttribute('visibility') === 'visible'"
                " && +document.getElementById('depth-plot').dataset.points > 20",
                timeout=60000)
            result["samples"].append(read_dom(page))
            t_end = time.monotonic() + 3
            while time.monotonic() < t_end:
                time.sleep(0.5)
                result["samples"].append(read_dom(page))
            page.screenshot(path=str(out / "view.png"), full_page=True)
            page.click("#stop")
            proc.wait(timeout=30)
            time.sleep(0.3)
            result["after_stop"] = read_dom(page)
            page.screenshot(path=str(out / "after-stop.png"), full_page=True)
            browser.close()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        time.sleep(0.2)
        result["returncode"] = proc.returncode
        result["stderr"] = "".join(lines)
        (out / "result.json").write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
