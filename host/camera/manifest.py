"""manifest.json beside captured pairs: which camera, in which mode, and when each view was
taken, so a replay knows what it replays (and keeps the capture times)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from host.camera.source import CameraError
from host.files import write_text_atomic

NAME = "manifest.json"
CLOCK = "seconds on the capture machine's monotonic clock (time.monotonic)"


def write_manifest(folder: Path, camera: dict[str, Any], pairs: list[dict[str, Any]]) -> None:
    """Rewritten whole after every pair, atomically: an interrupted capture leaves a manifest
    that lists exactly the pairs on disk."""
    doc = {"camera": camera, "clock": CLOCK, "pairs": pairs}
    write_text_atomic(folder / NAME, json.dumps(doc, indent=1) + "\n")


def read_manifest(folder: Path) -> dict[str, Any] | None:
    """The folder's manifest, or None when it has none."""
    path = folder / NAME
    if not path.exists():
        return None
    try:
        doc = json.loads(path.read_text())
        pairs = {p["left"]: (float(p["t_left"]), float(p["t_right"])) for p in doc["pairs"]}
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError) as e:
        raise CameraError(f"{path}: not a capture manifest ({type(e).__name__}: {e})"
                          .splitlines()[0]) from None
    return {"camera": doc.get("camera", {}), "times": pairs}
