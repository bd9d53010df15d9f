"""Matcher parameters: one validated record shared by the matcher, tuner, CLI and params files."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from host.errors import HostError

MATCHERS = ("sad", "ssd", "ncc", "sgm", "opencv-bm", "opencv-sgbm")
BORDERS = ("invalid", "clip")
SUBPIXEL_FITS = ("auto", "parabola", "equiangular")
SGM_PATHS = (4, 5, 8)
SGBM_MODES = {"sgbm": 0, "hh": 1, "sgbm3way": 2, "hh4": 3}
CENSUS_BITS = 62  # bits of the own SGM's 9x7 census (host.stereo.sgm.CENSUS_BITS)
# each matcher's measured best where it differs from the dataclass defaults: own SGM measured on
# the ten shared Middlebury scenes, leave-one-out (docs/stereo.md, "SGM defaults")
MATCHER_DEFAULTS: dict[str, dict[str, Any]] = {
    "sgm": {"block_size": 1, "border": "clip", "lr_check": 0.0, "uniqueness_ratio": 30.0,
            "fill": True, "median": 5, "paths": 4, "subpixel": False,
            "intensity_weight": 1.0, "intensity_cap": 20, "outside_cost": 23,
            "p2_adapt": 16.0},
}


@dataclass(frozen=True)
class MatcherParams:
    """Block-matching parameters; names follow OpenCV's (blockSize -> block_size ...).

    Units: block_size, num_disparities, min_disparity, lr_check and speckle_range in pixels;
    uniqueness_ratio in percent (0 = off); subpixel_fit = "parabola", "equiangular" or "auto"
    (the measured best for the matcher's cost); lr_check None = off; colour = match on the BGR
    channels where the input has them (SAD, SSD, SGBM), else on grey; border = "invalid"
    (a pixel whose window leaves the image has no disparity) or "clip" (the window is cropped
    to the image; own matchers only); median = median-filter size
    applied after filling (0 = off); fill = fill invalid pixels from the farther valid neighbour;
    paths = aggregation paths of the own SGM: 5 (left, right and the three from above, in one
    pass), 8 or 4 (left, right, up, down); intensity_weight, intensity_cap = the own SGM's
    intensity term added to census (weight per grey level of |difference|, capped at cap grey
    levels; 0 = census alone); outside_cost = the own SGM's cost of a candidate whose right
    pixel lies outside the image (CENSUS_BITS, the census maximum, when not lowered);
    p2_adapt = the own SGM's P2 per path step, P2 / (1 + grey step / p2_adapt) (grey levels of
    the left image between the step's two pixels; at least P1 + 1; 0 = P2 everywhere).

    The dataclass defaults are the plain matcher; for_matcher gives each matcher's measured
    best, which is what the commands start from (docs/stereo.md).
    """

    matcher: str = "sad"
    block_size: int = 9
    num_disparities: int = 64
    min_disparity: int = 0
    subpixel: bool = True
    subpixel_fit: str = "auto"
    colour: bool = True
    border: str = "invalid"
    lr_check: float | None = None
    uniqueness_ratio: float = 0.0
    fill: bool = False
    median: int = 0
    pre_filter_cap: int = 31
    texture_threshold: int = 10
    speckle_window_size: int = 0
    speckle_range: int = 2
    p1: int = 0
    p2: int = 0
    mode: str = "sgbm"
    paths: int = 5
    intensity_weight: float = 0.0
    intensity_cap: int = 20
    outside_cost: int = CENSUS_BITS
    p2_adapt: float = 0.0

    @classmethod
    def for_matcher(cls, matcher: str = "sad") -> MatcherParams:
        """The measured default configuration of a matcher (MATCHER_DEFAULTS), else the plain
        dataclass defaults with that matcher."""
        return cls(matcher=matcher, **MATCHER_DEFAULTS.get(matcher, {}))

    def replace(self, **changes: Any) -> MatcherParams:
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        return {k: v for k, v in asdict(self).items() if v is not None}

    @classmethod
    def from_dict(cls, data: dict[str, Any], base: MatcherParams | None = None) -> MatcherParams:
        """data's keys (type-checked) over base, else over the plain dataclass defaults."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise HostError(f"unknown matcher parameter(s): {', '.join(unknown)}")
        defaults = cls()
        for key, value in data.items():
            want = type(getattr(defaults, key))
            if key == "lr_check" and (value is None or isinstance(value, (int, float))):
                continue
            if want is float and isinstance(value, int) and not isinstance(value, bool):
                continue
            if key == "lr_check":
                raise HostError(f"matcher parameter lr_check must be a number (px) or "
                                f"\"off\", got {value!r}")
            if not isinstance(value, want) or (want is int and isinstance(value, bool)):
                raise HostError(f"matcher parameter {key} must be {want.__name__}, got {value!r}")
        return replace(base, **data) if base is not None else cls(**data)

    def validate(self, width: int | None = None) -> MatcherParams:
        """Check bounds; width (px) also bounds the disparity range. Returns self."""
        if self.matcher not in MATCHERS:
            raise HostError(f"unknown matcher {self.matcher!r} (choose from {', '.join(MATCHERS)})")
        if self.block_size < 1 or self.block_size % 2 == 0:
            raise HostError(f"block size must be odd and positive, got {self.block_size}")
        if self.block_size > 255 or (self.matcher == "opencv-bm" and not self.block_size >= 5):
            raise HostError(f"block size {self.block_size} is out of range for {self.matcher}")
        if self.num_disparities < 1:
            raise HostError(f"num-disparities must be positive, got {self.num_disparities}")
        if self.matcher.startswith("opencv") and self.num_disparities % 16:
            raise HostError(f"{self.matcher} needs num-disparities divisible by 16, "
                            f"got {self.num_disparities}")
        if self.lr_check is not None and self.lr_check < 0:
            raise HostError(f"lr-check tolerance must be >= 0 px, got {self.lr_check}")
        if self.uniqueness_ratio < 0:
            raise HostError(f"uniqueness ratio must be >= 0, got {self.uniqueness_ratio}")
        if self.border not in BORDERS:
            raise HostError(f"unknown border {self.border!r} (choose from {', '.join(BORDERS)})")
        if not self.matcher.startswith("opencv") and self.min_disparity < 0:
            raise HostError(f"min-disparity must be >= 0 for {self.matcher}, "
                            f"got {self.min_disparity}")
        if self.median not in (0, 3, 5):
            raise HostError(f"median must be 0, 3 or 5, got {self.median}")
        if self.subpixel_fit not in SUBPIXEL_FITS:
            raise HostError(f"unknown sub-pixel fit {self.subpixel_fit!r} "
                            f"(choose from {', '.join(SUBPIXEL_FITS)})")
        if self.mode not in SGBM_MODES:
            raise HostError(f"unknown SGBM mode {self.mode!r} "
                            f"(choose from {', '.join(SGBM_MODES)})")
        if not 0.0 <= self.intensity_weight <= 8.0:
            raise HostError(f"intensity weight must be in 0..8, got {self.intensity_weight}")
        if not 0 <= self.intensity_cap <= 255:
            raise HostError(f"intensity cap must be in 0..255 grey levels, "
                            f"got {self.intensity_cap}")
        if not 0 <= self.outside_cost <= 1024:
            raise HostError(f"outside cost must be in 0..1024, got {self.outside_cost}")
        if not 0.0 <= self.p2_adapt <= 255.0:
            raise HostError(f"p2_adapt must be in 0..255 grey levels, got {self.p2_adapt}")
        if self.paths not in SGM_PATHS:
            raise HostError(f"paths must be 4, 5 or 8 (own SGM), got {self.paths}")
        if width is not None:
            if self.block_size >= width:
                raise HostError(f"block size {self.block_size} is too large for an image "
                                f"{width} px wide")
            if self.min_disparity + self.num_disparities > width - self.block_size // 2:
                raise HostError(f"disparity range {self.min_disparity}.."
                                f"{self.min_disparity + self.num_disparities - 1} is wider "
                                f"than the image ({width} px)")
        return self
