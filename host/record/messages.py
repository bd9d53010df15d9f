"""ROS 2 messages of standard types (rosbags' typestore) for what a run saw and did: pure
functions from arrays, calibrations and snapshots to message objects."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

from host.camera.calib_files import Calibration
from host.camera.calib_files import camera_info as camera_info_fields
from host.camera.geometry import Geometry

STORE = get_typestore(Stores.ROS2_HUMBLE)
T = STORE.types

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
DISPARITY = "stereo_msgs/msg/DisparityImage"
POINT = "geometry_msgs/msg/PointStamped"
IMAGE_MARKER = "visualization_msgs/msg/ImageMarker"
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"

LEFT_FRAME, RIGHT_FRAME = "stereo_left_optical", "stereo_right_optical"
# topic -> type: every topic a recording may hold (replay reads the first four)
TOPICS = {
    "/stereo/left/image_raw": IMAGE,
    "/stereo/right/image_raw": IMAGE,
    "/stereo/left/camera_info": CAMERA_INFO,
    "/stereo/right/camera_info": CAMERA_INFO,
    "/stereo/disparity": DISPARITY,
    "/servo/marker": POINT,  # the robot's marker, in the left camera's frame (m)
    "/servo/target": POINT,  # the target object's centre at the target depth (m)
    "/servo/overlay": IMAGE_MARKER,  # marker circle and target box on the left image
    "/diagnostics": DIAGNOSTICS,  # servo phase and stop reason, drive, link, robot, recorder
}
DELTA_D = 1.0 / 16  # the matchers' disparity step (px)
OK, WARN, ERROR = 0, 1, 2  # diagnostic_msgs/DiagnosticStatus levels


def stamp(ns: int) -> Any:
    return T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def header(ns: int, frame: str) -> Any:
    return T["std_msgs/msg/Header"](stamp=stamp(ns), frame_id=frame)


def image(img: np.ndarray, ns: int, frame: str) -> Any:
    """sensor_msgs/Image of a uint8 BGR (bgr8) or grey (mono8) image, or a float32 map
    (32FC1)."""
    img = np.ascontiguousarray(img)
    h, w = img.shape[:2]
    if img.dtype == np.float32 and img.ndim == 2:
        encoding = "32FC1"
    elif img.dtype == np.uint8 and img.ndim == 2:
        encoding = "mono8"
    elif img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3:
        encoding = "bgr8"
    else:
        raise ValueError(f"no ROS image encoding for {img.dtype} {img.shape}")
    return T[IMAGE](header=header(ns, frame), height=h, width=w, encoding=encoding,
                    is_bigendian=0, step=img.strides[0], data=img.reshape(-1).view(np.uint8))


def decode_image(msg: Any) -> np.ndarray:
    """The array a sensor_msgs/Image holds (bgr8, rgb8, mono8, 32FC1)."""
    data = np.frombuffer(bytes(msg.data) if not isinstance(msg.data, np.ndarray) else msg.data,
                         np.uint8)
    h, w, step = msg.height, msg.width, msg.step
    rows = data[:h * step].reshape(h, step)
    if msg.encoding == "32FC1":
        return rows[:, :w * 4].copy().view(np.float32).reshape(h, w)
    if msg.encoding == "mono8":
        return rows[:, :w].copy()
    if msg.encoding in ("bgr8", "rgb8"):
        out = rows[:, :w * 3].reshape(h, w, 3)
        return (out[:, :, ::-1] if msg.encoding == "rgb8" else out).copy()
    raise ValueError(f"image encoding {msg.encoding!r} is not read (bgr8, rgb8, mono8, 32FC1)")


def camera_info(calib: Calibration, side: str, ns: int) -> Any:
    """sensor_msgs/CameraInfo of one camera, from the fields the --ros files are written from."""
    f = camera_info_fields(calib, side)
    roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0,
                                                do_rectify=False)
    return T[CAMERA_INFO](header=header(ns, LEFT_FRAME if side == "left" else RIGHT_FRAME),
                          height=f["height"], width=f["width"],
                          distortion_model=f["distortion_model"], d=f["D"].ravel().copy(),
                          k=f["K"].ravel().copy(), r=f["R"].ravel().copy(),
                          p=f["P"].ravel().copy(), binning_x=0, binning_y=0, roi=roi)


def info_fields(msg: Any) -> dict[str, Any]:
    """The K, D, R, P (and size) a sensor_msgs/CameraInfo holds, as calib_files names them."""
    return {"width": int(msg.width), "height": int(msg.height),
            "K": np.asarray(msg.k, np.float64).reshape(3, 3),
            "D": np.asarray(msg.d, np.float64).reshape(1, -1),
            "R": np.asarray(msg.r, np.float64).reshape(3, 3),
            "P": np.asarray(msg.p, np.float64).reshape(3, 4)}


def disparity(band: np.ndarray, y0: int, shape: tuple[int, int], geometry: Geometry,
              search: tuple[float, float], ns: int) -> Any:
    """stereo_msgs/DisparityImage of the full image: the rows computed (y0.. of band) with
    invalid pixels, and every row not computed, below min_disparity as the message says."""
    lo, hi = search
    invalid = np.float32(lo - 1)
    full = np.full(shape, invalid, np.float32)
    rows = band[:, :shape[1]]
    full[y0:y0 + rows.shape[0]] = np.where(np.isfinite(rows), rows, invalid)
    window = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=y0,
                                                   height=rows.shape[0], width=shape[1],
                                                   do_rectify=False)
    return T[DISPARITY](header=header(ns, LEFT_FRAME), image=image(full, ns, LEFT_FRAME),
                        f=geometry.focal_px, t=geometry.baseline_m, valid_window=window,
                        min_disparity=float(lo), max_disparity=float(hi), delta_d=DELTA_D)


def point(x: float, y: float, z: float, ns: int) -> Any:
    return T[POINT](header=header(ns, LEFT_FRAME),
                    point=T["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=float(z)))


def at_disparity(geometry: Geometry, u: float, v: float, d: float) -> tuple[float, float, float]:
    """The point (m, left camera optical frame: x right, y down, z ahead) seen at pixel (u, v)
    with disparity d."""
    b = geometry.baseline_m
    return b * (u - geometry.cx) / d, b * (v - geometry.cy) / d, geometry.focal_px * b / d


def _colour(r: float, g: float, b: float) -> Any:
    return T["std_msgs/msg/ColorRGBA"](r=r, g=g, b=b, a=1.0)


def _pt(x: float, y: float) -> Any:
    return T["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0)


def image_marker(ns: int, ident: int, kind: str, **kw: Any) -> Any:
    """visualization_msgs/ImageMarker on the left image: kind "circle" (u, v, radius) or
    "box" (x, y, w, h); "delete" removes marker ident."""
    base = dict(header=header(ns, LEFT_FRAME), ns="servo", id=ident, type=0, action=0,
                position=_pt(0, 0), scale=1.0, outline_color=_colour(0, 0, 0), filled=0,
                fill_color=_colour(0, 0, 0),
                lifetime=T["builtin_interfaces/msg/Duration"](sec=0, nanosec=0), points=[],
                outline_colors=[])
    if kind == "circle":
        base.update(type=0, position=_pt(kw["u"], kw["v"]), scale=float(kw["radius"]),
                    outline_color=_colour(0.0, 1.0, 0.3))
    elif kind == "box":
        x, y, w, h = kw["x"], kw["y"], kw["w"], kw["h"]
        base.update(type=1, outline_color=_colour(1.0, 0.8, 0.0), scale=2.0,
                    points=[_pt(x, y), _pt(x + w, y), _pt(x + w, y + h), _pt(x, y + h),
                            _pt(x, y)])
    else:
        base.update(action=1)  # REMOVE
    return T[IMAGE_MARKER](**base)


def status(name: str, level: int, message: str, values: dict[str, Any]) -> Any:
    """One diagnostic_msgs/DiagnosticStatus; values as text (NaN as "nan")."""
    kv = T["diagnostic_msgs/msg/KeyValue"]
    return T["diagnostic_msgs/msg/DiagnosticStatus"](
        level=level, name=name, message=message, hardware_id="stereo-servo",
        values=[kv(key=k, value=_text(v)) for k, v in values.items()])


def _text(v: Any) -> str:
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.6g}"
    return str(v)


def diagnostics(ns: int, statuses: list[Any]) -> Any:
    return T[DIAGNOSTICS](header=header(ns, ""), status=statuses)


def serialize(msg: Any) -> bytes:
    return bytes(STORE.serialize_cdr(msg, msg.__msgtype__))


def deserialize(data: bytes | memoryview, msgtype: str) -> Any:
    return STORE.deserialize_cdr(data, msgtype)


def msgdef(msgtype: str) -> str:
    """The message definition (its dependencies appended) that rosbag2 stores in MCAP."""
    return STORE.generate_msgdef(msgtype, ros_version=2)[0]
