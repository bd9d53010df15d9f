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


def render(rvec: np.ndarray, tvec: np.ndarray, rng: np.random.Generator,
           moved_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> StereoFrame:
    """Both views of the board at (rvec, tvec) (left camera frame, mm); moved_mm shifts the
    board before the right view is taken, as when unsynchronised sensors expose apart."""
    tex, a = board_texture()
    r = cv2.Rodrigues(rvec)[0]
    views = []
    for cam_r, cam_t, shift in ((np.eye(3), np.zeros(3), np.zeros(3)),
                                (R_RIGHT, -R_RIGHT @ np.array([BASELINE_MM, 0, 0]),
                                 np.array(moved_mm))):
        rb = cam_r @ r
        tb = cam_r @ (tvec + shift) + cam_t
        h = K @ np.column_stack([rb[:, 0], rb[:, 1], tb]) @ a
        img = cv2.warpPerspective(tex, h, SIZE, flags=cv2.INTER_AREA,
                                  borderValue=128)
        noisy = img.astype(np.float32) + rng.normal(0, 2.0, img.shape)
        views.append(np.clip(noisy, 0, 255).astype(np.uint8))
    return StereoFrame(views[0], views[1], 0.0, 0.0)


def poses(n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """n board poses over the view at 0.55-0.8 m, tilted up to 26 degrees."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        rvec = np.array([rng.uniform(-0.45, 0.45), rng.uniform(-0.45, 0.45),
                         rng.uniform(-0.3, 0.3)])
        center = np.array([rng.uniform(-90, 90), rng.uniform(-60, 60), rng.uniform(550, 800)])
        # place the board so that its centre lands at `center`
        mid = np.array([(BOARD[0] - 1) * SQUARE_MM / 2, (BOARD[1] - 1) * SQUARE_MM / 2, 0])
        out.append((rvec, center - cv2.Rodrigues(rvec)[0] @ mid))
    return out


def views(n: int = 14, seed: int = 0) -> list[StereoFrame]:
    rng = np.random.default_rng(seed + 1000)
    return [render(r, t, rng) for r, t in poses(n, seed)]


def moved_view(seed: int, moved_mm: tuple[float, float, float]) -> StereoFrame:
    """A pair whose board moved by moved_mm between the left and the right exposure."""
    (r, t), = poses(1, seed)
    return render(r, t, np.random.default_rng(seed), moved_mm)


def bent_view(seed: int, amplitude_px: float = 3.0) -> StereoFrame:
    """A pair whose left view is bent by a smooth wave (a warped board, or rolling shutter
    under a shaking hand): no pinhole camera sees a plane like that."""
    frame = views(1, seed)[0]
    h, w = frame.left.shape
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float32)
    map_x = xs + amplitude_px * np.sin(2 * np.pi * ys / 160.0).astype(np.float32)
    map_y = ys + amplitude_px * np.sin(2 * np.pi * xs / 200.0).astype(np.float32)
    bent = cv2.remap(frame.left, map_x, map_y, cv2.INTER_LINEAR, borderValue=128)
    return StereoFrame(bent, frame.right, 0.0, 0.0)


# index in the sequence -> the spoiled pair put there
SPOILED = {3: ("moved 7 mm between the exposures", lambda: moved_view(101, (6, 4, 0))),
           9: ("bent by a 3 px wave", lambda: bent_view(102)),
           15: ("moved 15 mm nearer", lambda: moved_view(103, (0, 0, 15)))}


def spoiled_sequence(good: int = 18) -> list[StereoFrame]:
    pairs = views(good)
    for i in sorted(SPOILED):
        pairs.insert(i, SPOILED[i][1]())
    return pairs
