"""Tuned-parameters files: a small TOML file with the matcher and how it was tuned."""

from __future__ import annotations

import math
import os
import sys
import tomllib
from pathlib import Path
from typing import Any

from host.errors import HostError
from host.files import write_text_atomic
from host.renamed import PARAMETERS, SPACES
from host.stereo.params import MatcherParams


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _table(name: str, data: dict[str, Any]) -> str:
    lines = [f"[{name}]"] + [f"{k} = {_toml_value(v)}" for k, v in data.items() if v is not None]
    return "\n".join(lines) + "\n"


def save_params(path: str | os.PathLike[str], params: MatcherParams,
                tuning: dict[str, Any] | None = None,
                disparity_range: dict[str, Any] | None = None) -> None:
    """Write [matcher] (every parameter) and [tuning] (method, scenes, score ...) atomically.

    With disparity_range (a policy, host.tuning.disparity_range) the matcher table leaves out
    the range: the reader derives it from each scene or frame."""
    text = "# stereo-servo matcher parameters (host tune); read by host eval/servo --params\n"
    matcher = params.to_dict() | ({"lr_check": "off"} if params.lr_check is None else {})
    if disparity_range:
        del matcher["num_disparities"], matcher["min_disparity"]
    text += _table("matcher", matcher)
    if disparity_range:
        text += "\n" + _table("disparity_range", disparity_range)
    if tuning:
        text += "\n" + _table("tuning", tuning)
    write_text_atomic(path, text)


def load_params(path: str | os.PathLike[str]) -> tuple[MatcherParams, dict[str, Any]]:
    """Read a params file; returns the validated matcher parameters and the [tuning] table.

    The [matcher] table's keys override its matcher's measured defaults
    (MatcherParams.for_matcher); lr_check = "off" turns the LR check off."""
    p = Path(path)
    if p.is_dir():
        raise HostError(f"{p}: is a folder, not a params file")
    try:
        data = tomllib.loads(p.read_bytes().decode("utf-8"))
    except OSError as e:
        raise HostError(f"{p}: cannot read ({e.strerror})") from None
    except UnicodeDecodeError as e:
        raise HostError(f"{p}: not a TOML file (not UTF-8 text: byte 0x{e.object[e.start]:02X} "
                        f"at {e.start})") from None
    except tomllib.TOMLDecodeError as e:
        raise HostError(f"{p}: not a valid TOML file ({e})") from None
    except ValueError as e:  # a number beyond Python's digit limit, and the like
        raise HostError(f"{p}: bad value ({str(e).split(';')[0]})") from None
    except RecursionError:
        raise HostError(f"{p}: not a params file (nested too deeply)") from None
    if not isinstance(data.get("matcher", {}), dict):
        raise HostError(f"{p}: [matcher] must be a table")
    if "matcher" not in data:
        raise HostError(f"{p}: no [matcher] table")
    for key in data["matcher"]:
        field = PARAMETERS.get(key.replace("-", "_"))
        if field:  # never a key of a written file: the CLI's
            raise HostError(f"{p}: [matcher] key {key} is {field} in a params file")
    tuning = data.get("tuning", {})
    if isinstance(tuning, dict) and tuning.get("space") in SPACES:
        new = SPACES[tuning["space"]]
        print(f"note: {p}: [tuning] space {tuning['space']!r} is now {new!r} (read as such)",
              file=sys.stderr)
        tuning = tuning | {"space": new}
    for key, value in data["matcher"].items():
        if isinstance(value, float) and not math.isfinite(value):
            raise HostError(f"{p}: matcher parameter {key} must be a finite number, got {value}")
    table = data["matcher"] | ({"lr_check": None} if data["matcher"].get("lr_check") == "off"
                               else {})
    try:  # the keys over the named matcher's measured defaults, as the command line's
        base = MatcherParams.for_matcher(table.get("matcher", MatcherParams.matcher))
        params = MatcherParams.from_dict(table, base).validate()
    except HostError as e:
        raise HostError(f"{p}: {e}") from None
    except TypeError as e:
        raise HostError(f"{p}: bad [matcher] table ({e})") from None
    return params, tuning


def load_disparity_range(path: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The [disparity_range] policy table of a params file, None when it fixes the range."""
    try:
        return tomllib.loads(Path(path).read_text()).get("disparity_range")
    except (OSError, tomllib.TOMLDecodeError):
        return None  # load_params reports the problem


def load_matcher_table(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The raw [matcher] table of a params file (empty when unreadable: load_params reports)."""
    try:
        table = tomllib.loads(Path(path).read_text()).get("matcher", {})
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError, ValueError, RecursionError):
        return {}
    return table if isinstance(table, dict) else {}
