"""How far each simulated camera's calibration leaves rectified disparity from the truth: world
points through the true lenses (host.sim.renderer.lens_maps' model), then through the
calibration's undistortion and rectification, their disparity against f'B'/Z of the
calibrated geometry (px) and the depth it gives against Z (cm). No matcher: the
calibration's own share of a depth bias.

    python tools/camera_bias.py SEED [--cameras 0-15]

Columns: the lenses' k1 (left, right); the box's face (x -0.45..-0.23 m, 1.22 m deep; a
trial's target), the marker (x 0, 0.2 m high, same depth) and their difference (the hold's
bias: the robot holds where the marker reads the face's disparity); the back wall (3.2 m) in
the lane (|x| <= 0.25 m) and over the picture (median, least, greatest; cm, negative: near).
"""

from __future__ import annotations

import argparse

import numpy as np

from host.camera.calib_files import Calibration
from host.sim.chessboard import rectified_disparity_error
from host.sim.run import _calibration, calibration_key
from host.sim.trials import CAMERAS, trial_setup
from host.sim.world import World
from host.stereo.params import MatcherParams


def camera(seed: int, index: int, size: tuple[int, int]) -> tuple[tuple[float, float],
                                                                   Calibration]:
    """The lenses (k1 left, right) and calibration of a campaign's camera index % CAMERAS, as
    its trials get them (host.sim.trials.trial_setup)."""
    setup = trial_setup(seed, index, size, MatcherParams())
    key = calibration_key(setup)
    assert key is not None  # every faulty trial's camera has lenses
    return setup.faults.camera.distortion, _calibration(*key)


def camera_row(world: World, calib: Calibration, lenses: tuple[float, float],
               target_m: float = 1.22) -> dict[str, float]:
    """One camera's figures (the module's columns)."""
    fx, fy = np.meshgrid(np.linspace(-0.45, -0.23, 9), np.linspace(0.05, 0.33, 7))
    face, _, _ = rectified_disparity_error(world, calib, lenses, fx.ravel(), fy.ravel(),
                                           np.full(fx.size, target_m))
    mark, _, _ = rectified_disparity_error(world, calib, lenses, np.zeros(1),
                                           np.full(1, 0.2), np.full(1, target_m))
    wx, wy = np.meshgrid(np.linspace(-1.0, 1.0, 41), np.array([0.08, 0.18, 0.28]))
    _, dz, col = rectified_disparity_error(world, calib, lenses, wx.ravel(), wy.ravel(),
                                           np.full(wx.size, 3.2))
    seen = (col >= 0) & (col < world.size[0])
    lane = seen & (np.abs(wx.ravel()) <= 0.25)
    return {"face_px": float(np.median(face)), "marker_px": float(mark[0]),
            "hold_px": float(np.median(face) - mark[0]),
            "wall_lane_cm": 100 * float(np.median(dz[lane])),
            "wall_cm": 100 * float(np.median(dz[seen])),
            "wall_lo_cm": 100 * float(dz[seen].min()), "wall_hi_cm": 100 * float(dz[seen].max())}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("seed", type=int)
    ap.add_argument("--cameras", default=f"0-{CAMERAS - 1}")
    ap.add_argument("--size", default="320x240")
    a = ap.parse_args()
    lo, _, hi = a.cameras.partition("-")
    w, h = (int(v) for v in a.size.split("x"))
    world = World.for_size(w, h)
    print("cam   k1 L    k1 R   face px  marker px  hold px  wall lane cm  wall cm (lo..hi)")
    rows = []
    for cam in range(int(lo), int(hi or lo) + 1):
        lenses, calib = camera(a.seed, cam, (w, h))
        r = camera_row(world, calib, lenses)
        rows.append(r)
        print(f"{cam:3d}  {lenses[0]:+.3f}  {lenses[1]:+.3f}  {r['face_px']:+.3f}   "
              f"{r['marker_px']:+.3f}    {r['hold_px']:+.3f}    {r['wall_lane_cm']:+6.2f}      "
              f"{r['wall_cm']:+6.2f} ({r['wall_lo_cm']:+.1f}..{r['wall_hi_cm']:+.1f})",
              flush=True)
    for key in ("face_px", "hold_px", "wall_lane_cm"):
        v = np.array([r[key] for r in rows])
        print(f"{key}: RMS {np.sqrt(np.mean(v ** 2)):.3f}, |max| {np.abs(v).max():.3f}")


if __name__ == "__main__":
    main()
