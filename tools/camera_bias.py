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

import cv2
import numpy as np

from host.camera.calib_files import Calibration
from host.sim.run import _calibrate
from host.sim.trials import CAMERAS
from host.sim.world import World


def camera_lenses(seed: int, camera: int) -> tuple[float, float]:
    """The k1 of the left and right lens of a campaign's camera (host.sim.trials.trial_setup)."""
    k = np.random.default_rng([seed, camera, 1]).uniform(-0.1, 0.04, 2)
    return float(k[0]), float(k[1])


def _raw(world: World, ideal: np.ndarray, k1: float) -> np.ndarray:
    """The raw pixels whose ideal (lens-free) positions are `ideal` (n, 2)."""
    g = world.geometry
    k = np.array([[g.focal_px, 0, g.cx], [0, g.focal_px, g.cy], [0, 0, 1]])
    rays = np.column_stack([(ideal - [g.cx, g.cy]) / g.focal_px, np.ones(len(ideal))])
    out, _ = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), k,
                               np.array([k1, 0, 0, 0, 0], np.float64))
    return np.asarray(out, np.float64).reshape(-1, 2)


def disparity_error(world: World, calib: Calibration, lenses: tuple[float, float],
                    x: np.ndarray, y: np.ndarray, z: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For world points (x right, y above the floor, z deep; m): the rectified disparity's
    excess over the calibrated geometry's f'B'/z (px), the depth's error (m) and the rectified
    left column."""
    g, m = world.geometry, calib.mats
    v = g.cy + g.focal_px * (world.height_m - y) / z
    left = np.column_stack([g.cx + g.focal_px * x / z, v])
    right = np.column_stack([g.cx + g.focal_px * (x - g.baseline_m) / z, v])
    rect = []
    for side, ideal in enumerate((left, right)):
        k, d, r, p = (m[f"{n}{side + 1}"] for n in ("M", "D", "R", "P"))
        raw = _raw(world, ideal, lenses[side]).reshape(-1, 1, 2)
        rect.append(cv2.undistortPoints(raw, k, d, R=r, P=p).reshape(-1, 2))
    disp = rect[0][:, 0] - rect[1][:, 0]
    fb = calib.geometry.focal_px * calib.geometry.baseline_m
    return disp - fb / z, fb / disp - z, rect[0][:, 0]


def camera_row(world: World, calib: Calibration, lenses: tuple[float, float],
               target_m: float = 1.22) -> dict[str, float]:
    """One camera's figures (the module's columns)."""
    fx, fy = np.meshgrid(np.linspace(-0.45, -0.23, 9), np.linspace(0.05, 0.33, 7))
    face, _, _ = disparity_error(world, calib, lenses, fx.ravel(), fy.ravel(),
                                 np.full(fx.size, target_m))
    mark, _, _ = disparity_error(world, calib, lenses, np.zeros(1), np.full(1, 0.2),
                                 np.full(1, target_m))
    wx, wy = np.meshgrid(np.linspace(-1.0, 1.0, 41), np.array([0.08, 0.18, 0.28]))
    _, dz, col = disparity_error(world, calib, lenses, wx.ravel(), wy.ravel(),
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
        lenses = camera_lenses(a.seed, cam)
        r = camera_row(world, _calibrate((w, h), lenses, a.seed * CAMERAS + cam), lenses)
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
