"""The Python API: a stereo matcher object in OpenCV's manner over every matcher, with input
checks and the disparity-range policy applied, and a params file read as one object.

    >>> from host.api import StereoMatcher
    >>> m = StereoMatcher.create("ncc", block_size=7, border="clip", lr_check=1.0, fill=True)
    >>> disp = m.compute(left, right)   # float32 px, NaN = no disparity

    >>> m = StereoMatcher.load("tuned.toml")   # what `host tune --out` wrote, range policy too

Images are numpy arrays of dtype uint8: grey (H x W) or BGR (H x W x 3), both views of one
size and kind, rectified (rows aligned). Anything else raises InputError (a ValueError) naming
the problem.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from host.errors import HostError
from host.stereo.matcher import compute_disparity
from host.stereo.params import MATCHERS, MatcherParams
from host.tuning.disparity_range import RangePolicy, apply_range

__all__ = ["MATCHERS", "InputError", "MatcherParams", "ParamsFile", "RangePolicy",
           "StereoMatcher", "check_pair", "load_params_file"]


class InputError(HostError, ValueError):
    """An image or parameter the matcher cannot take, stated in one line."""


@contextlib.contextmanager
def _as_input_error() -> Iterator[None]:
    """The matcher's own refusals (HostError) as InputError, a ValueError a caller can catch."""
    try:
        yield
    except InputError:
        raise
    except HostError as e:
        raise InputError(str(e)) from None
    except TypeError as e:  # a parameter of the wrong kind
        raise InputError(f"bad matcher parameter ({e})") from None


def _check_image(name: str, image: Any) -> None:
    if not isinstance(image, np.ndarray):
        raise InputError(f"{name}: expected a numpy array (uint8, H x W or H x W x 3), got "
                         f"{type(image).__name__}")
    if image.dtype != np.uint8:
        hint = (" (scale 16-bit images to 8 bits first, e.g. (img >> 8).astype(np.uint8))"
                if image.dtype == np.uint16 else "")
        raise InputError(f"{name}: dtype {image.dtype} is not supported: the matchers take "
                         f"uint8{hint}")
    if image.ndim not in (2, 3) or (image.ndim == 3 and image.shape[2] != 3):
        raise InputError(f"{name}: shape {image.shape} is neither grey (H x W) nor BGR "
                         "(H x W x 3)")
    if min(image.shape[:2]) < 1:
        raise InputError(f"{name}: empty image {image.shape}")


def check_pair(left: Any, right: Any) -> None:
    """Raise InputError unless left and right are uint8 images of one size and kind."""
    _check_image("left", left)
    _check_image("right", right)
    if left.shape[:2] != right.shape[:2]:
        raise InputError(f"left and right differ in size: {left.shape[1]}x{left.shape[0]} vs "
                         f"{right.shape[1]}x{right.shape[0]}")
    if left.ndim != right.ndim:
        raise InputError(f"left is {'grey' if left.ndim == 2 else 'BGR'} and right is "
                         f"{'grey' if right.ndim == 2 else 'BGR'}: give both views alike")


@dataclass(frozen=True)
class ParamsFile:
    """A params file (host tune --out) as one object: the matcher parameters, the disparity
    range policy it stores (None: the range is fixed in params; a file with neither a policy
    nor num_disparities gets create's default, coarse) and its [tuning] record."""

    params: MatcherParams
    range_policy: RangePolicy | None = None
    tuning: dict[str, Any] = field(default_factory=dict)


def load_params_file(path: str | os.PathLike[str]) -> ParamsFile:
    """Read and validate a params file; HostError names the file and the problem."""
    from host.params_file import load_disparity_range, load_matcher_table, load_params

    params, tuning = load_params(path)
    table = load_disparity_range(path)
    if table is None and "num_disparities" not in load_matcher_table(path):
        return ParamsFile(params, RangePolicy.parse("coarse"), tuning)  # as create's default
    return ParamsFile(params, RangePolicy.from_table(table) if table else None, tuning)


class StereoMatcher:
    """One matcher with its parameters (like cv2.StereoSGBM): compute(left, right) gives the
    left view's disparity. Without a fixed range, each pair gets its range from the policy
    (default: the coarse pass, docs/tuning.md), as host eval and host servo apply it."""

    def __init__(self, params: MatcherParams, range_policy: RangePolicy | None = None) -> None:
        with _as_input_error():
            self.params = params.validate()
        self.range_policy = range_policy

    @classmethod
    def create(cls, matcher: str = "sad", block_size: int | None = None,
               num_disparities: int | None = None, min_disparity: int = 0,
               range_policy: str | RangePolicy | None = None, **params: Any) -> StereoMatcher:
        """A matcher by name (one of MATCHERS) and MatcherParams fields (OpenCV's names:
        block_size, num_disparities, uniqueness_ratio ...) over the matcher's measured
        defaults, the ones `--matcher NAME` gives (MatcherParams.for_matcher; block_size None:
        the matcher's own). num_disparities given: the range min_disparity ..
        min_disparity + num_disparities - 1 px; else range_policy ("coarse" by default,
        "depth:NEAR:FAR" needs focal_baseline in compute, "fixed:N") decides per pair."""
        if matcher not in MATCHERS:
            raise InputError(f"unknown matcher {matcher!r} (choose from {', '.join(MATCHERS)})")
        with _as_input_error():
            given = {"min_disparity": min_disparity, **params}
            if block_size is not None:
                given["block_size"] = block_size
            p = MatcherParams.from_dict(given, MatcherParams.for_matcher(matcher))
            if num_disparities is not None:
                if range_policy is not None:
                    raise InputError("give num_disparities or range_policy, not both")
                return cls(p.replace(num_disparities=num_disparities))
            if isinstance(range_policy, str) or range_policy is None:
                range_policy = RangePolicy.parse(range_policy or "coarse")
            return cls(p, range_policy)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> StereoMatcher:
        """The matcher a params file describes, with the range policy it stores."""
        f = load_params_file(path)
        return cls(f.params, f.range_policy)

    def disparity_range(self, left: np.ndarray, right: np.ndarray,
                        focal_baseline: float | None = None) -> tuple[int, int]:
        """(min_disparity, num_disparities) px this matcher searches on this pair."""
        check_pair(left, right)
        if self.range_policy is None:
            return self.params.min_disparity, self.params.num_disparities
        return self.range_policy.resolve(left, right, focal_baseline=focal_baseline)

    def compute(self, left: np.ndarray, right: np.ndarray,
                focal_baseline: float | None = None) -> np.ndarray:
        """Disparity of the left view in px (float32, H x W), NaN where there is none.
        focal_baseline: focal_px * baseline_m, for a depth:NEAR:FAR range policy."""
        check_pair(left, right)
        p = self.params
        with _as_input_error():
            if self.range_policy is not None:
                p = apply_range(p, self.disparity_range(left, right, focal_baseline))
            return compute_disparity(left, right, p)

    def __repr__(self) -> str:
        return f"StereoMatcher({self.params!r}, range_policy={self.range_policy})"
