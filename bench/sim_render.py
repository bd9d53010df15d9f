"""Benchmark of the simulated camera: CPU a view of host.sim.renderer against the frozen renderer
from before it was made faster (tests/sim/renderer_oracle.py, the same images), interleaved in
one process, one OpenCV thread: a faulty camera (random_faults' of --seed) with the robot coming
from 1.9 m to 0.7 m, turning and blurred; and the same with flicker, and with a knocked rig.

Process CPU time (not wall time), best of --repeats runs of --views views; the machine's load
average is printed with the figures."""

from __future__ import annotations

import argparse
import math
import os
import time

import cv2
import numpy as np

from host.sim.faults import random_faults
from host.sim.renderer import Flicker, Renderer
from host.sim.world import World
from tests.sim import renderer_oracle


def ms_per_view(cls: type, camera, size: tuple[int, int], views: int, seed: int,
                flicker: Flicker | None = None, pitch_deg: float = 0.0,
                image: bool = False) -> float:
    """CPU ms a view; image: Renderer.image (the image alone, drawn in place, as the trials'
    camera takes it) instead of view()."""
    world = World.for_size(*size, seed=seed)
    r = cls(world, camera, seed=seed)
    r.pitch_deg, r.flicker = pitch_deg, flicker
    r.view(0)
    r.view(1)  # the static scene (and the bare sensor images) are made once, not timed
    t0 = time.process_time()
    for i in range(views):
        world.robot.z_m = 1.9 - 1.2 * i / views
        world.robot.theta = 0.3 * math.sin(i / 20)
        world.t = i / 30
        if image:
            r.image(i % 2, True, (0.6 * math.sin(i / 7), 0.2), world.t)
        else:
            r.view(i % 2, True, (0.6 * math.sin(i / 7), 0.2), world.t)
    return (time.process_time() - t0) / views * 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--views", type=int, default=400)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=2)
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    cv2.setNumThreads(1)
    camera = random_faults(np.random.default_rng(args.seed), 1.2).camera
    print(f"load average {os.getloadavg()[0]:.1f}, {args.size}, seed {args.seed}, "
          f"{args.views} views x {args.repeats}")
    for label, kw in [("faulty", {}), ("faulty + flicker", {"flicker": Flicker(0.2, 100, 0.01)}),
                      ("faulty + knock 1.5 deg", {"pitch_deg": 1.5})]:
        old, new, image = [], [], []
        for _ in range(args.repeats):
            old.append(ms_per_view(renderer_oracle.Renderer, camera, size, args.views,
                                   args.seed, **kw))
            new.append(ms_per_view(Renderer, camera, size, args.views, args.seed, **kw))
            image.append(ms_per_view(Renderer, camera, size, args.views, args.seed, **kw,
                                     image=True))
        print(f"{label:24s} before {min(old):.3f} ms/view, now {min(new):.3f} ms/view, "
              f"{min(old) / min(new):.2f}x; image() {min(image):.3f} ms "
              f"({min(old) / min(image):.2f}x)")


if __name__ == "__main__":
    main()
