"""Fake sysfs trees laid out as the kernel lays them out: USB devices with their descriptors,
video4linux nodes linked to their USB interface, for camera discovery tests."""

from __future__ import annotations

import os
import struct
from pathlib import Path

from host.camera.uvc_descriptors import (
    CS_INTERFACE,
    INTERFACE,
    VIDEO_CLASS,
    VIDEO_STREAMING,
    VS_FORMAT_MJPEG,
    VS_FORMAT_UNCOMPRESSED,
    VS_FRAME_MJPEG,
    VS_FRAME_UNCOMPRESSED,
)

Frames = list[tuple[int, int, tuple[float, ...]]]
MINORU_SENSOR = {"YUYV": [(640, 480, (30.0, 15.0)), (320, 240, (30.0, 15.0)),
                          (160, 120, (30.0,))]}
LAPTOP = {"YUYV": [(640, 480, (30.0,)), (1280, 720, (10.0,))],
          "MJPG": [(1280, 720, (30.0,)), (640, 480, (30.0,))]}
SBS = {"MJPG": [(2560, 720, (60.0, 30.0)), (1280, 480, (60.0, 30.0)), (640, 240, (60.0,))],
       "YUYV": [(2560, 720, (5.0,)), (1280, 480, (15.0,))]}


def descriptors(formats: dict[str, Frames]) -> bytes:
    """A device's descriptor blob with one VideoStreaming interface offering these formats."""
    out = bytearray(18)  # the device descriptor, which parse_modes skips
    out[0], out[1] = 18, 1
    out += struct.pack("<BBBBBBBBB", 9, INTERFACE, 1, 0, 0, VIDEO_CLASS, VIDEO_STREAMING, 0, 0)
    for index, (fourcc, frames) in enumerate(formats.items(), 1):
        if fourcc == "MJPG":
            out += struct.pack("<11B", 11, CS_INTERFACE, VS_FORMAT_MJPEG, index, len(frames),
                               0, 1, 0, 0, 0, 0)
        else:
            guid = b"YUY2" + bytes(12)
            out += struct.pack("<BBBBB16s6B", 27, CS_INTERFACE, VS_FORMAT_UNCOMPRESSED, index,
                               len(frames), guid, 16, 1, 0, 0, 0, 0)
        sub = VS_FRAME_MJPEG if fourcc == "MJPG" else VS_FRAME_UNCOMPRESSED
        for j, (w, h, rates) in enumerate(frames, 1):
            iv = [round(1e7 / r) for r in rates]
            out += struct.pack(f"<BBBBBHHIIIIB{len(iv)}I", 26 + 4 * len(iv), CS_INTERFACE, sub,
                               j, 0, w, h, 0, 0, w * h * 2, iv[0], len(iv), *iv)
    return bytes(out)


def add_camera(root: Path, port: str, ids: tuple[str, str], name: str, nodes: list[int],
               formats: dict[str, Frames]) -> None:
    """A USB camera at port (e.g. 1-1.2) whose capture node is video<nodes[0]>; further
    numbers are its metadata nodes (index 1, 2 ...)."""
    bus, chain = port.split("-")
    usb = root / "devices" / "pci0000:00" / "0000:00:14.0" / f"usb{bus}"
    parts = chain.split(".")
    for k in range(1, len(parts) + 1):
        usb = usb / f"{bus}-{'.'.join(parts[:k])}"
    iface = usb / f"{port}:1.0"
    iface.mkdir(parents=True)
    (usb / "idVendor").write_text(ids[0] + "\n")
    (usb / "idProduct").write_text(ids[1] + "\n")
    (usb / "product").write_text(name + "\n")
    (usb / "descriptors").write_bytes(descriptors(formats))
    classes = root / "class" / "video4linux"
    classes.mkdir(parents=True, exist_ok=True)
    for index, n in enumerate(nodes):
        dev = iface / "video4linux" / f"video{n}"
        dev.mkdir(parents=True)
        (dev / "name").write_text(name + "\n")
        (dev / "index").write_text(f"{index}\n")
        os.symlink(os.path.relpath(iface, dev), dev / "device")
        os.symlink(os.path.relpath(dev, classes), classes / f"video{n}")


def add_minoru(root: Path, hub_port: str, first_node: int) -> None:
    """A Minoru on hub_port: its sensors on the hub's ports 1 and 2, two nodes each, the sensor
    on port 2 enumerated first (so /dev/video order is the reverse of left/right)."""
    add_camera(root, f"{hub_port}.2", ("0ac8", "3420"), "Venus USB2.0 Camera",
               [first_node, first_node + 1], MINORU_SENSOR)
    add_camera(root, f"{hub_port}.1", ("0ac8", "3410"), "Vimicro USB2.0 PC Camera",
               [first_node + 2, first_node + 3], MINORU_SENSOR)
