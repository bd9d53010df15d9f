"""Benchmark of the live view's cost to the servo loop: loop rate at 640x480 (or --size) with
no view, with the view but no page, and with a page connected (a separate process that asks for
updates as fast as they come, as a browser does), runs interleaved to show the noise; and the
page's update rate and bytes per second. The simulated world and robot run in lockstep
(host.sim.run), so the loop runs as fast as it can.

On a shared machine the wall-clock rate follows the load more than anything; the CPU time the
loop's own thread spends a step, and the whole process's (the view's threads included, the
page's process not), say what the view costs regardless of the load."""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import subprocess
import sys
import time

from host.sim.run import Setup, simulation
from host.stereo import MatcherParams
from host.stereo.matcher import warm_up
from host.view import ViewFeed, ViewServer


def measure(size: tuple[int, int], params: MatcherParams, frames: int, view: str) -> dict:
    """view: none, idle (server up, no page) or page."""
    page = None
    with simulation(Setup(size, 2.0, params=params), reference=False) as sim:
        servo = sim.servo
        feed = server = None
        if view != "none":
            feed = ViewFeed()
            server = ViewServer(feed, "127.0.0.1", 0, servo.request_stop).start()
            servo.observers.append(feed)
        servo.reference()
        if view == "page":
            assert server is not None
            page = subprocess.Popen([sys.executable, __file__, "--page",
                                     f"ws://127.0.0.1:{server.port}/updates"],
                                    stdout=subprocess.DEVNULL)
            while not server.connections:
                time.sleep(0.01)
        load0 = os.getloadavg()[0]
        busy = 0.0
        t0, cpu0, loop_cpu0 = time.perf_counter(), time.process_time(), time.thread_time()
        for _ in range(frames):
            busy += servo.step().latency_ms / 1000
        wall = time.perf_counter() - t0
        out = {"loop_hz": frames / wall, "processing_hz": frames / busy, "load": load0,
               "loop_cpu_ms": (time.thread_time() - loop_cpu0) / frames * 1000,
               "cpu_ms": (time.process_time() - cpu0) / frames * 1000}
        if server is not None and feed is not None:
            if page is not None:
                stats = server.connections[0]
                out.update(page_hz=stats["updates"] / stats["seconds"],
                           page_bytes_s=stats["bytes"] / stats["seconds"],
                           dropped=feed.dropped, snapshots=feed.snapshots)
            server.close()
            feed.close()
    if page is not None:
        page.wait(timeout=10)
    return out


async def _page(url: str) -> None:
    """A page: ask for the next update as soon as the last one (text and two pictures) came."""
    import aiohttp

    updates = 0
    async with aiohttp.ClientSession() as s, s.ws_connect(url, max_msg_size=0) as ws:
        await ws.send_str("next")
        parts = 0
        async for _msg in ws:
            parts += 1
            if parts == 3:
                parts, updates = 0, updates + 1
                await ws.send_str("next")
    print(json.dumps({"updates": updates}))


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--page", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.page:
        asyncio.run(_page(args.page))
        return 0
    size = tuple(int(v) for v in args.size.split("x"))
    params = MatcherParams(matcher="sad", block_size=9, num_disparities=64, border="clip")
    warm_up(params)
    print(f"{size[0]}x{size[1]}, matcher {params.matcher} window {params.block_size}, "
          f"{params.num_disparities} disparities, marker band; {args.frames} frames a run, "
          f"{args.rounds} interleaved rounds in rotated order; {os.cpu_count()} cores shared "
          "with other users")
    print(f"uptime at start: {_uptime()}")
    results: dict[str, list[dict]] = {"none": [], "idle": [], "page": []}
    for r in range(args.rounds):
        names = list(results)
        for view in names[r % 3:] + names[:r % 3]:  # each condition first in some round
            m = measure(size, params, args.frames, view)
            results[view].append(m)
            extra = ""
            if view == "page":
                extra = (f"; page {m['page_hz']:.1f} updates/s, {m['page_bytes_s'] / 1000:.0f} "
                         f"kB/s, dropped {m['dropped']} of {m['snapshots']}")
            print(f"  round {r + 1} {view:>4}: loop {m['loop_hz']:5.1f} Hz (processing alone "
                  f"{m['processing_hz']:5.1f} Hz); CPU a step: loop thread "
                  f"{m['loop_cpu_ms']:5.1f} ms, whole process {m['cpu_ms']:5.1f} ms; load "
                  f"{m['load']:.2f}{extra}", flush=True)
    print(f"uptime at end: {_uptime()}")
    for view, ms in results.items():
        hz = [m["loop_hz"] for m in ms]
        sd = statistics.stdev(hz) if len(hz) > 1 else 0.0
        print(f"{view:>4}: loop rate median {statistics.median(hz):5.1f} Hz, "
              f"range {min(hz):5.1f}-{max(hz):5.1f}, sd {sd:.1f}; CPU a step: loop thread "
              f"{statistics.median(m['loop_cpu_ms'] for m in ms):5.1f} ms, process "
              f"{statistics.median(m['cpu_ms'] for m in ms):5.1f} ms")
    pages = results["page"]
    print(f"page: {statistics.median(m['page_hz'] for m in pages):.1f} updates/s, "
          f"{statistics.median(m['page_bytes_s'] for m in pages) / 1000:.0f} kB/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
