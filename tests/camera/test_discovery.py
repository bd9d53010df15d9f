"""Camera discovery on fake sysfs trees: the right nodes by USB port, whatever /dev order."""

from __future__ import annotations

from pathlib import Path

import pytest

from host.camera.discovery import discover, resolve
from host.camera.source import CameraError
from host.camera.uvc_descriptors import Mode, parse_modes
from host.cli import main

from .fake_sysfs import LAPTOP, SBS, add_camera, add_minoru, descriptors


def test_descriptor_modes_round_trip_formats_sizes_and_rates() -> None:
    modes = parse_modes(descriptors(SBS))
    assert modes[0] == Mode("MJPG", 2560, 720, (60.0, 30.0))
    assert [(m.fourcc, m.width, m.height) for m in modes] == [
        ("MJPG", 2560, 720), ("MJPG", 1280, 480), ("MJPG", 640, 240), ("YUYV", 2560, 720),
        ("YUYV", 1280, 480)]
    assert str(modes[3]) == "YUYV 2560x720@5"
    assert parse_modes(descriptors(SBS)[:-7]) == modes[:4]  # truncated: the whole ones only


def test_frame_based_formats_and_continuous_intervals_are_read() -> None:
    import struct

    from host.camera.uvc_descriptors import (
        CS_INTERFACE,
        VS_FORMAT_FRAME_BASED,
        VS_FRAME_FRAME_BASED,
    )

    blob = descriptors({})  # the streaming interface, no formats yet
    blob += struct.pack("<BBBBB16s7B", 28, CS_INTERFACE, VS_FORMAT_FRAME_BASED, 1, 1,
                        b"H264" + bytes(12), 0, 1, 0, 0, 0, 0, 1)
    # 1920x1080, continuous from 1/30 s to 1/5 s; bytes per line 0 (compressed)
    blob += struct.pack("<BBBBBHHIIIBI3I", 38, CS_INTERFACE, VS_FRAME_FRAME_BASED, 1, 0, 1920,
                        1080, 0, 0, 333333, 0, 0, 333333, 2000000, 333333)
    assert parse_modes(blob) == [Mode("H264", 1920, 1080, (30.0, 5.0))]


def test_one_minoru_left_is_the_lower_hub_port_not_the_lower_node(tmp_path: Path) -> None:
    add_minoru(tmp_path, "1-1.4", first_node=0)  # the port-2 sensor enumerated first
    (cam,) = discover(tmp_path)
    assert cam.kind == "minoru" and cam.port == "1-1.4"
    assert cam.nodes == ("/dev/video2", "/dev/video0")  # port 1 (left), port 2 (right)
    assert resolve("minoru", tmp_path) == cam == resolve("minoru:1-1.4", tmp_path)


def test_minoru_and_laptop_camera(tmp_path: Path) -> None:
    add_camera(tmp_path, "1-5", ("04f2", "b604"), "Integrated Camera", [0, 1], LAPTOP)
    add_minoru(tmp_path, "2-1", first_node=2)
    cams = discover(tmp_path)
    assert [(c.kind, c.port, c.nodes) for c in cams] == [
        ("minoru", "2-1", ("/dev/video4", "/dev/video2")),
        ("mono", "1-5", ("/dev/video0",))]
    assert resolve("minoru", tmp_path).nodes == ("/dev/video4", "/dev/video2")


def test_two_minorus_are_told_apart_by_port(tmp_path: Path) -> None:
    add_minoru(tmp_path, "1-2", first_node=4)
    add_minoru(tmp_path, "1-1", first_node=0)
    cams = discover(tmp_path)
    assert [(c.port, c.nodes) for c in cams] == [
        ("1-1", ("/dev/video2", "/dev/video0")), ("1-2", ("/dev/video6", "/dev/video4"))]
    with pytest.raises(CameraError, match="2 cameras match minoru: say which with one of "
                                          "minoru:1-1, minoru:1-2"):
        resolve("minoru", tmp_path)
    assert resolve("minoru:1-2", tmp_path).nodes == ("/dev/video6", "/dev/video4")
    with pytest.raises(CameraError, match="no camera minoru:3-1 found"):
        resolve("minoru:3-1", tmp_path)


def test_a_replug_into_the_same_socket_keeps_left_and_right(tmp_path: Path) -> None:
    before, after = tmp_path / "before", tmp_path / "after"
    add_minoru(before, "1-3", first_node=0)
    add_camera(after, "1-5", ("04f2", "b604"), "Integrated Camera", [0, 1], LAPTOP)
    add_minoru(after, "1-3", first_node=6)  # replugged after the laptop camera: new numbers
    left_before = resolve("minoru:1-3", before).nodes[0]
    left_after = resolve("minoru:1-3", after).nodes[0]
    assert (left_before, left_after) == ("/dev/video2", "/dev/video8")
    # both are the sensor on hub port 1
    assert all(Path(r / "class/video4linux" / Path(n).name / "device").resolve().parent.name
               == "1-3.1" for r, n in ((before, left_before), (after, left_after)))


def test_side_by_side_camera_by_its_double_width_modes(tmp_path: Path) -> None:
    add_camera(tmp_path, "3-2", ("32e4", "9750"), "3D USB Camera", [3, 4], SBS)
    add_camera(tmp_path, "1-5", ("04f2", "b604"), "Integrated Camera", [0, 1], LAPTOP)
    sbs, mono = discover(tmp_path)
    assert sbs.kind == "sbs" and sbs.nodes == ("/dev/video3",) and sbs.spec == "sbs:3-2"
    assert [(m.width, m.height) for m in sbs.modes][:3] == [(2560, 720), (1280, 480), (640, 240)]
    assert mono.kind == "mono"  # 1280x720 and 640x480 are one view, not two
    assert resolve("sbs", tmp_path) == sbs
    assert resolve("sbs:/dev/video3", tmp_path).modes == sbs.modes
    with pytest.raises(CameraError, match="no camera minoru found .stereo cameras found: "
                                          "sbs:3-2"):
        resolve("minoru", tmp_path)


def test_one_sensor_of_a_minoru_missing_is_named(tmp_path: Path) -> None:
    add_camera(tmp_path, "1-1.1", ("0ac8", "3410"), "Vimicro", [0], {})
    with pytest.raises(CameraError, match="only one sensor of the Minoru at USB 1-1 answers"):
        resolve("minoru", tmp_path)


def test_host_cameras_lists_kind_nodes_modes_and_the_spec(tmp_path: Path, capsys) -> None:
    add_minoru(tmp_path, "1-1", first_node=0)
    add_camera(tmp_path, "3-2", ("32e4", "9750"), "3D USB Camera", [4, 5], SBS)
    assert main(["cameras", "--sysfs", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "minoru   USB 1-1" in out and "left /dev/video2, right /dev/video0" in out
    assert "--camera minoru:1-1" in out and "YUYV 320x240@30, YUYV 640x480@15" in out
    assert "sbs      USB 3-2" in out and "MJPG 2560x720@60/30" in out
    assert "--camera sbs:3-2  (or sbs:/dev/video4" in out
    (tmp_path / "empty" / "class").mkdir(parents=True)  # a sysfs tree without cameras
    assert main(["cameras", "--sysfs", str(tmp_path / "empty")]) == 0
    assert "no USB cameras" in capsys.readouterr().out
