"""Benchmark of the servo loop a user runs: `host servo --sim` with the defaults (own SAD,
window 9, 64 disparities) at 320x240 and 640x480, one whole run each (measure, turn, drive,
creep, hold and the target's re-measures; the reference phase not counted). Per size: frames
per second the processing allows (frames / summed frame-to-command time), the frame-to-command
latency (frame arrival to the command acknowledged by the robot) p50 / p95 / max, and the CPU
time the loop's thread spent on the same span (what a free core would need, whatever the load).
Rendering is not counted (a camera delivers the frames); the robot is the firmware's core on a
pty in lockstep, so the 1.9 ms a SET_DRIVE and its ACK take on a 115200-baud wire
(bench/link.py) is not in the latency.

The machine may be shared: beside each figure stand the load average before and after, the
threads, and cv2.StereoBM (64 disparities, window 9) on the whole 640x480 frame, timed in the
same process between the servo's frames, with the ratio of the two.

    bench/servo.py [FRAMES] [--stages]    FRAMES: most frames per run (default 450);
                                          --stages: where each frame's milliseconds go
                                          (wall and CPU of the loop's thread per stage)
"""

from __future__ import annotations

import functools
import os
import statistics
import sys
import time
from collections import Counter
from collections.abc import Callable

import cv2
import numba

from host.servo import loop
from host.servo.perception import StripMap
from host.sim.renderer import Renderer
from host.sim.run import Setup, simulation
from host.sim.world import World
from host.stereo import MatcherParams
from host.stereo.matcher import SERIAL_WORK, warm_up

STAGES = {  # what the loop calls, by the name the table prints
    "exposure": (loop, "match_exposure"),
    "marker": (loop, "marker_candidates"),
    "marker window match": (loop, "marker_disparity"),
    "re-measure band": (StripMap, "add"),
    "re-measure analysis": (loop.Servo, "_remeasure"),
    "control law": (loop.Controller, "update"),
    "command + ACK": (loop.Servo, "_send"),
}


def _timed(f: Callable, times: list[tuple[float, float]]) -> Callable:
    """f, appending (wall ms, CPU ms of the calling thread) of every call to times."""
    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        t0, c0 = time.perf_counter(), time.thread_time()
        try:
            return f(*args, **kwargs)
        finally:
            times.append(((time.perf_counter() - t0) * 1000, (time.thread_time() - c0) * 1000))
    return wrapper


def _pct(values: list[float], q: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(q * len(s)))]


def run(size: tuple[int, int], frames: int, bm_every: int = 5) -> dict:
    """One simulated run of the user's loop; StereoBM timed on the 640x480 frame every
    bm_every frames."""
    bm = cv2.StereoBM_create(64, 9)
    world = World.for_size(640, 480)
    world.robot.z_m = 1.9
    bm_frame = Renderer(world).frame()
    setup = Setup(size, params=MatcherParams().validate())
    load0 = os.getloadavg()[0]
    latency, cpu, bm_ms, phases = [], [], [], Counter()
    with simulation(setup) as sim:
        read, reading = sim.servo._frame, [0.0]

        def timed_read():  # rendering the frame is the camera's work, not the loop's
            t0 = time.thread_time()
            try:
                return read()
            finally:
                reading[0] = time.thread_time() - t0

        sim.servo._frame = timed_read
        for i in range(frames):
            t0 = time.thread_time()
            sim.step()
            cpu.append((time.thread_time() - t0 - reading[0]) * 1000)
            row = sim.servo.rows[-1]
            latency.append(row.latency_ms)
            phases[row.phase] += 1
            if i % bm_every == 0:
                t0 = time.perf_counter()
                bm.compute(bm_frame.left, bm_frame.right)
                bm_ms.append((time.perf_counter() - t0) * 1000)
            if sim.servo.stop_reason or sim.servo.held_for(1.0):
                break
        outcome = sim.servo.outcome()
    return {"latency": latency, "cpu": cpu, "bm": bm_ms, "phases": phases, "outcome": outcome,
            "load": (load0, os.getloadavg()[0])}


def main(argv: list[str]) -> int:
    frames = int(next((a for a in argv if a.isdigit()), 450))
    stages: dict[str, list[tuple[float, float]]] = {}
    if "--stages" in argv:
        for name, (owner, attr) in STAGES.items():
            stages[name] = []
            setattr(owner, attr, _timed(getattr(owner, attr), stages[name]))
    warm_up(MatcherParams())
    print(f"servo loop, `host servo --sim` defaults (SAD window 9, 64 disparities, nominal "
          f"world, start 1.9 m), {os.cpu_count()} cores; numba {numba.get_num_threads()} "
          f"threads (matches under {SERIAL_WORK / 1e6:.1f} M pixel-disparities and the "
          f"re-measure's bands on the loop's own thread), OpenCV {cv2.getNumThreads()} threads")
    for size in ((320, 240), (640, 480)):
        for times in stages.values():
            times.clear()
        r = run(size, frames)
        lat, bm = r["latency"], statistics.median(r["bm"])
        mean = sum(lat) / len(lat)
        phases = ", ".join(f"{k} {v}" for k, v in r["phases"].items())
        print(f"  {size[0]}x{size[1]}: {1000 / mean:6.1f} frames/s of processing (mean "
              f"{mean:.1f} ms); frame-to-command p50 {statistics.median(lat):.1f} ms, p95 "
              f"{_pct(lat, 0.95):.1f} ms, max {max(lat):.1f} ms; load {r['load'][0]:.2f} -> "
              f"{r['load'][1]:.2f}, numba {numba.get_num_threads()} threads, OpenCV "
              f"{cv2.getNumThreads()}")
        cpu = r["cpu"]
        print(f"      CPU of the loop's thread a frame: p50 {statistics.median(cpu):.1f} ms, p95 "
              f"{_pct(cpu, 0.95):.1f} ms, mean {sum(cpu) / len(cpu):.1f} ms: "
              f"{1000 * len(cpu) / sum(cpu):.0f} frames/s on a free core")
        print(f"      same process: cv2.StereoBM on the whole 640x480 frame {bm:.1f} ms "
              f"(median of {len(r['bm'])}); a servo frame costs {mean / bm:.2f} StereoBM "
              f"frames")
        print(f"      {len(lat)} frames ({phases}); {': '.join(filter(None, r['outcome']))}")
        for name, times in stages.items():
            if times:
                wall, cpu = [t[0] for t in times], [t[1] for t in times]
                print(f"      {name:<20} {len(times):4d} calls; wall p50 "
                      f"{statistics.median(wall):6.2f} ms, p95 {_pct(wall, 0.95):6.2f} ms; CPU "
                      f"p50 {statistics.median(cpu):6.2f} ms, p95 {_pct(cpu, 0.95):6.2f} ms, "
                      f"{sum(cpu) / len(lat):5.2f} ms a frame")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
