"""The console scripts' entry point (host, stereo-servo, python -m stereo_servo): checks that
`host` is the package installed beside it, not a stray host.py in the working folder."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path


def shadowing() -> str | None:
    """What is wrong when `import host` would not load the host package installed beside this
    one (a host.py or host/ earlier on sys.path), else None."""
    spec = importlib.util.find_spec("host")
    mine = Path(__file__).resolve().parent.parent / "host"
    origin = Path(spec.origin).resolve() if spec and spec.origin else None
    if origin is not None and origin.parent == mine:
        return None
    found = origin or "nothing"
    return (f"{found} shadows the stereo-servo package {mine} (it comes first on the module "
            f"path): rename it, or run from another folder")


def main() -> int:
    """Run the CLI (host.cli.main), or one line and exit status 2 when host is shadowed; Ctrl-C
    while host.cli imports (before it handles Ctrl-C itself) is one line and 130 too."""
    name = Path(sys.argv[0]).name if Path(sys.argv[0]).name in NAMES else "stereo-servo"
    problem = shadowing()
    if problem:
        print(f"{name}: error: {problem}", file=sys.stderr)
        return 2
    try:
        from host.cli import main as cli_main

        return cli_main()  # which handles Ctrl-C itself once the command runs
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr)
        return 130


NAMES = ("host", "stereo-servo")
