"""A stereo calibration and its files: OpenCV FileStorage YAML (host calibrate --out) and ROS
camera_info YAML (one file per camera, as camera_calibration and stereo_image_proc read and
write them).

Every way a file can be wrong (missing, not text, a YAML syntax error, missing or misshapen
matrices, a bad image_size) is one CameraError line naming the file, never a traceback.
ROS projection matrices carry the baseline in metres; ours in mm (the --square unit).
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml

from host.camera.geometry import Geometry
from host.camera.source import CameraError
from host.files import write_text_atomic

MATRICES = ("M1", "D1", "M2", "D2", "R", "T", "E", "F", "R1", "R2", "P1", "P2", "Q")

# shapes (rows, cols); None: any count (distortion has 4, 5, 8 ... coefficients)
SHAPES: dict[str, tuple[int | None, int | None]] = {
    "M1": (3, 3), "M2": (3, 3), "D1": (None, None), "D2": (None, None), "R": (3, 3),
    "T": (3, 1), "E": (3, 3), "F": (3, 3), "R1": (3, 3), "R2": (3, 3), "P1": (3, 4),
    "P2": (3, 4), "Q": (4, 4)}
OLD_NAMES = {"M1": "K1", "M2": "K2"}  # files written before the sample's names were used
MM_PER_M = 1000.0


@dataclass
class Calibration:
    """A stereo calibration: matrices named as in OpenCV's stereo_calib sample (MATRICES)."""

    size: tuple[int, int]  # (width, height) px
    mats: dict[str, np.ndarray]  # MATRICES
    rms: float  # px, reprojection RMS of the stereo fit (NaN when not known, e.g. from ROS)
    epipolar_rms: float  # px, row difference of rectified corners
    # what the fit's boards did not pin down (calibration.edge_problem; one line), "" when
    # nothing or not known (a file keeps the matrices alone)
    problem: str = ""

    @property
    def baseline_mm(self) -> float:
        return float(np.linalg.norm(self.mats["T"]))

    @property
    def geometry(self) -> Geometry:
        p1, p2 = self.mats["P1"], self.mats["P2"]
        return Geometry(float(p1[0, 0]), abs(float(p2[0, 3] / p2[0, 0])) / 1000.0,
                        float(p1[0, 2]), float(p1[1, 2]))

    def save(self, path: str | os.PathLike[str]) -> None:
        """save_opencv."""
        save_opencv(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Calibration:
        """load_calibration: an OpenCV calibration file, or LEFT.yaml,RIGHT.yaml (ROS
        camera_info)."""
        return load_calibration(str(path))


def save_opencv(calib: Calibration, path: str | os.PathLike[str]) -> None:
    fs = cv2.FileStorage("calib.yml", cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_MEMORY)
    fs.write("image_size", np.array(calib.size, np.int32))
    for k in MATRICES:
        fs.write(k, calib.mats[k])
    fs.write("rms", calib.rms)
    fs.write("epipolar_rms", calib.epipolar_rms)
    fs.write("baseline_mm", calib.baseline_mm)
    write_text_atomic(path, fs.releaseAndGetString())


def _read_text(path: str) -> str:
    p = Path(path)
    if not p.is_file():
        raise CameraError(f"{path}: no such calibration file")
    data = p.read_bytes()
    try:
        if b"\0" in data:
            raise UnicodeDecodeError("utf-8", data, 0, 1, "NUL byte")
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise CameraError(f"{path}: not a text file (a calibration is YAML)") from None


def _syntax_error(path: str, e: BaseException) -> CameraError:
    text = str(e.__cause__ or e)
    line = re.search(r"line (\d+)", text)
    where = f" at line {line.group(1)}" if line else ""
    return CameraError(f"{path}: not readable as OpenCV YAML (a syntax error{where})")


def _image_size(path: str, node: cv2.FileNode) -> tuple[int, int]:
    """image_size as OpenCV writes it (a 2x1 matrix) or as people write it ([640, 480])."""
    if node.isNone():
        raise CameraError(f"{path}: no image_size (not a host calibrate file?)")
    if node.isSeq():
        values = [node.at(i).real() for i in range(node.size())]
    else:
        try:
            m = node.mat()
        except (cv2.error, SystemError):
            m = None
        values = [] if m is None else [float(v) for v in m.ravel()]
    if len(values) != 2 or not all(v >= 1 and v == int(v) for v in values):
        raise CameraError(f"{path}: image_size must be two positive whole numbers, width and "
                          f"height")
    return int(values[0]), int(values[1])


def _matrix(path: str, fs: cv2.FileStorage, key: str) -> np.ndarray | None:
    for name in (key, OLD_NAMES.get(key)):
        if name is None or fs.getNode(name).isNone():
            continue
        try:
            m = fs.getNode(name).mat()
        except (cv2.error, SystemError):
            m = None
        rows, cols = SHAPES[key]
        if m is None or (rows and m.shape != (rows, cols)) or not np.all(np.isfinite(m)):
            shape = f"{rows}x{cols} " if rows else ""
            raise CameraError(f"{path}: {name} is not a finite {shape}matrix")
        return m.astype(np.float64)
    return None


def load_opencv(path: str) -> Calibration:
    text = _read_text(path)
    if not text.strip():
        raise CameraError(f"{path}: the file is empty")
    if "camera_matrix" in text and "projection_matrix" in text:
        raise CameraError(f"{path} is one camera's ROS camera_info: pass both, "
                          f"--calib LEFT.yaml,RIGHT.yaml")
    try:
        fs = cv2.FileStorage(text, cv2.FILE_STORAGE_READ | cv2.FILE_STORAGE_MEMORY)
        ok = fs.isOpened()
    except (cv2.error, SystemError) as e:
        raise _syntax_error(path, e) from None
    if not ok:
        raise CameraError(f"{path}: not an OpenCV calibration file")
    if not fs.root().isMap():
        raise CameraError(f"{path}: not an OpenCV calibration file (its top level is not a map "
                          "of names to matrices)")
    size = _image_size(path, fs.getNode("image_size"))
    mats = {k: _matrix(path, fs, k) for k in MATRICES}
    missing = [k for k, v in mats.items() if v is None]
    if missing:
        raise CameraError(f"{path}: missing {', '.join(missing)} (not a host calibrate file?)")
    rms = fs.getNode("rms").real() if not fs.getNode("rms").isNone() else math.nan
    epi = (fs.getNode("epipolar_rms").real() if not fs.getNode("epipolar_rms").isNone()
           else math.nan)
    return Calibration(size, {k: v for k, v in mats.items() if v is not None}, rms, epi)


def load_calibration(spec: str) -> Calibration:
    """--calib: an OpenCV file, or LEFT.yaml,RIGHT.yaml (ROS camera_info)."""
    if "," in spec:
        parts = spec.split(",")
        if len(parts) != 2 or not all(parts):
            raise CameraError(f"--calib {spec}: give one OpenCV file, or two ROS camera_info "
                              f"files as LEFT.yaml,RIGHT.yaml (got {len(parts)} names)")
        return load_ros(*parts)
    return load_opencv(spec)


# ---- ROS camera_info ----------------------------------------------------------------------

def _ros_matrix(m: np.ndarray) -> str:
    rows, cols = m.shape
    data = ", ".join(repr(float(v)) for v in m.ravel())
    return f"\n  rows: {rows}\n  cols: {cols}\n  data: [{data}]"


def camera_info(calib: Calibration, side: str) -> dict[str, Any]:
    """One camera's camera_info fields (side: left or right): width, height, distortion_model
    and K, D, R, P as arrays, P's Tx in metres as ROS has it. The one source of both the --ros
    files and the recordings' sensor_msgs/CameraInfo."""
    i = "1" if side == "left" else "2"
    m = calib.mats
    p = np.asarray(m["P" + i], np.float64).copy()
    p[:, 3] /= MM_PER_M  # ROS: Tx = -fx' * baseline in metres
    d = np.asarray(m["D" + i], np.float64).reshape(1, -1)
    return {"width": calib.size[0], "height": calib.size[1],
            "distortion_model": "plumb_bob" if d.size <= 5 else "rational_polynomial",
            "K": np.asarray(m["M" + i], np.float64), "D": d,
            "R": np.asarray(m["R" + i], np.float64), "P": p}


def ros_text(calib: Calibration, side: str) -> str:
    """One camera's camera_info YAML (side: left or right)."""
    info = camera_info(calib, side)
    return (f"image_width: {info['width']}\nimage_height: {info['height']}\n"
            f"camera_name: {side}\n"
            f"camera_matrix:{_ros_matrix(info['K'])}\n"
            f"distortion_model: {info['distortion_model']}\n"
            f"distortion_coefficients:{_ros_matrix(info['D'])}\n"
            f"rectification_matrix:{_ros_matrix(info['R'])}\n"
            f"projection_matrix:{_ros_matrix(info['P'])}\n")


def ideal_calibration(geometry: Geometry, size: tuple[int, int]) -> Calibration:
    """The calibration of an already rectified pair of the given geometry (no distortion, no
    rotation): what a recording's CameraInfo says when no --calib was given."""
    f = geometry.focal_px
    k = np.array([[f, 0, geometry.cx], [0, f, geometry.cy], [0, 0, 1]], np.float64)
    p1 = np.hstack([k, np.zeros((3, 1))])
    p2 = p1.copy()
    p2[0, 3] = -f * geometry.baseline_m
    left = {"K": k, "D": np.zeros((1, 5)), "R": np.eye(3), "P": p1}
    return from_camera_info(size, left, {**left, "P": p2})


def is_ideal(calib: Calibration) -> bool:
    """Whether rectifying with calib changes nothing (no distortion, no rotation, P = K)."""
    m = calib.mats
    return all(not np.any(m["D" + i]) and np.allclose(m["R" + i], np.eye(3))
               and np.allclose(m["P" + i][:, :3], m["M" + i]) for i in "12")


def save_ros(calib: Calibration, folder: Path) -> tuple[Path, Path]:
    """folder/left.yaml and folder/right.yaml."""
    paths = (folder / "left.yaml", folder / "right.yaml")
    for side, path in zip(("left", "right"), paths):
        write_text_atomic(path, ros_text(calib, side))
    return paths


def _ros_field(path: str, info: dict[str, Any], key: str, shape: tuple[int, int] | None
               ) -> np.ndarray:
    node: Any = info.get(key)
    try:
        data = np.array(node["data"], np.float64)
        rows, cols = int(node["rows"]), int(node["cols"])
        m = data.reshape(rows, cols)
    except (TypeError, KeyError, ValueError):
        raise CameraError(f"{path}: {key} must have rows, cols and data (ROS camera_info)"
                          ) from None
    if (shape and m.shape != shape) or not np.all(np.isfinite(m)):
        dims = f"{shape[0]}x{shape[1]} " if shape else ""
        raise CameraError(f"{path}: {key} is not a finite {dims}matrix")
    return m


ROS_MODELS = ("plumb_bob", "rational_polynomial")  # what ros_text writes, cv2's model


def _read_ros(path: str) -> tuple[tuple[int, int], dict[str, np.ndarray]]:
    text = _read_text(path)
    if text.startswith("%YAML:1.0") or "!!opencv-matrix" in text:  # OpenCV's FileStorage
        raise CameraError(f"{path} is an OpenCV stereo calibration (host calibrate --out): pass "
                          f"it alone as --calib {path}; LEFT,RIGHT takes two ROS camera_info "
                          "files")
    try:
        info = yaml.safe_load(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise CameraError(f"{path}: not readable as YAML (a syntax error{where})") from None
    if not isinstance(info, dict) or "camera_matrix" not in info:
        raise CameraError(f"{path}: not a ROS camera_info file (no camera_matrix)")
    model = info.get("distortion_model", "plumb_bob")
    if model not in ROS_MODELS:
        raise CameraError(f"{path}: distortion_model {model!r} is not supported (only "
                          f"{' and '.join(ROS_MODELS)}, the models OpenCV's stereo calibration "
                          "fits)")
    try:
        size = (int(info["image_width"]), int(info["image_height"]))
    except (KeyError, TypeError, ValueError):
        raise CameraError(f"{path}: image_width and image_height must be whole numbers"
                          ) from None
    return size, {"M": _ros_field(path, info, "camera_matrix", (3, 3)),
                  "D": _ros_field(path, info, "distortion_coefficients", None).reshape(1, -1),
                  "R": _ros_field(path, info, "rectification_matrix", (3, 3)),
                  "P": _ros_field(path, info, "projection_matrix", (3, 4))}


def load_ros(left_path: str, right_path: str) -> Calibration:
    """A stereo calibration from the left and right camera_info files (from_camera_info)."""
    (size, left), (size_r, right) = _read_ros(left_path), _read_ros(right_path)
    if size != size_r:
        raise CameraError(f"{left_path} is for {size[0]}x{size[1]}, {right_path} for "
                          f"{size_r[0]}x{size_r[1]}")
    return from_camera_info(size, left, right, right_path)


def from_camera_info(size: tuple[int, int], left: dict[str, Any], right: dict[str, Any],
                     right_name: str = "the right camera_info") -> Calibration:
    """A stereo calibration from the two cameras' K (or M), D, R, P (Tx in metres): the
    rectification is theirs; R, T, E, F and Q are rebuilt from it (R = R2^T R1, T = R2^T t,
    t the rectified right camera's offset)."""
    left = {"M": left.get("M", left.get("K")), **left}
    right = {"M": right.get("M", right.get("K")), **right}
    p1, p2 = np.array(left["P"], np.float64), np.array(right["P"], np.float64)
    p1[:, 3] *= MM_PER_M
    p2[:, 3] *= MM_PER_M
    if p2[0, 3] == 0:
        raise CameraError(f"{right_name}: projection_matrix has no baseline (Tx = 0): is it "
                          f"the right camera's?")
    tx, ty = p2[0, 3] / p2[0, 0], p2[1, 3] / p2[1, 1]
    r = right["R"].T @ left["R"]
    t = right["R"].T @ np.array([[tx], [ty], [0.0]])
    tx_hat = np.array([[0, -t[2, 0], t[1, 0]], [t[2, 0], 0, -t[0, 0]], [-t[1, 0], t[0, 0], 0]])
    e = tx_hat @ r
    f = np.linalg.inv(right["M"]).T @ e @ np.linalg.inv(left["M"])
    f = f / (f[2, 2] if f[2, 2] else np.abs(f).max())  # F[2, 2] is 0 for a rectified pair
    q = np.array([[1, 0, 0, -p1[0, 2]], [0, 1, 0, -p1[1, 2]], [0, 0, 0, p1[0, 0]],
                  [0, 0, -1 / tx, (p1[0, 2] - p2[0, 2]) / tx]])
    mats = {"M1": left["M"], "D1": left["D"], "M2": right["M"], "D2": right["D"], "R": r,
            "T": t, "E": e, "F": f, "R1": left["R"], "R2": right["R"], "P1": p1,
            "P2": p2, "Q": q}
    return Calibration(size, mats, math.nan, math.nan)
