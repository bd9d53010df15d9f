"""Stereo calibration from chessboard pairs (with badly fitting views rejected), and
rectification maps.

Matrices keep the names of OpenCV's stereo_calib sample: M1 D1 M2 D2 (intrinsics), R T E F
(right camera from left: X_r = R X_l + T, T in the units of --square, mm), R1 R2 P1 P2 Q
(rectification). The Calibration itself and its files: host/camera/calib_files.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

# MATRICES, Calibration and Geometry re-exported for the modules that still import them here
from host.camera.calib_files import MATRICES as MATRICES
from host.camera.calib_files import Calibration as Calibration
from host.camera.geometry import Geometry as Geometry
from host.camera.source import CameraError, StereoFrame

MIN_VIEWS = 15
# a view is rejected when its RMS reprojection error exceeds both of these
OUTLIER_FACTOR = 3.0  # times the median view's error
OUTLIER_FLOOR_PX = 0.3
# the lens model at the image's edge columns (centre row) may differ from its k1 term alone,
# fitted where the boards' corners lie, by this much (px) when the boards do not reach there:
# beyond their reach the higher term is extrapolated, not measured (seed 16's camera 11: the
# right lens fitted k1 -0.052, k2 -0.339 for a true -0.092, 0, 0.55 px there; its rectified
# disparity read 0.7-1 px high at the left columns; the other 31 lenses of seed 16: <= 0.28)
EDGE_EXTRAPOLATION_PX = 0.4


@dataclass(frozen=True)
class View:
    """One chessboard pair in a calibration: used, rejected (a poor fit) or without board."""

    name: str
    status: str  # used, rejected, no board
    error_px: float = math.nan  # RMS reprojection error, worse camera (at rejection time)
    corners: tuple[np.ndarray, np.ndarray] | None = None  # (left, right), (N, 1, 2) px


@dataclass
class CalibrationRun:
    """A calibration with the fate of every view."""

    calibration: Calibration
    views: list[View] = field(default_factory=list)

    @property
    def problem(self) -> str:
        """One line: what the boards do not pin down (edge_problem), "" if none."""
        return self.calibration.problem

    def named(self, status: str) -> list[View]:
        return [v for v in self.views if v.status == status]

    @property
    def used(self) -> int:
        return len(self.named("used"))


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


def _stereo_fit(obj: list[np.ndarray], left: list[np.ndarray], right: list[np.ndarray],
                size: tuple[int, int]) -> tuple[float, dict[str, np.ndarray], np.ndarray]:
    """Each camera alone, then the pair: (rms, mats M1 D1 M2 D2 R T E F, per-view RMS (n, 2))."""
    # k3 stays 0: webcam lenses are narrow, and a free k3 fits noise at the image corners
    flags = cv2.CALIB_FIX_K3
    _, m1, d1, _, _ = cv2.calibrateCamera(obj, left, size, None, None, flags=flags)
    _, m2, d2, _, _ = cv2.calibrateCamera(obj, right, size, None, None, flags=flags)
    term = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-6)
    # cv2's stubs want R and T arrays; OpenCV takes None (allocate them) at run time
    fit = cv2.stereoCalibrateExtended(  # type: ignore[call-overload]
        obj, left, right, m1, d1, m2, d2, size, None, None, criteria=term,
        flags=cv2.CALIB_USE_INTRINSIC_GUESS | flags)
    rms, m1, d1, m2, d2, r, t, e, f, _, _, per_view = fit
    mats = {"M1": m1, "D1": d1, "M2": m2, "D2": d2, "R": r, "T": t, "E": e, "F": f}
    return float(rms), mats, np.asarray(per_view).reshape(-1, 2)


def _rectify(mats: dict[str, np.ndarray], size: tuple[int, int]) -> None:
    r1, r2, p1, p2, q, _, _ = cv2.stereoRectify(
        mats["M1"], mats["D1"], mats["M2"], mats["D2"], size, mats["R"], mats["T"],
        flags=cv2.CALIB_ZERO_DISPARITY, alpha=0)
    mats.update({"R1": r1, "R2": r2, "P1": p1, "P2": p2, "Q": q})


def epipolar_rms(mats: dict[str, np.ndarray], left: list[np.ndarray], right: list[np.ndarray]
                 ) -> float:
    """RMS row difference (px) of matching corners after rectification."""
    rows = []
    for cl, cr in zip(left, right):
        ul = cv2.undistortPoints(cl, mats["M1"], mats["D1"], R=mats["R1"], P=mats["P1"])
        ur = cv2.undistortPoints(cr, mats["M2"], mats["D2"], R=mats["R2"], P=mats["P2"])
        rows.append(ul.reshape(-1, 2)[:, 1] - ur.reshape(-1, 2)[:, 1])
    return float(np.sqrt(np.mean(np.concatenate(rows) ** 2)))


def calibrate(pairs: list[StereoFrame], board: tuple[int, int], square_mm: float,
              names: list[str] | None = None, min_views: int = MIN_VIEWS) -> CalibrationRun:
    """Calibrate each camera, then the pair; drop the worst-fitting view while its error is
    over OUTLIER_FACTOR x the median and OUTLIER_FLOOR_PX, refit; then rectify."""
    if not pairs:
        raise CameraError("no image pairs to calibrate from")
    names = names or [f"pair {i}" for i in range(len(pairs))]
    h, w = pairs[0].left.shape[:2]
    views: dict[int, View] = {}
    found: list[int] = []
    corners: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for i, frame in enumerate(pairs):
        if frame.left.shape[:2] != (h, w) or frame.right.shape[:2] != (h, w):
            raise CameraError(f"{names[i]}: calibration images differ in size")
        cl = find_board(frame.left, board)
        cr = None if cl is None else find_board(frame.right, board)
        if cl is None or cr is None:
            views[i] = View(names[i], "no board")
        else:
            found.append(i)
            corners[i] = (cl, cr)
    need = f"need {min_views} (check --board: inner corners, columns x rows)"
    if len(found) < min_views:
        raise CameraError(f"the {board[0]}x{board[1]} chessboard was found in both views of "
                          f"only {len(found)} of {len(pairs)} pairs; {need}")
    obj = board_points(board, square_mm)
    active = list(found)
    while True:
        rms, mats, per_view = _stereo_fit([obj] * len(active), [corners[i][0] for i in active],
                                          [corners[i][1] for i in active], (w, h))
        err = per_view.max(axis=1)
        worst = int(np.argmax(err))
        if err[worst] <= max(OUTLIER_FACTOR * float(np.median(err)), OUTLIER_FLOOR_PX):
            break
        views[active[worst]] = View(names[active[worst]], "rejected", float(err[worst]),
                                    corners[active[worst]])
        del active[worst]
        if len(active) < min_views:
            raise CameraError(f"only {len(active)} of {len(found)} chessboard pairs fit well "
                              f"({len(found) - len(active)} rejected); {need}")
    for i, e in zip(active, err):
        views[i] = View(names[i], "used", float(e), corners[i])
    _rectify(mats, (w, h))
    epi = epipolar_rms(mats, [corners[i][0] for i in active], [corners[i][1] for i in active])
    problem = edge_problem(mats, ([corners[i][0] for i in active],
                                  [corners[i][1] for i in active]), (w, h))
    calib = Calibration((w, h), mats, rms, epi, problem)
    return CalibrationRun(calib, [views[i] for i in range(len(pairs))])


def edge_extrapolation_px(camera_matrix: np.ndarray, distortion: np.ndarray,
                          corners: np.ndarray, size: tuple[int, int]) -> tuple[float, float, float]:
    """How far the fitted lens model is extrapolated at the image's edge columns: (the gap in
    px there between the model's radial displacement and that of its k1 term alone fitted to
    the model where the boards' corners lie, the corners' largest radius, the edge columns'
    radius; radii normalised by the focal length). Within the corners' reach the two higher
    terms are pinned by the boards; beyond it only the k1 term's growth is measured, and what
    more the model bends there comes from the fit's freedom, not from the lens."""
    coefficients = np.asarray(distortion, np.float64).ravel()
    k1 = float(coefficients[0]) if coefficients.size > 0 else 0.0
    k2 = float(coefficients[1]) if coefficients.size > 1 else 0.0
    k3 = float(coefficients[4]) if coefficients.size > 4 else 0.0
    f, cx, cy = (float(camera_matrix[0, 0]), float(camera_matrix[0, 2]),
                 float(camera_matrix[1, 2]))
    pts = np.asarray(corners, np.float64).reshape(-1, 2)
    r = np.hypot((pts[:, 0] - cx) / f, (pts[:, 1] - cy) / f)
    w = size[0]
    edge = max(cx, w - 1 - cx) / f

    def moved(rr: np.ndarray | float) -> np.ndarray | float:
        return k1 * rr ** 3 + k2 * rr ** 5 + k3 * rr ** 7

    cubes = r ** 3
    k1_alone = float(np.dot(np.asarray(moved(r)), cubes) / max(float(np.dot(cubes, cubes)),
                                                               1e-12))
    gap = f * abs(float(moved(edge)) - k1_alone * edge ** 3)
    return gap, float(r.max()) if r.size else 0.0, edge


