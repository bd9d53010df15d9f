"""Portable Float Map reader and writer (Middlebury 2014 ground truth; inf = unknown)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from host.errors import HostError


def read_pfm(path: str | os.PathLike[str]) -> np.ndarray:
    """Read a PFM as float32, top row first (the file stores the bottom row first)."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            kind = f.readline().strip()
            dims = f.readline().split()
            scale = float(f.readline().strip())
            data = f.read()
    except OSError as e:
        raise HostError(f"{path}: cannot read ({e.strerror})") from None
    except ValueError:
        raise HostError(f"{path}: not a PFM file (bad header)") from None
    if kind not in (b"Pf", b"PF") or len(dims) != 2:
        raise HostError(f"{path}: not a PFM file (bad header)")
    width, height = int(dims[0]), int(dims[1])
    channels = 3 if kind == b"PF" else 1
    dtype = "<f4" if scale < 0 else ">f4"
    count = width * height * channels
    if len(data) < 4 * count:
        raise HostError(f"{path}: truncated PFM ({len(data)} bytes of {4 * count})")
    img = np.frombuffer(data, dtype=dtype, count=count).reshape(height, width, channels)
    img = np.flipud(img).astype(np.float32)
    return img[:, :, 0] if channels == 1 else img


def write_pfm(path: str | os.PathLike[str], image: np.ndarray) -> None:
    """Write a single-channel float32 PFM, little-endian."""
    img = np.flipud(np.asarray(image, dtype="<f4"))
    with open(path, "wb") as f:
        f.write(b"Pf\n%d %d\n-1.0\n" % (img.shape[1], img.shape[0]))
        f.write(img.tobytes())
