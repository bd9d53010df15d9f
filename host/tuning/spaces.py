"""Parameter spaces for tuning: each dimension is a list of values; a state is a tuple of
indices into them; an action moves one dimension one step up or down, or keeps all."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

from host import renamed
from host.errors import HostError
from host.stereo.params import MatcherParams


@dataclass(frozen=True)
class Dimension:
    name: str  # a MatcherParams field; p1_factor / p2_factor (times channels * block_size^2);
    # lr_fill: the left-right check's tolerance (px) with filling, None = neither
    values: tuple[Any, ...]
    cyclic: bool = False  # categories without an order: a step wraps round


@dataclass(frozen=True)
class Space:
    name: str
    dims: tuple[Dimension, ...]
    base: MatcherParams

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(d.values) for d in self.dims)

    @property
    def size(self) -> int:
        n = 1
        for k in self.shape:
            n *= k
        return n

    def states(self) -> list[tuple[int, ...]]:
        """Every state, in grid order."""
        return list(itertools.product(*(range(k) for k in self.shape)))

    def values(self, state: tuple[int, ...]) -> dict[str, Any]:
        return {d.name: d.values[i] for d, i in zip(self.dims, state)}

    def params(self, state: tuple[int, ...]) -> MatcherParams:
        v = self.values(state)
        p1, p2 = v.pop("p1_factor", None), v.pop("p2_factor", None)
        if "lr_fill" in v:  # the check only invalidates; filling makes it pay
            tol = v.pop("lr_fill")
            v |= {"lr_check": tol, "fill": tol is not None}
        params = self.base.replace(**v)
        # OpenCV's penalties scale with the matched channels: 3 for colour, 1 for grey
        area = (3 if params.colour else 1) * params.block_size ** 2
        if p1 is not None:
            params = params.replace(p1=int(p1 * area))
        if p2 is not None:
            params = params.replace(p2=int(max(p2, p1 or 0) * area))
        return params

    @property
    def actions(self) -> list[tuple[int, int]]:
        """(dimension, step): step -1 or +1 on one dimension; (-1, 0) keeps everything."""
        return [(-1, 0)] + [(d, s) for d in range(len(self.dims)) for s in (-1, 1)]

    def move(self, state: tuple[int, ...], action: tuple[int, int], step: int = 1
             ) -> tuple[int, ...]:
        dim, sign = action
        if dim < 0:
            return state
        s = list(state)
        n = self.shape[dim]
        if self.dims[dim].cyclic:
            s[dim] = (s[dim] + sign * step) % n
        else:
            s[dim] = min(max(s[dim] + sign * step, 0), n - 1)
        return tuple(s)


def odd_range(spec: str) -> tuple[int, ...]:
    """'5:41' -> 5, 7, ..., 41 (odd block sizes)."""
    try:
        lo, hi = (int(x) for x in spec.split(":"))
    except ValueError:
        raise HostError(f"block-size range must look like 5:41, got {spec!r}") from None
    if lo < 1 or hi < lo or lo % 2 == 0 or hi % 2 == 0:
        raise HostError(f"block-size range needs odd bounds lo <= hi, got {spec!r}")
    return tuple(range(lo, hi + 1, 2))


SPACES = ("block-size", "sad", "opencv-bm", "opencv-sgbm")


def make_space(name: str, base: MatcherParams, block_sizes: tuple[int, ...] = odd_range("5:41")
               ) -> Space:
    """The named space around base (which fixes every parameter the space does not vary).

    No space tunes the disparity range: it is the scene's (host.tuning.disparity_range)."""
    if name == "block-size":
        return Space(name, (Dimension("block_size", block_sizes),), base)
    if name == "sad":
        return Space(name, (
            Dimension("block_size", tuple(w for w in block_sizes if w <= 25)),
            Dimension("lr_fill", (None, 2.0, 1.0, 0.5)),  # by strictness: off = no limit
            Dimension("matcher", ("sad", "ssd", "ncc"), cyclic=True),
        ), base)
    if name == "opencv-bm":
        return Space(name, (
            Dimension("block_size", tuple(w for w in block_sizes if w <= 31)),
            Dimension("pre_filter_cap", (15, 31, 47, 63)),
            Dimension("texture_threshold", (0, 10, 20, 40)),
            Dimension("uniqueness_ratio", (0, 5, 10, 15, 20)),
            Dimension("speckle_window_size", (0, 50, 100, 200)),
        ), base.replace(matcher="opencv-bm", speckle_range=2))
    if name == "opencv-sgbm":
        return Space(name, (
            Dimension("block_size", (1, 3, 5, 7, 9, 11)),
            Dimension("p1_factor", (2, 4, 8, 16)),
            Dimension("p2_factor", (16, 32, 64, 96)),
            Dimension("uniqueness_ratio", (0, 5, 10, 15)),
            Dimension("mode", ("sgbm", "hh", "sgbm3way"), cyclic=True),
        ), base.replace(matcher="opencv-sgbm"))
    now = f"now {renamed.SPACES[name]!r}; " if name in renamed.SPACES else ""
    raise HostError(f"unknown space {name!r} ({now}choose from {', '.join(SPACES)})")
