"""host cameras: list the cameras found (kind, nodes, modes) and what to pass to --camera."""

from __future__ import annotations

import argparse
from pathlib import Path

from host.camera.discovery import SYSFS, discover
from host.errors import HostError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--sysfs", type=Path, default=SYSFS, help="sysfs root to read (default /sys)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if not args.sysfs.is_dir():
        raise HostError(f"--sysfs {args.sysfs}: no such folder")
    if args.sysfs != SYSFS and not (args.sysfs / "class").is_dir():
        raise HostError(f"--sysfs {args.sysfs}: not a sysfs tree (no class/ in it)")
    cameras = discover(args.sysfs)
    if not cameras:
        print(f"no USB cameras under {args.sysfs}/class/video4linux")
        return 0
    for c in cameras:
        nodes = (f"left {c.nodes[0]}, right {c.nodes[1]}" if c.kind == "minoru"
                 else ", ".join(c.nodes))
        print(f"{c.kind:<8} USB {c.port:<10} {c.name}: {nodes}")
        if c.modes:
            print(f"         modes: {', '.join(str(m) for m in c.modes)}")
        if c.kind == "minoru":
            print(f"         --camera {c.spec}")
        elif c.kind == "sbs":
            print(f"         --camera {c.spec}  (or sbs:{c.nodes[0]}; each view is half the "
                  f"width)")
        elif c.kind == "minoru-incomplete":
            print("         only one of the Minoru's two sensors answers: replug it")
        else:
            print("         a single camera: not stereo")
    return 0
