"""Find stereo cameras in sysfs: Minorus by USB id and port path, side-by-side UVC cameras by
their modes, and resolve what a user passes to --camera to /dev/video nodes.

Each /sys/class/video4linux/videoN links (`device`) to its USB interface, whose parent folder is
the USB device: idVendor, idProduct, product and the raw `descriptors` (the modes). That
folder's name is the USB port path (1-1.2.3: bus 1, ports 1, 2, 3), which stays the same across
replugs into the same socket and does not depend on which other cameras are plugged in, unlike
the N of /dev/videoN. The Minoru is a USB hub with one sensor on each of two ports: its port
path is the hub's, and its left sensor is the one on the lower hub port (the start-up
left/right check catches a unit wired the other way).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from host.camera.source import CameraError
from host.camera.uvc_descriptors import Mode, parse_modes

SYSFS = Path("/sys")
MINORU_IDS = {("0ac8", "3410"), ("0ac8", "3420")}
# The modes a Minoru streams as a pair: both sensors are YUYV-only on one USB 2.0 bus
MINORU_MODES = (Mode("YUYV", 320, 240, (30.0,)), Mode("YUYV", 640, 480, (15.0,)))
# a frame holding two views side by side: twice as wide as 4:3 or 16:9 (1280x480, 2560x720)
SBS_ASPECTS = (8 / 3, 32 / 9)


@dataclass(frozen=True)
class VideoNode:
    """One capture node of a USB camera."""

    node: str  # /dev/videoN
    name: str
    port: str  # USB port path of the device, e.g. 1-1.2
    vendor: str
    product: str
    modes: tuple[Mode, ...]

    @property
    def ids(self) -> tuple[str, str]:
        return self.vendor, self.product


@dataclass(frozen=True)
class StereoCamera:
    """A camera as host cameras lists it; spec is what to pass to --camera."""

    kind: str  # minoru, sbs, or mono (a single camera: listed, but not stereo)
    port: str
    nodes: tuple[str, ...]  # minoru: (left, right); sbs and mono: (node,)
    modes: tuple[Mode, ...]
    name: str

    @property
    def spec(self) -> str:
        return f"{self.kind}:{self.port}"

    @property
    def stereo(self) -> bool:
        return self.kind in ("minoru", "sbs")


def _read(path: Path) -> str:
    try:
        return path.read_text().strip()
    except OSError:
        return ""


def _node_number(path: Path) -> int:
    digits = path.name[len("video"):]
    return int(digits) if digits.isdigit() else 1 << 30


def video_nodes(sysfs: Path | None = None) -> list[VideoNode]:
    """The capture nodes of USB cameras (a node with index > 0 is a metadata stream)."""
    sysfs = SYSFS if sysfs is None else sysfs
    nodes = []
    for dev in sorted((sysfs / "class" / "video4linux").glob("video*"), key=_node_number):
        if _read(dev / "index") not in ("", "0"):
            continue
        usb = (dev / "device").resolve().parent
        vendor, product = _read(usb / "idVendor"), _read(usb / "idProduct")
        if not vendor:
            continue  # not a USB camera (a platform or loopback device)
        try:
            modes = tuple(parse_modes((usb / "descriptors").read_bytes()))
        except OSError:
            modes = ()
        nodes.append(VideoNode(f"/dev/{dev.name}", _read(dev / "name") or _read(usb / "product"),
                               usb.name, vendor.lower(), product.lower(), modes))
    return nodes


def sbs_modes(modes: tuple[Mode, ...]) -> tuple[Mode, ...]:
    """The modes whose frame is two views side by side."""
    return tuple(m for m in modes if m.height and any(
        abs(m.width / m.height - a) < 0.01 for a in SBS_ASPECTS))


def _port_key(port: str) -> tuple[int, ...]:
    return tuple(int(p) for p in port.replace("-", ".").split(".") if p.isdigit())


def discover(sysfs: Path | None = None) -> list[StereoCamera]:
    """Every USB camera found, Minorus first, then side-by-side, then single cameras."""
    nodes = video_nodes(sysfs)
    hubs: dict[str, list[VideoNode]] = {}
    found = []
    for n in nodes:
        if n.ids in MINORU_IDS:
            hubs.setdefault(n.port.rsplit(".", 1)[0], []).append(n)
        elif sbs := sbs_modes(n.modes):
            found.append(StereoCamera("sbs", n.port, (n.node,), sbs, n.name))
        else:
            found.append(StereoCamera("mono", n.port, (n.node,), n.modes, n.name))
    minorus = []
    for hub, sensors in hubs.items():
        sensors.sort(key=lambda s: _port_key(s.port))
        kind = "minoru" if len(sensors) == 2 else "minoru-incomplete"
        minorus.append(StereoCamera(kind, hub, tuple(s.node for s in sensors), MINORU_MODES,
                                    "Minoru 3D webcam"))
    key = {"minoru": 0, "minoru-incomplete": 1, "sbs": 2, "mono": 3}
    return sorted(minorus + found, key=lambda c: (key[c.kind], _port_key(c.port)))


def resolve(spec: str, sysfs: Path | None = None) -> StereoCamera:
    """The camera --camera names: minoru, minoru:PORT, sbs, sbs:PORT or sbs:/dev/videoN."""
    kind, _, where = spec.partition(":")
    if kind == "sbs" and where.startswith("/dev/"):
        known = [c for c in discover(sysfs) if where in c.nodes]
        modes = known[0].modes if known else ()
        return StereoCamera("sbs", known[0].port if known else "", (where,), modes,
                            known[0].name if known else where)
    cameras = [c for c in discover(sysfs) if c.kind == kind]
    if where:
        cameras = [c for c in cameras if c.port == where]
    if len(cameras) == 1:
        return cameras[0]
    others = ", ".join(c.spec for c in discover(sysfs) if c.stereo) or "none"
    if not cameras:
        broken = [c for c in discover(sysfs) if c.kind == "minoru-incomplete"]
        hint = (f"; only one sensor of the Minoru at USB {broken[0].port} answers (replug it)"
                if kind == "minoru" and broken else "")
        raise CameraError(f"no camera {spec} found (stereo cameras found: {others}){hint}; "
                          f"host cameras lists them")
    raise CameraError(f"{len(cameras)} cameras match {spec}: say which with one of {others}")
