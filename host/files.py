"""The one output layer: outputs checked before any work, written atomically with the umask's
mode, and (inside all_or_nothing) committed together or not at all.

    out = check_output(args.out, IMAGE, "--out")      # at the start of a command
    pic = check_output(check_folder(args.picture, "--picture") / safe_name(scene.name, ".png"),
                       IMAGE, "--picture")            # names derived from data stay inside
    with all_or_nothing():                            # every write_*_atomic in the block is
        write_image_atomic(out, picture)              # kept in memory and renamed into place
        write_npy_atomic(npy, disp)                   # only when the block ends without error
"""

from __future__ import annotations

import contextlib
import contextvars
import io
import os
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np

from host.errors import HostError

# kinds of output: what the bytes are, and the file name endings that say so
IMAGE = "image"  # any format OpenCV can encode, told by the extension
KINDS = {"png": (".png",), "npy": (".npy",), "toml": (".toml",), "csv": (".csv",),
         "yml": (".yml", ".yaml"), "mcap": (".mcap",)}
_KIND_NAMES = {"png": "a PNG picture", "npy": "a NumPy array", "toml": "a TOML file",
               "csv": "a CSV table", "yml": "an OpenCV YAML file",
               "mcap": "a ROS 2 bag in MCAP storage"}

_staged: contextvars.ContextVar[dict[Path, bytes] | None] = contextvars.ContextVar(
    "host_files_staged", default=None)


def _where(option: str | None, path: Path) -> str:
    return f"{option} {path}" if option else str(path)


def check_folder(path: str | os.PathLike[str], option: str | None = None,
                 create: bool = False, target: Path | None = None) -> Path:
    """A folder the command may write into: it exists (made when create), is a folder, and a
    file can really be made in it (a probe, so root on a read-only mount is told the truth)."""
    folder = Path(path) if str(path) else Path(".")
    where = _where(option, target or folder)
    if create and not folder.exists():
        try:
            folder.mkdir(parents=True)
        except OSError as e:
            raise HostError(f"{where}: cannot make the folder ({e.strerror})") from None
    if not folder.exists():
        raise HostError(f"{where}: no such folder {folder}" if target else
                        f"{where}: no such folder")
    if not folder.is_dir():
        raise HostError(f"{where}: {folder} is not a folder" if target else
                        f"{where}: not a folder")
    try:
        fd, probe = tempfile.mkstemp(prefix=".host-probe-", dir=folder)
    except OSError as e:
        raise HostError(f"{where}: cannot write in folder {folder} ({e.strerror})") from None
    os.close(fd)
    os.unlink(probe)
    return folder


def check_output(path: str | os.PathLike[str], kind: str, option: str | None = None) -> Path:
    """Check an output file before any work: its folder is writable, it is not a folder, and
    its extension names a format the kind can be written as. Returns the path."""
    p = Path(path)
    where = _where(option, p)
    if p.is_dir():
        raise HostError(f"{where}: is a folder (name a file)")
    if kind == IMAGE:
        if not p.suffix or not cv2.haveImageWriter(str(p)):
            raise HostError(f"{where}: cannot write an image as {p.suffix or 'no extension'!r} "
                            f"(use .png, .jpg, .bmp, .tif ...)")
    elif p.suffix.lower() not in KINDS[kind]:
        raise HostError(f"{where}: is written as {_KIND_NAMES[kind]}; name it "
                        f"{' or '.join(KINDS[kind])}")
    check_folder(p.parent, option, target=p)
    return p


_UNSAFE = re.compile(r"[^A-Za-z0-9._+-]+")


def safe_name(text: str, suffix: str = "", fallback: str = "unnamed") -> str:
    """A file name made from data (a scene's name ...): no separators, no leading dot, no
    '..', at most 100 characters, so that it stays inside the folder it is joined to."""
    name = _UNSAFE.sub("_", str(text)).lstrip(".")[:100] or fallback
    return name + suffix


def inside(folder: Path, name: str) -> Path:
    """folder / name, refusing a name that leads out of folder (after safe_name it cannot)."""
    path = folder / name
    if path.resolve().parent != folder.resolve():
        raise HostError(f"{name!r} would be written outside {folder}")
    return path


def _umask_mode() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def _write_temp(path: Path, data: bytes) -> str:
    """The bytes in a hidden temporary file beside path, with the mode a new file gets."""
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise HostError(f"{path}: folder {folder} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=folder)
    except OSError as e:
        raise HostError(f"{path}: cannot write ({e.strerror})") from None
    try:
        with os.fdopen(fd, "wb") as f:
            os.fchmod(f.fileno(), _umask_mode())  # mkstemp makes 0600; outputs are shared
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
    except OSError as e:
        Path(tmp).unlink(missing_ok=True)
        raise HostError(f"{path}: cannot write ({e.strerror})") from None
    return tmp


def _commit(files: dict[Path, bytes]) -> None:
    """Write every file to its temporary first, then rename them all into place."""
    temps: list[tuple[str, Path]] = []
    try:
        for path, data in files.items():
            temps.append((_write_temp(path, data), path))
        for tmp, path in temps:
            os.replace(tmp, path)
    except OSError as e:
        raise HostError(f"cannot write the outputs ({e.strerror})") from None
    finally:
        for tmp, _ in temps:
            Path(tmp).unlink(missing_ok=True)


@contextlib.contextmanager
def all_or_nothing() -> Iterator[None]:
    """Writes inside the block are held in memory and written when it ends without an error;
    an error (or Ctrl-C) leaves every output as it was."""
    token = _staged.set({})
    try:
        yield
        files = _staged.get()
        assert files is not None
    finally:
        _staged.reset(token)
    _commit(files)


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write data to path by rename from a temporary file (or stage it in all_or_nothing)."""
    path = Path(path)
    staged = _staged.get()
    if staged is not None:
        staged[path] = bytes(data)
        return
    _commit({path: bytes(data)})


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    write_bytes_atomic(path, text.encode())


def write_image_atomic(path: str | os.PathLike[str], image: np.ndarray) -> None:
    ext = Path(path).suffix or ".png"
    try:
        ok, buf = cv2.imencode(ext, image)
    except cv2.error:
        ok = False
    if not ok:
        raise HostError(f"{path}: cannot encode an image as {ext}")
    write_bytes_atomic(path, buf.tobytes())


def write_npy_atomic(path: str | os.PathLike[str], array: np.ndarray) -> None:
    buf = io.BytesIO()
    np.save(buf, array)
    write_bytes_atomic(path, buf.getvalue())
