"""Atomic writes: a temporary file in the same folder, then a rename, so a reader or an
interrupted run never sees a half-written result."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import cv2
import numpy as np

from host.errors import HostError


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise HostError(f"{path}: folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as e:
        Path(tmp).unlink(missing_ok=True)
        raise HostError(f"{path}: cannot write ({e.strerror})") from None


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    write_bytes_atomic(path, text.encode())


def write_image_atomic(path: str | os.PathLike[str], image: np.ndarray) -> None:
    ext = Path(path).suffix or ".png"
    ok, buf = cv2.imencode(ext, image)
    if not ok:
        raise HostError(f"{path}: cannot encode an image as {ext}")
    write_bytes_atomic(path, buf.tobytes())


def write_npy_atomic(path: str | os.PathLike[str], array: np.ndarray) -> None:
    import io

    buf = io.BytesIO()
    np.save(buf, array)
    write_bytes_atomic(path, buf.getvalue())
