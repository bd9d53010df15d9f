"""Calibrating the simulated Minoru as a user calibrates the real one: chessboard pairs rendered
through its lenses, then the project's own calibration (host.camera.calibration), so the loop
rectifies with an imperfect, realistic calibration rather than with the renderer's truth."""

from __future__ import annotations

import cv2
import numpy as np

from host.camera.calib_files import Calibration
from host.camera.calibration import calibrate, find_board
from host.camera.source import StereoFrame
from host.sim.faults import CameraFaults
from host.sim.renderer import lens_maps
from host.sim.world import World

BOARD = (9, 6)  # inner corners, columns x rows
SQUARE_MM = 25.0
PPM = 6  # texture pixels per mm
SUPERSAMPLE = 4  # a view is drawn at 4x4 points a pixel and averaged: a sensor's pixel
# integrates the light over its area (the scene's renderer does the same with its 4x4 samples);
# one point a pixel steps every edge and moved the corners 0.19 px RMS, 0.05 px at 4x4


def _texture() -> tuple[np.ndarray, np.ndarray]:
    """The board image and the affine map from its pixels to board millimetres."""
    cols, rows = BOARD[0] + 1, BOARD[1] + 1
    sq = int(SQUARE_MM * PPM)
    img = np.full(((rows + 2) * sq, (cols + 2) * sq), 235, np.uint8)
    for j in range(rows):
        for i in range(cols):
            if (i + j) % 2 == 0:
                img[(j + 1) * sq:(j + 2) * sq, (i + 1) * sq:(i + 2) * sq] = 20
    x0 = -2 * SQUARE_MM  # inner corner (0, 0) is one square in, after a square of margin
    # texture pixel p covers p - 0.5 .. p + 0.5: a square's edge at index (j + 1) sq lies at
    # (j + 1) sq - 0.5, board millimetre x0 + (j + 1) SQUARE_MM
    return img, np.array([[1 / PPM, 0, x0 + 0.5 / PPM], [0, 1 / PPM, x0 + 0.5 / PPM],
                          [0, 0, 1]])


def board_pairs(world: World, camera: CameraFaults, n: int = 24, seed: int = 0,
                poses: list[tuple[np.ndarray, np.ndarray]] | None = None) -> list[StereoFrame]:
    """n pairs of a chessboard held at random poses 0.4-0.65 m in front of the camera, over the
    whole picture (corners and edges too, where distortion is largest), seen through the lenses
    (the world's ideal geometry, each pixel the mean over its area, then each side's radial
    distortion). poses: when given, each pair's board pose in the left camera (Rodrigues
    vector, translation in mm; inner corner (0, 0) at the origin) is appended to it."""
    g, (w, h) = world.geometry, world.size
    k = np.array([[g.focal_px, 0, g.cx], [0, g.focal_px, g.cy], [0, 0, 1]])
    tex, a = _texture()
    lenses = [lens_maps(world, k1) for k1 in camera.distortion]
    rng = np.random.default_rng(seed)
    mid = np.array([(BOARD[0] - 1) * SQUARE_MM / 2, (BOARD[1] - 1) * SQUARE_MM / 2, 0])
    # pixel x of the view is the mean of the fine pixels s x .. s x + s - 1 (INTER_AREA)
    s = SUPERSAMPLE
    fine = np.array([[s, 0, (s - 1) / 2], [0, s, (s - 1) / 2], [0, 0, 1]])
    pairs = []
    for _ in range(n):
        rvec = np.array([rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), rng.uniform(-0.3, 0.3)])
        r = cv2.Rodrigues(rvec)[0]
        z = rng.uniform(400, 650)
        centre = np.array([rng.uniform(-0.2, 0.2) * z, rng.uniform(-0.12, 0.12) * z, z])
        t = centre - r @ mid
        if poses is not None:
            poses.append((rvec, t))
        views = []
        for side, lens in enumerate(lenses):
            shift = np.array([-world.geometry.baseline_m * 1000 * side, 0, 0])
            hom = fine @ k @ np.column_stack([r[:, 0], r[:, 1], t + shift]) @ a
            img = cv2.resize(cv2.warpPerspective(tex, hom, (w * s, h * s), flags=cv2.INTER_LINEAR,
                                                 borderValue=128).astype(np.float32),
                             (w, h), interpolation=cv2.INTER_AREA)
            if lens is not None:
                img = np.asarray(cv2.remap(img, lens[0], lens[1], cv2.INTER_LINEAR,
                                           borderMode=cv2.BORDER_REPLICATE), np.float32)
            img += rng.normal(0, 2.0, (h, w)).astype(np.float32)
            views.append(np.clip(np.rint(img), 0, 255).astype(np.uint8))
        pairs.append(StereoFrame(views[0], views[1], 0.0, 0.0))
    return pairs


def calibrate_camera(world: World, camera: CameraFaults, seed: int = 0,
                     pairs: int = 18) -> Calibration:
    """The simulated camera calibrated by host.camera.calibration on rendered boards: poses
    are drawn until `pairs` of them show the whole board in both views, as a user keeps
    showing the board until enough views are taken."""
    found: list[StereoFrame] = []
    for batch in range(8):
        for frame in board_pairs(world, camera, seed=seed * 8 + batch):
            if find_board(frame.left, BOARD) is not None and \
                    find_board(frame.right, BOARD) is not None:
                found.append(frame)
        if len(found) >= pairs:
            break
    return calibrate(found[:pairs], BOARD, SQUARE_MM).calibration


def rectified_disparity_error(world: World, calib: Calibration, lenses: tuple[float, float],
                              x: np.ndarray, y: np.ndarray, z: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How far a calibration of the simulated camera leaves rectified disparity from the truth:
    world points (x right, y above the floor, z deep; m) through the true lenses (lens_maps'
    model), then the calibration's undistortion and rectification. Returns the disparity's
    excess over the calibrated geometry's f'B'/z (px), the depth it gives less z (m), and the
    points' rectified left columns (px)."""
    g, m = world.geometry, calib.mats
    k = np.array([[g.focal_px, 0, g.cx], [0, g.focal_px, g.cy], [0, 0, 1]])
    rect = []
    for side in (0, 1):
        rays = np.column_stack([x - g.baseline_m * side, world.height_m - y, z])
        raw, _ = cv2.projectPoints(rays.astype(np.float64), np.zeros(3), np.zeros(3), k,
                                   np.array([lenses[side], 0, 0, 0, 0], np.float64))
        kk, d, r, p = (m[f"{name}{side + 1}"] for name in ("M", "D", "R", "P"))
        rect.append(cv2.undistortPoints(raw, kk, d, R=r, P=p).reshape(-1, 2))
    disp = rect[0][:, 0] - rect[1][:, 0]
    fb = calib.geometry.focal_px * calib.geometry.baseline_m
    return disp - fb / z, fb / disp - z, rect[0][:, 0]
