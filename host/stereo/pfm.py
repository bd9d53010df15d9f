"""Portable Float Map reader and writer (Middlebury 2014 ground truth; inf = unknown)."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from host.errors import HostError


def _header(path: Path, kind: bytes, dims: list[bytes], scale_text: bytes
            ) -> tuple[int, int, float]:
    """(width, height, scale) of a PFM header, or one line saying what is wrong with it."""
    if kind not in (b"Pf", b"PF"):
        raise HostError(f"{path}: not a PFM file (it starts {kind[:8]!r}, not Pf or PF)")
    if len(dims) != 2 or not all(d.isdigit() for d in dims) or 0 in map(int, dims):
        shown = b" ".join(dims).decode("latin-1")[:40]
        raise HostError(f"{path}: PFM size {shown!r} is not two positive integers "
                        "(width height)")
    try:
        scale = float(scale_text)
    except ValueError:
        scale = float("nan")
    if not math.isfinite(scale) or scale == 0:
        raise HostError(f"{path}: PFM scale {scale_text.decode('latin-1')[:20]!r} is not a "
                        "finite non-zero number (its sign gives the byte order)")
    return int(dims[0]), int(dims[1]), scale


def read_pfm(path: str | os.PathLike[str]) -> np.ndarray:
    """Read a PFM as float32, top row first (the file stores the bottom row first)."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            kind = f.readline().strip()
            dims = f.readline().split()
            scale_text = f.readline().strip()
            data = f.read()
    except OSError as e:
        raise HostError(f"{path}: cannot read ({e.strerror})") from None
    width, height, scale = _header(path, kind, dims, scale_text)
    channels = 3 if kind == b"PF" else 1
    dtype = "<f4" if scale < 0 else ">f4"
    count = width * height * channels
    if len(data) < 4 * count:
        raise HostError(f"{path}: truncated PFM ({len(data)} bytes of {4 * count})")
    img = np.frombuffer(data, dtype=dtype, count=count).reshape(height, width, channels)
    img = np.flipud(img).astype(np.float32)
    return img[:, :, 0] if channels == 1 else img


def read_disparity_pfm(path: str | os.PathLike[str]) -> np.ndarray:
    """A ground-truth disparity map (px, float32) from a single-channel PFM, NaN where unknown
    (inf, as Middlebury stores it); refuses a colour PFM, negative disparities, and a map with
    no known pixel."""
    disp = read_pfm(path)
    if disp.ndim == 3:
        raise HostError(f"{path}: a colour PFM (PF): ground-truth disparity is single-channel "
                        "(Pf)")
    disp[~np.isfinite(disp)] = np.nan
    if not np.isfinite(disp).any():
        raise HostError(f"{path}: no known disparity (every value is inf or NaN)")
    low = float(np.nanmin(disp))
    if low < 0:
        raise HostError(f"{path}: negative disparities (down to {low:g} px): a left view's "
                        "disparity is >= 0")
    return disp


def write_pfm(path: str | os.PathLike[str], image: np.ndarray) -> None:
    """Write a single-channel float32 PFM, little-endian."""
    img = np.flipud(np.asarray(image, dtype="<f4"))
    with open(path, "wb") as f:
        f.write(b"Pf\n%d %d\n-1.0\n" % (img.shape[1], img.shape[0]))
        f.write(img.tobytes())
