"""--swap-check for a recorded camera (replay:DIR, replay:FILE.mcap), as open_source does it
for a live one: its first pairs are looked at before the servo or the view uses any, and a pair
whose left and right are swapped is refused in one line (--swap-check auto swaps them back)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from host.camera.source import StereoFrame, StereoSource
from host.camera.swapped import SwapVerdict, swap_verdict
from host.camera.wrapper import WrappedSource
from host.errors import HostError

FRAMES = 3  # pairs looked at, at most, until one is conclusive


class CheckedSource(WrappedSource):
    """inner with the pairs read for the check handed on first, then the rest; swap: each pair
    with its views exchanged (before the rectification inner would have applied)."""

    def __init__(self, inner: StereoSource) -> None:
        super().__init__(inner)
        self.rectify, inner.rectify = inner.rectify, None
        self.held: list[StereoFrame] = []
        self.swap = False

    def _read(self) -> StereoFrame | None:
        frame = self.held.pop(0) if self.held else self.inner.read()
        if frame is None or not self.swap:
            return frame
        return StereoFrame(frame.right, frame.left, frame.t_right, frame.t_left)


def look(source: CheckedSource, frames: int = FRAMES) -> SwapVerdict | None:
    """The verdict on the first conclusive of source's first pairs (the last one's if none is),
    those pairs kept to be read again; None when the source has no pair."""
    verdict = None
    for _ in range(frames):
        raw = source.inner.read()
        if raw is None:
            break
        source.held.append(raw)
        pair = source.rectify(raw) if source.rectify else raw
        verdict = swap_verdict(pair.left, pair.right)
        if verdict.conclusive:
            break
    return verdict


def check_recorded(args: argparse.Namespace, source: StereoSource) -> StereoSource:
    """source, its views checked when it is a recording (--camera replay:...) and --swap-check
    is not off: swapped ones refused (HostError), or swapped back (auto, said on stderr)."""
    if not args.camera.startswith("replay:") or args.swap_check == "off":
        return source
    checked = CheckedSource(source)
    verdict = look(checked)
    if verdict is None or not verdict.swapped:
        return checked
    if args.swap_check == "auto":
        checked.swap = True
        print(f"camera: left and right were swapped ({verdict.describe()}): swapped them back",
              file=sys.stderr)
        return checked
    raise HostError(f"{args.camera}: left and right look swapped ({verdict.describe()}): its "
                    f"left view is the right camera's; --swap-check auto swaps them back")


def check_pairs(named: list[tuple[str, Any, Any]], policy: str) -> None:
    """Refuse (HostError) the first of (name, left, right) whose views look swapped, unless
    policy is off: a swapped pair tuned on self-supervised would tune the matcher to nonsense."""
    if policy == "off":
        return
    for name, left, right in named:
        verdict = swap_verdict(left, right)
        if verdict.swapped:
            raise HostError(f"{name}: left and right look swapped ({verdict.describe()}): "
                            f"exchange the two images (or --swap-check off to tune anyway)")
