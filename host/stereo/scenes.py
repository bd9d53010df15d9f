"""Stereo scenes with ground truth: the shared layout, Middlebury 2001-2014 and the default.

Ground truth is float32 disparity in px with NaN where unknown; masks are boolean regions
(nonocc, all, disc) where the dataset provides them.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import cv2
import numpy as np

from host.errors import HostError
from host.stereo.pfm import read_disparity_pfm

DEFAULT_SCENE = "motorcycle"


@dataclass
class Scene:
    """A rectified pair (uint8, grey or BGR), optional ground truth and evaluation masks."""

    name: str
    left: np.ndarray
    right: np.ndarray
    gt: np.ndarray | None = None
    masks: dict[str, np.ndarray] = field(default_factory=dict)
    max_disparity: float | None = None
    scale: float | None = None  # stored 8-bit ground-truth value per px, where the layout has one

    def num_disparities(self, multiple: int = 16) -> int:
        """Smallest multiple of `multiple` above the largest ground-truth disparity."""
        top = self.max_disparity
        if top is None and self.gt is not None and np.isfinite(self.gt).any():
            top = float(np.nanmax(self.gt))
        top = 64.0 if top is None else top
        return int(np.ceil((top + 1) / multiple) * multiple)


def read_image(path: Path, flags: int = cv2.IMREAD_COLOR) -> np.ndarray:
    if path.is_dir():
        raise HostError(f"{path}: is a folder, not an image")
    if not path.is_file():
        raise HostError(f"{path}: no such file")
    img = cv2.imread(str(path), flags)
    if img is None:
        raise HostError(f"{path}: not a readable image")
    return img


def _gt_png(path: Path, scale: float) -> np.ndarray:
    raw = read_image(path, cv2.IMREAD_UNCHANGED)
    if raw.ndim == 3:
        raw = raw[:, :, 0]
    gt = raw.astype(np.float32) / scale
    gt[raw == 0] = np.nan
    return gt


def _mask(path: Path, value: int = 255) -> np.ndarray:
    raw = read_image(path, cv2.IMREAD_GRAYSCALE)
    return np.asarray(raw == value)


def _check_sizes(name: str, scene: Scene) -> Scene:
    shape = scene.left.shape[:2]
    if scene.right.shape[:2] != shape:
        raise HostError(f"{name}: left and right images differ in size")
    if scene.gt is not None and scene.gt.shape != shape:
        raise HostError(f"{name}: ground truth {scene.gt.shape[1]}x{scene.gt.shape[0]} differs "
                        f"from the images {shape[1]}x{shape[0]}")
    for key, m in scene.masks.items():
        if m.shape != shape:
            raise HostError(f"{name}: mask {key} differs in size from the images")
    return scene


def _load_shared(d: Path) -> Scene:
    try:
        meta = json.loads((d / "meta.json").read_text())
        scale = float(meta["scale"])
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise HostError(f"{d / 'meta.json'}: unreadable or lacks 'scale' ({e})") from None
    top = meta.get("max_disparity")
    if not (np.isfinite(scale) and scale > 0) or not isinstance(meta.get("scene", ""), str) \
            or not (top is None or (isinstance(top, (int, float)) and 0 < top < 1e4)):
        raise HostError(f"{d / 'meta.json'}: needs a positive 'scale', and a text 'scene' and a "
                        f"positive 'max_disparity' where given")
    masks = {k: _mask(d / f"{k}.png") for k in ("nonocc", "all") if (d / f"{k}.png").exists()}
    if (d / "disc.png").exists():
        masks["disc"] = _mask(d / "disc.png")
    return Scene(meta.get("scene", d.name), read_image(d / "left.png"),
                 read_image(d / "right.png"), _gt_png(d / "disp_left.png", scale), masks,
                 meta.get("max_disparity"), scale)


def _load_2003(d: Path, scale: float | None) -> Scene:
    # 2001 and 2003 scenes: im2/im6 with disp2; quarter-size 2003 files use scale 4.
    s = scale or 4.0
    masks = {}
    if (d / "nonocc.png").exists():
        masks["nonocc"] = _mask(d / "nonocc.png")
    return Scene(d.name, read_image(d / "im2.png"), read_image(d / "im6.png"),
                 _gt_png(d / "disp2.png", s), masks, scale=s)


def _load_2005(d: Path, scale: float | None) -> Scene:
    # 2005/2006: full size ~1300-1400 px wide has scale 1, half 2, third 3.
    left = read_image(d / "view1.png")
    s = scale or float(max(1, round(1330 / left.shape[1])))
    return Scene(d.name, left, read_image(d / "view5.png"), _gt_png(d / "disp1.png", s),
                 scale=s)


def _calib(path: Path) -> dict[str, str]:
    out = {}
    for line in path.read_text().splitlines():
        if "=" in line:
            k, v = line.split("=", 1)
            out[k.strip()] = v.strip()
    return out


def _load_2014(d: Path) -> Scene:
    gt_path = d / "disp0GT.pfm" if (d / "disp0GT.pfm").exists() else d / "disp0.pfm"
    gt = read_disparity_pfm(gt_path) if gt_path.exists() else None
    max_d = None
    if (d / "calib.txt").exists():
        ndisp = _calib(d / "calib.txt").get("ndisp")
        try:
            max_d = float(ndisp) - 1 if ndisp else None
        except ValueError:
            raise HostError(f"{d / 'calib.txt'}: ndisp={ndisp!r} is not a number") from None
    masks = {}
    if (d / "mask0nocc.png").exists():
        masks["nonocc"] = _mask(d / "mask0nocc.png")
    return Scene(d.name, read_image(d / "im0.png"), read_image(d / "im1.png"), gt, masks, max_d)


def load_scene(path: str | os.PathLike[str], scale: float | None = None) -> Scene:
    """Load a scene folder in any supported layout; the layout is told by its file names.

    scale divides stored 8-bit ground truth to px where the layout does not say it itself.
    """
    d = Path(path)
    if not d.is_dir():
        raise HostError(f"{d}: no such scene folder")
    if (d / "left.png").exists() and (d / "meta.json").exists():
        scene = _load_shared(d)
    elif (d / "im2.png").exists():
        scene = _load_2003(d, scale)
    elif (d / "view1.png").exists():
        scene = _load_2005(d, scale)
    elif (d / "im0.png").exists():
        scene = _load_2014(d)
    else:
        raise HostError(f"{d}: not a scene folder (expected left.png+meta.json, im2/im6, "
                        "view1/view5 or im0/im1)")
    return _check_sizes(str(d), scene)


def _is_scene(d: Path) -> bool:
    return any((d / f).exists() for f in ("meta.json", "im2.png", "view1.png", "im0.png"))


def load_scenes(paths: list[Path], scale: float | None = None) -> list[Scene]:
    """Scenes from folders; a folder that holds scene folders (like middlebury/) gives them all.

    No paths: the embedded default scene.
    """
    if not paths:
        return [default_scene()]
    scenes = []
    for path in paths:
        if path.is_dir() and not _is_scene(path):
            subs = sorted(d for d in path.iterdir() if d.is_dir() and _is_scene(d))
            if subs:
                scenes += [load_scene(d, scale) for d in subs]
                continue
        scenes.append(load_scene(path, scale))
    return scenes


def default_scene() -> Scene:
    """Middlebury 2014 Motorcycle (quarter size), shipped inside scikit-image's wheel."""
    from skimage import data

    # scikit-image leaves it unannotated: three arrays, the views (RGB) and the disparity
    motorcycle = cast(Callable[[], tuple[np.ndarray, np.ndarray, np.ndarray]],
                      data.stereo_motorcycle)
    left, right, gt = motorcycle()
    gt = gt.astype(np.float32)
    gt[~np.isfinite(gt)] = np.nan
    bgr = [cv2.cvtColor(im, cv2.COLOR_RGB2BGR) for im in (left, right)]
    return Scene(DEFAULT_SCENE, bgr[0], bgr[1], gt, {}, float(np.nanmax(gt)))
