"""Recorded stereo: a folder of image pairs (left_*.png with right_*.png, as host capture writes
them) or two video files."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2

from host.camera.manifest import read_manifest
from host.camera.source import CameraError, StereoFrame, StereoSource
from host.stereo.scenes import read_image

IMAGE_TYPES = (".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff")


def image_pairs(folder: Path) -> list[tuple[Path, Path]]:
    """(left, right) files of a folder: left_X.ext goes with right_X.ext."""
    if not folder.is_dir():
        raise CameraError(f"{folder}: no such folder")
    pairs = []
    for left in sorted(folder.glob("left_*")):
        if left.suffix.lower() not in IMAGE_TYPES:
            continue
        right = left.with_name("right_" + left.name[5:])
        if not right.exists():
            raise CameraError(f"{left}: no matching {right.name}")
        pairs.append((left, right))
    if not pairs:
        raise CameraError(f"{folder}: no left_*/right_* image pairs")
    return pairs


class ReplaySource(StereoSource):
    """Pairs from a folder (with the capture times of its manifest.json, else at fps) or from
    two videos (their own timestamps)."""

    def __init__(self, path: Path, fps: float = 30.0) -> None:
        self.path, self.fps = path, fps
        self._index = 0
        self._videos = None
        self.manifest = None
        if path.is_dir() and (path / "left.avi").exists() or str(path).count(",") == 1:
            files = ([path / "left.avi", path / "right.avi"] if path.is_dir()
                     else [Path(p) for p in str(path).split(",")])
            self._videos = [cv2.VideoCapture(str(f)) for f in files]
            for f, v in zip(files, self._videos):
                if not v.isOpened():
                    raise CameraError(f"{f}: cannot open the video")
        else:
            self._pairs = image_pairs(path)
            self.manifest = read_manifest(path)

    def _read(self) -> StereoFrame | None:
        if self._videos is not None:
            out = []
            for v in self._videos:
                ok, img = v.read()
                if not ok:
                    return None
                out.append((img, v.get(cv2.CAP_PROP_POS_MSEC) / 1000))
            return StereoFrame(out[0][0], out[1][0], out[0][1], out[1][1])
        if self._index >= len(self._pairs):
            return None
        left, right = self._pairs[self._index]
        t = self._index / self.fps
        t_left, t_right = self.manifest["times"].get(left.name, (t, t)) if self.manifest else (t, t)
        self._index += 1
        return StereoFrame(read_image(left), read_image(right), t_left, t_right)

    def describe(self) -> dict[str, Any]:
        recorded = self.manifest["camera"] if self.manifest else None
        return {"camera": f"replay:{self.path}", "kind": "replay", "recorded_from": recorded}

    def close(self) -> None:
        for v in self._videos or []:
            v.release()
