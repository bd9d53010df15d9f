"""What tells a user whether to trust a calibration: where in the image the chessboard corners
fell (lens distortion is only known where corners were), and the rectified pair drawn with
horizontal lines (a feature must sit on the same line in both views)."""

from __future__ import annotations

import cv2
import numpy as np

from host.camera.calib_files import Calibration
from host.camera.calibration import Rectifier
from host.camera.source import StereoFrame

GRID = (8, 6)  # coverage cells across, down
WELL_COVERED = 0.75  # share of cells with corners below which the user is told


def coverage(corners: list[np.ndarray], size: tuple[int, int],
             grid: tuple[int, int] = GRID) -> np.ndarray:
    """Corner counts per cell of a grid over the image, shape (rows, cols)."""
    counts = np.zeros((grid[1], grid[0]), int)
    if not corners:
        return counts
    pts = np.concatenate([c.reshape(-1, 2) for c in corners])
    col = np.clip((pts[:, 0] * grid[0] / size[0]).astype(int), 0, grid[0] - 1)
    row = np.clip((pts[:, 1] * grid[1] / size[1]).astype(int), 0, grid[1] - 1)
    np.add.at(counts, (row, col), 1)
    return counts


def coverage_lines(counts: np.ndarray, side: str) -> list[str]:
    """A text map ('#' corners, '.' none) and a one-line verdict."""
    share = float(np.mean(counts > 0))
    border = np.concatenate([counts[0], counts[-1], counts[1:-1, 0], counts[1:-1, -1]])
    lines = [f"{side}: corners in {share:.0%} of the image ({counts.shape[1]}x"
             f"{counts.shape[0]} cells), {np.mean(border > 0):.0%} of the border cells"]
    lines += ["  |" + "".join("#" if c else "." for c in row) + "|" for row in counts]
    if share < WELL_COVERED:
        lines.append(f"  {side}: add views with the board near the empty cells ('.'): the "
                     f"lens distortion is a guess there")
    return lines


def check_picture(calib: Calibration, frame: StereoFrame, spacing: int = 24) -> np.ndarray:
    """The rectified pair side by side (BGR) with horizontal lines every `spacing` px."""
    r = Rectifier(calib)(frame)
    views = [cv2.cvtColor(v, cv2.COLOR_GRAY2BGR) if v.ndim == 2 else v.copy()
             for v in (r.left, r.right)]
    pic = np.hstack(views)
    for i, y in enumerate(range(spacing // 2, pic.shape[0], spacing)):
        colour = (0, 200, 0) if i % 2 == 0 else (0, 0, 230)
        cv2.line(pic, (0, y), (pic.shape[1] - 1, y), colour, 1)
    return pic
