"""Chessboard pairs rendered from known intrinsics and a known baseline (no camera needed)."""

from __future__ import annotations

import cv2
import numpy as np

from host.camera.source import StereoFrame

SIZE = (640, 480)
K = np.array([[800.0, 0, 322.0], [0, 800.0, 238.0], [0, 0, 1]])
BASELINE_MM = 60.0
R_RIGHT = cv2.Rodrigues(np.array([0.004, -0.012, 0.006]))[0]  # right camera slightly turned
BOARD = (9, 6)
SQUARE_MM = 25.0
PPM = 8  # texture pixels per mm


def board_texture() -> tuple[np.ndarray, np.ndarray]:
    """The chessboard image and the affine map from texture pixels to board mm."""
    cols, rows = BOARD[0] + 1, BOARD[1] + 1  # squares
    margin = 1
    sq = int(SQUARE_MM * PPM)
    img = np.full(((rows + 2 * margin) * sq, (cols + 2 * margin) * sq), 235, np.uint8)
    for j in range(rows):
        for i in range(cols):
            if (i + j) % 2 == 0:
                y, x = (j + margin) * sq, (i + margin) * sq
                img[y:y + sq, x:x + sq] = 20
    # inner corner (0, 0) sits one square into the board, after the margin
    x0 = -(margin + 1) * SQUARE_MM
    a = np.array([[1 / PPM, 0, x0], [0, 1 / PPM, x0], [0, 0, 1]])
    return img, a


def render(rvec: np.ndarray, tvec: np.ndarray, rng: np.random.Generator) -> StereoFrame:
    tex, a = board_texture()
    r = cv2.Rodrigues(rvec)[0]
    views = []
    for cam_r, cam_t in ((np.eye(3), np.zeros(3)),
                         (R_RIGHT, -R_RIGHT @ np.array([BASELINE_MM, 0, 0]))):
        rb = cam_r @ r
        tb = cam_r @ tvec + cam_t
        h = K @ np.column_stack([rb[:, 0], rb[:, 1], tb]) @ a
        img = cv2.warpPerspective(tex, h, SIZE, flags=cv2.INTER_AREA,
                                  borderValue=128)
        noisy = img.astype(np.float32) + rng.normal(0, 2.0, img.shape)
        views.append(np.clip(noisy, 0, 255).astype(np.uint8))
    return StereoFrame(views[0], views[1], 0.0, 0.0)


def views(n: int = 14, seed: int = 0) -> list[StereoFrame]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        rvec = np.array([rng.uniform(-0.45, 0.45), rng.uniform(-0.45, 0.45),
                         rng.uniform(-0.3, 0.3)])
        center = np.array([rng.uniform(-60, 60), rng.uniform(-40, 40), rng.uniform(550, 800)])
        # place the board so that its centre lands at `center`
        mid = np.array([(BOARD[0] - 1) * SQUARE_MM / 2, (BOARD[1] - 1) * SQUARE_MM / 2, 0])
        tvec = center - cv2.Rodrigues(rvec)[0] @ mid
        out.append(render(rvec, tvec, rng))
    return out