def edge_problem(mats: dict[str, np.ndarray], corners: tuple[list[np.ndarray], list[np.ndarray]],
                 size: tuple[int, int], limit_px: float = EDGE_EXTRAPOLATION_PX) -> str:
    """"" when the boards pin the lens models down at the image's edge columns, else one line
    naming the camera and the problem: its boards' corners stop short of the edge columns'
    radius and the model bends beyond them by more than limit_px (edge_extrapolation_px).
    corners: the used views' (left, right) corners."""
    for side, (m, d, pts) in enumerate(((mats["M1"], mats["D1"], corners[0]),
                                        (mats["M2"], mats["D2"], corners[1]))):
        if not pts:
            continue
        gap, reach, edge = edge_extrapolation_px(m, d, np.concatenate(pts), size)
        if reach < edge and gap > limit_px:
            name = ("left", "right")[side]
            return (f"the {name} lens model is not pinned down at the image's edge columns: "
                    f"the boards reach radius {reach:.3f} of {edge:.3f}, and beyond them the "
                    f"fit bends {gap:.2f} px from its k1 term (over {limit_px:.2f}); rectified "
                    f"disparity there may be off by as much: show the board at the {name} "
                    f"view's left and right edges")
    return ""


class Rectifier:
    """Remaps raw pairs to rectified ones with a calibration's maps."""

    def __init__(self, calib: Calibration) -> None:
        self.calib = calib
        m = calib.mats
        self._maps = [cv2.initUndistortRectifyMap(m[k], m[d], m[r], m[p], calib.size,
                                                  cv2.CV_16SC2)
                      for k, d, r, p in (("M1", "D1", "R1", "P1"), ("M2", "D2", "R2", "P2"))]

    def __call__(self, frame: StereoFrame) -> StereoFrame:
        h, w = frame.left.shape[:2]
        if (w, h) != self.calib.size:
            raise CameraError(f"the calibration is for {self.calib.size[0]}x"
                              f"{self.calib.size[1]}, the frames are {w}x{h}")
        left, right = (cv2.remap(img, m1, m2, cv2.INTER_LINEAR)
                       for img, (m1, m2) in zip((frame.left, frame.right), self._maps))
        return StereoFrame(left, right, frame.t_left, frame.t_right)
