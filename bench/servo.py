"""Benchmark of the servo loop on this machine: loop rate and frame-to-command latency (frame
arrival to the command acknowledged by the robot) at 320x240 and 640x480 with 64 disparities,
the emulator on a pty at 115200 baud in real time. Rendering the simulated frames is not
counted: a camera delivers them. Two ways of using the matcher each frame: a window around the
marker (the cross-check the loop needs, its search range set around the marker's disparity)
and the whole disparity map; both include the target's re-measure (a whole map once a second).
Record `uptime` beside the figures: the machine may be shared."""

from __future__ import annotations

import statistics
import sys

from host.emulator.emulator import Emulator, PtyService
from host.link.client import RobotLink
from host.servo.loop import Servo
from host.sim.source import SimSource
from host.sim.world import World
from host.stereo import MatcherParams
from host.stereo.matcher import warm_up

FRAMES = int(sys.argv[1]) if len(sys.argv) > 1 else 150


def measure(size: tuple[int, int], params: MatcherParams, full_map: bool) -> tuple[float, ...]:
    world = World.for_size(*size)
    world.robot.z_m = 2.0
    emulator = Emulator()
    with PtyService(emulator, realtime=True) as service, RobotLink(service.path) as link:
        # the simulated camera steps its own copy of the world; the robot here only answers
        source = SimSource(world, Emulator(line_rate=False), reference_frames=3)
        servo = Servo(source, link, params, world.geometry, full_map=full_map)
        servo.reference()
        lat = []
        t_busy = 0.0
        for _ in range(FRAMES):
            row = servo.step()
            lat.append(row.latency_ms)
            t_busy += row.latency_ms / 1000
    lat.sort()
    return statistics.median(lat), lat[int(0.95 * len(lat))], FRAMES / t_busy


def main() -> int:
    import os

    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} on "
          f"{os.cpu_count()} cores")
    params = MatcherParams(matcher="sad", block_size=9, num_disparities=64, border="clip")
    warm_up(params)
    print(f"matcher: {params.matcher}, window {params.block_size}, {params.num_disparities} "
          f"disparities, colour off (the simulated camera is grey); {FRAMES} frames each")
    for size in ((320, 240), (640, 480)):
        for full in (False, True):
            med, p95, hz = measure(size, params, full)
            what = "whole map  " if full else "marker band"
            print(f"  {size[0]}x{size[1]} {what}: frame-to-command median {med:5.1f} ms, "
                  f"p95 {p95:5.1f} ms; loop rate the processing allows {hz:6.1f} Hz")
    return 0


if __name__ == "__main__":
    sys.exit(main())
