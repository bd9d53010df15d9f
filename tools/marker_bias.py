"""The marker's depth bias against the world's truth over distance (issue 23: it reads deep far
away): dev trials' worlds (their camera: gains, noise, lenses and calibration) with the robot
standing at each depth, no events; the servo's own frame preparation (exposure, column bias) and
marker search, the pair nearest the true marker taken. Printed per depth: the median disparity
error (px, against the calibrated geometry's fB / z) of the centres taken once (before the mend)
and re-centred (after), on the same frames, and of the block matching over the ring; the median
depth error (cm) before and after, and the largest of the trials' medians. --camera picks the
camera's faults: the trial's, without its lenses ("flat"), or flat and noiseless ("ideal").

    .venv/bin/python tools/marker_bias.py --seeds 105 --indices 0-7 --depths 0.5,1,1.5,2,2.5,3
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics

from host.servo.loop import marker_disparity
from host.servo.marker import RECENTRE, marker_candidates
from host.sim.run import simulation
from host.sim.trials import trial_setup
from host.stereo.params import MatcherParams


def _range(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        out.extend(range(int(lo), int(hi or lo) + 1))
    return out


def measure(seed: int, index: int, z: float, frames: int, camera: str
            ) -> list[tuple[float, float, float, float, float]]:
    """Each frame where the true marker was found: the disparity error (px) of the centres
    taken once (recentre 0, before issue 23's mend), re-centred (RECENTRE) and of the block
    matching over the ring; the depth error (m) of the first two. On the same frames."""
    setup = trial_setup(seed, index, (320, 240), MatcherParams(block_size=9, num_disparities=48,
                                                               border="clip"))
    faults = dataclasses.replace(setup.faults, events=())
    if camera != "trial":
        cam = dataclasses.replace(faults.camera, distortion=(0.0, 0.0), skew_ms=0.0,
                                  exposure_ms=0.0, drop=0.0)
        if camera == "ideal":
            cam = dataclasses.replace(cam, noise=0.0, gain=(1.0, 1.0), bias=(0.0, 0.0))
        faults = dataclasses.replace(faults, camera=cam)
    setup = dataclasses.replace(setup, faults=faults, start_z_m=z,
                                start_x_m=setup.start_x_m / setup.start_z_m * z,
                                calib_seed=setup.calib_seed if camera == "trial" else None)
    out = []
    with simulation(setup) as sim:
        servo, world = sim.servo, sim.world
        g = servo.geometry
        for _ in range(frames):
            f = servo._unbiased(servo._exposed(servo._frame()))
            u, v, _ = world.marker_truth()
            z_true = world.robot.z_m
            truth = g.focal_px * g.baseline_m / z_true
            got = []
            for recentre in (0, RECENTRE):
                pairs = [p for p in marker_candidates(f.left, f.right, "disc", 0.03,
                                                      g.baseline_m, recentre=recentre)
                         if abs(p.left.u - u) < 3 and abs(p.left.v - v) < 3]
                got.append(pairs[0] if pairs else None)
            old, new = got
            if old is None or new is None:
                continue
            block, _, _ = marker_disparity(f.left, f.right, servo.params, new)
            out.append((old.disparity - truth, new.disparity - truth, block - truth,
                        g.depth_m(old.disparity) - z_true, g.depth_m(new.disparity) - z_true))
    return out


def _med(rows: list[tuple[float, float, float, float, float]], k: int) -> float:
    vals = [r[k] for r in rows if math.isfinite(r[k])]
    return statistics.median(vals) if vals else math.nan


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="105")
    ap.add_argument("--indices", default="0-3")
    ap.add_argument("--depths", default="0.5,1.0,1.5,2.0,2.5,3.0")
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--camera", choices=("trial", "flat", "ideal"), default="trial")
    a = ap.parse_args()
    print(f"camera {a.camera}; seeds {a.seeds} indices {a.indices}; {a.frames} frames each; "
          f"recentre 0 (before) and {RECENTRE} (after) on the same frames")
    print("depth_m   n  px: before  after  block | cm: before  after  |before|max  |after|max")
    for z in (float(s) for s in a.depths.split(",")):
        rows: list[tuple[float, float, float, float, float]] = []
        per: list[tuple[float, float]] = []  # each trial's median depth error, before and after
        for seed in _range(a.seeds):
            for index in _range(a.indices):
                got = measure(seed, index, z, a.frames, a.camera)
                rows += got
                if got:
                    per.append((_med(got, 3) * 100, _med(got, 4) * 100))
        if not rows:
            print(f"{z:5.2f}    0")
            continue
        print(f"{z:5.2f} {len(rows):4d}  {_med(rows, 0):+7.3f} {_med(rows, 1):+6.3f} "
              f"{_med(rows, 2):+6.3f} | {_med(rows, 3) * 100:+6.2f} {_med(rows, 4) * 100:+6.2f}"
              f"  {max(abs(p[0]) for p in per):6.2f}  {max(abs(p[1]) for p in per):6.2f}"
              "   (per trial, cm: " + " ".join(f"{p[0]:+.1f}/{p[1]:+.1f}" for p in per) + ")")


if __name__ == "__main__":
    main()
