"""Stereo calibration from chessboard pairs, rectification maps, and the camera geometry.

Calibration files are OpenCV FileStorage YAML with image_size, K1 D1 K2 D2 R T E F R1 R2 P1 P2 Q,
rms (px), epipolar_rms (px, row error of rectified corners) and baseline_mm.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from host.camera.source import CameraError, StereoFrame
from host.files import write_text_atomic

MIN_PAIRS = 6
MINORU_FOCAL_PX_320 = 426.0  # Minoru sensor at 320x240, without a calibration
MINORU_BASELINE_M = 0.060


@dataclass(frozen=True)
class Geometry:
    """Rectified stereo geometry: Z = focal_px * baseline_m / disparity_px."""

    focal_px: float
    baseline_m: float
    cx: float
    cy: float

    def depth_m(self, disparity_px: float) -> float:
        return self.focal_px * self.baseline_m / disparity_px

    def disparity_px(self, depth_m: float) -> float:
        return self.focal_px * self.baseline_m / depth_m

    def px_per_m(self, disparity_px: float) -> float:
        """Depth resolution there: disparity change per metre of depth, d^2 / (f B) (one px of
        disparity is Z^2 / (f B) of depth)."""
        return disparity_px ** 2 / (self.focal_px * self.baseline_m)

    @classmethod
    def minoru_default(cls, width: int, height: int) -> Geometry:
        scale = width / 320.0
        print(f"no --calib: assuming the Minoru's nominal geometry, focal length "
              f"{MINORU_FOCAL_PX_320 * scale:.0f} px at {width}x{height} and baseline "
              f"{MINORU_BASELINE_M * 1000:.0f} mm", file=sys.stderr)
        return cls(MINORU_FOCAL_PX_320 * scale, MINORU_BASELINE_M, width / 2, height / 2)


@dataclass
class Calibration:
    size: tuple[int, int]
    mats: dict[str, np.ndarray]  # K1 D1 K2 D2 R T E F R1 R2 P1 P2 Q
    rms: float
    epipolar_rms: float

    @property
    def baseline_mm(self) -> float:
        return float(np.linalg.norm(self.mats["T"]))

    @property
    def geometry(self) -> Geometry:
        p1, p2 = self.mats["P1"], self.mats["P2"]
        return Geometry(float(p1[0, 0]), abs(float(p2[0, 3] / p2[0, 0])) / 1000.0,
                        float(p1[0, 2]), float(p1[1, 2]))

    def save(self, path: str | os.PathLike[str]) -> None:
        fs = cv2.FileStorage("calib.yml", cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_MEMORY)
        fs.write("image_size", np.array(self.size, np.int32))
        for k, v in self.mats.items():
            fs.write(k, v)
        fs.write("rms", self.rms)
        fs.write("epipolar_rms", self.epipolar_rms)
        fs.write("baseline_mm", self.baseline_mm)
        write_text_atomic(path, fs.releaseAndGetString())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Calibration:
        if not Path(path).is_file():
            raise CameraError(f"{path}: no such calibration file")
        try:
            fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
            ok = fs.isOpened()
        except cv2.error:
            ok = False
        if not ok:
            raise CameraError(f"{path}: not an OpenCV calibration file")
        mats = {k: fs.getNode(k).mat() for k in
                ("K1", "D1", "K2", "D2", "R", "T", "E", "F", "R1", "R2", "P1", "P2", "Q")}
        missing = [k for k, v in mats.items() if v is None]
        size = fs.getNode("image_size").mat()
        if missing or size is None:
            raise CameraError(f"{path}: missing {', '.join(missing or ['image_size'])}")
        return cls((int(size.ravel()[0]), int(size.ravel()[1])), mats,
                   fs.getNode("rms").real(), fs.getNode("epipolar_rms").real())


def find_board(image: np.ndarray, board: tuple[int, int]) -> np.ndarray | None:
    """Sub-pixel inner corners of a chessboard with board = (columns, rows), or None."""
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    found, corners = cv2.findChessboardCorners(grey, board, flags=flags)
    if not found:
        return None
    term = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-3)
    corners = cv2.cornerSubPix(grey, corners, (5, 5), (-1, -1), term)
    return corners.reshape(-1, 1, 2).astype(np.float32)


def board_points(board: tuple[int, int], square_mm: float) -> np.ndarray:
    cols, rows = board
    grid = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2).astype(np.float32)
    return np.hstack([grid * square_mm, np.zeros((len(grid), 1), np.float32)])


def calibrate(pairs: list[StereoFrame], board: tuple[int, int], square_mm: float
              ) -> tuple[Calibration, int]:
    """Calibrate each camera, then the pair, then rectify; returns (calibration, pairs used)."""
    if not pairs:
        raise CameraError("no image pairs to calibrate from")
    h, w = pairs[0].left.shape[:2]
    left_pts, right_pts = [], []
    for frame in pairs:
        if frame.left.shape[:2] != (h, w) or frame.right.shape[:2] != (h, w):
            raise CameraError("calibration images differ in size")
        cl, cr = find_board(frame.left, board), find_board(frame.right, board)
        if cl is not None and cr is not None:
            left_pts.append(cl)
            right_pts.append(cr)
    if len(left_pts) < MIN_PAIRS:
        raise CameraError(f"the {board[0]}x{board[1]} chessboard was found in both views of "
                          f"only {len(left_pts)} of {len(pairs)} pairs; need {MIN_PAIRS} "
                          f"(check --board: inner corners, columns x rows)")
    obj = [board_points(board, square_mm)] * len(left_pts)
    # k3 stays 0: webcam lenses are narrow, and a free k3 fits noise at the image corners
    flags = cv2.CALIB_FIX_K3
    _, k1, d1, _, _ = cv2.calibrateCamera(obj, left_pts, (w, h), None, None, flags=flags)
    _, k2, d2, _, _ = cv2.calibrateCamera(obj, right_pts, (w, h), None, None, flags=flags)
    term = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-6)
    rms, k1, d1, k2, d2, r, t, e, f = cv2.stereoCalibrate(
        obj, left_pts, right_pts, k1, d1, k2, d2, (w, h), criteria=term,
        flags=cv2.CALIB_USE_INTRINSIC_GUESS | flags)
    r1, r2, p1, p2, q, _, _ = cv2.stereoRectify(k1, d1, k2, d2, (w, h), r, t,
                                                flags=cv2.CALIB_ZERO_DISPARITY, alpha=0)
    mats = {"K1": k1, "D1": d1, "K2": k2, "D2": d2, "R": r, "T": t, "E": e, "F": f, "R1": r1,
            "R2": r2, "P1": p1, "P2": p2, "Q": q}
    rows = []
    for cl, cr in zip(left_pts, right_pts):
        ul = cv2.undistortPoints(cl, k1, d1, R=r1, P=p1).reshape(-1, 2)
        ur = cv2.undistortPoints(cr, k2, d2, R=r2, P=p2).reshape(-1, 2)
        rows.append(ul[:, 1] - ur[:, 1])
    epi = float(np.sqrt(np.mean(np.concatenate(rows) ** 2)))
    return Calibration((w, h), mats, float(rms), epi), len(left_pts)


class Rectifier:
    """Remaps raw pairs to rectified ones with a calibration's maps."""

    def __init__(self, calib: Calibration) -> None:
        self.calib = calib
        m = calib.mats
        self._maps = [cv2.initUndistortRectifyMap(m[k], m[d], m[r], m[p], calib.size,
                                                  cv2.CV_16SC2)
                      for k, d, r, p in (("K1", "D1", "R1", "P1"), ("K2", "D2", "R2", "P2"))]

    def __call__(self, frame: StereoFrame) -> StereoFrame:
        h, w = frame.left.shape[:2]
        if (w, h) != self.calib.size:
            raise CameraError(f"the calibration is for {self.calib.size[0]}x"
                              f"{self.calib.size[1]}, the frames are {w}x{h}")
        left, right = (cv2.remap(img, m1, m2, cv2.INTER_LINEAR)
                       for img, (m1, m2) in zip((frame.left, frame.right), self._maps))
        return StereoFrame(left, right, frame.t_left, frame.t_right)
